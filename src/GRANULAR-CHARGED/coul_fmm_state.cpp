/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "coul_fmm_state.h"

#include "atom.h"
#include "domain.h"
#include "error.h"
#include "force.h"
#include "update.h"

#include "gcfmm/options.hpp"
#include "memory.h"

#include <algorithm>
#include <cmath>

using namespace LAMMPS_NS;
using MTS = CoulFMMTimeStepping;

CoulFMMState::CoulFMMState(LAMMPS *lmp, int cols, int bit) :
    Pointers(lmp), field_cols(cols), groupbit(bit), applied(nullptr), applied_force(nullptr),
    row(nullptr), mpi(lmp), positions_pending(false), hashes_local(0), hashes_nlocal(-1)
{
}

CoulFMMState::~CoulFMMState()
{
  memory->destroy(applied);
  memory->destroy(applied_force);
  memory->destroy(row);
}

void CoulFMMState::grow(int nmax)
{
  memory->grow(applied, nmax, field_cols, "coul/fmm:field");
  memory->grow(applied_force, nmax, 3, "coul/fmm:polar_force");
  memory->grow(row, nmax, MTS::COLS, "coul/fmm:eval_state");
}

void CoulFMMState::copy(int i, int j)
{
  forget_hashes();
  std::copy(applied[i], applied[i] + field_cols, applied[j]);
  std::copy(row[i], row[i] + MTS::COLS, row[j]);
}

void CoulFMMState::clear(int i)
{
  forget_hashes();
  std::fill(applied[i], applied[i] + field_cols, 0.0);
  std::fill(row[i], row[i] + MTS::COLS, 0.0);
}

int CoulFMMState::pack_exchange(int i, double *buf) const
{
  std::copy(applied[i], applied[i] + field_cols, buf);
  std::copy(row[i], row[i] + MTS::COLS, buf + field_cols);
  return exchange_size();
}

int CoulFMMState::unpack_exchange(int i, const double *buf)
{
  forget_hashes();
  std::copy(buf, buf + field_cols, applied[i]);
  std::copy(buf + field_cols, buf + field_cols + MTS::COLS, row[i]);
  return exchange_size();
}

// the count first (atom->extra is shared by the fixes), the applied field (4), the row
int CoulFMMState::pack_restart(int i, double *buf) const
{
  buf[0] = restart_size();
  std::copy(applied[i], applied[i] + 4, buf + 1);
  std::copy(row[i], row[i] + MTS::COLS, buf + 5);
  if (positions_pending) domain->unmap(atom->x[i], atom->image[i], buf + 5 + MTS::LAST_X);
  return restart_size();
}

// files written before the ASLEEP column hold COLS_V1 columns: the rest start at zero
void CoulFMMState::unpack_restart(int i, const double *values)
{
  forget_hashes();
  const int cols = std::min<int>(MTS::COLS, std::max<int>(MTS::COLS_V1, static_cast<int>(values[0]) - 5));
  int m = 1;
  for (int k = 0; k < 4; k++) applied[i][k] = values[m++];
  for (int k = 4; k < field_cols; k++) applied[i][k] = 0.0;
  for (int k = 0; k < MTS::COLS; k++) row[i][k] = k < cols ? values[m++] : 0.0;
}

double CoulFMMState::memory_usage() const
{
  return (field_cols + 3.0 + MTS::COLS) * atom->nmax * sizeof(double);
}

void CoulFMMState::apply_evaluated(int i)
{
  for (int k = 0; k < 4; k++) applied[i][k] = row[i][MTS::FIELD + k];
}

void CoulFMMState::remember_charges()
{
  for (int i = 0; i < atom->nlocal; i++)
    row[i][MTS::LAST_Q] = (atom->mask[i] & groupbit) ? atom->q[i] : 0.0;
}

void CoulFMMState::remember_positions(bool now)
{
  positions_pending = !now;
  if (now)
    for (int i = 0; i < atom->nlocal; i++)
      domain->unmap(atom->x[i], atom->image[i], &row[i][MTS::LAST_X]);
}

void CoulFMMState::settle_positions()
{
  if (positions_pending) remember_positions(true);
}

void CoulFMMState::field_scale_sums(double sums[2])
{
  sums[0] = sums[1] = 0.0;
  for (int i = 0; i < atom->nlocal; i++) {
    const double q = charge_then(i), *e = &row[i][MTS::FIELD];
    if (q == 0.0 || static_source_then(i)) continue;
    sums[0] += q * q * (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
    sums[1] += q * q;
  }
  mpi.sum(sums, 2);
}

// one pass over the local charges; error->one, as the atom is on this rank only
void CoulFMMState::check_charges(const char *fix_id) const
{
  const double *q = atom->q;
  const int *mask = atom->mask;
  for (int i = 0; i < atom->nlocal; i++)
    if ((mask[i] & groupbit) && !std::isfinite(q[i]))
      error->one(FLERR, "Fix coul/fmm {}: atom {} has charge {}: charges must be finite", fix_id,
                 atom->tag[i], q[i]);
}

/* ----------------------------------------------------------------------
   the continuity record
------------------------------------------------------------------------- */

void CoulFMMState::cell(double box[4]) const
{
  box[0] = domain->boxlo[0];
  box[1] = domain->boxlo[1];
  box[2] = domain->xprd;
  box[3] = domain->yprd;
}

uint64_t CoulFMMState::local_hashes()
{
  if (hashes_nlocal != atom->nlocal) {
    hashes_local = 0;
    for (int i = 0; i < atom->nlocal; i++)
      if (charge_then(i) != 0.0) hashes_local += coul_fmm_charge_hash(atom->tag[i], charge_then(i));
    hashes_nlocal = atom->nlocal;
  }
  return hashes_local;
}

void CoulFMMState::record(CoulFMMTimeStepping &scheme, int boundary)
{
  auto &then = scheme.evaluated;
  forget_hashes();    // the evaluation wrote the charges of its rows
  then.charges = local_hashes();
  mpi.sum(&then.charges, 1);
  then.step = update->ntimestep;
  then.qqrd2e = force->qqrd2e;
  then.boundary = boundary;
  cell(then.box);
}

/* ----------------------------------------------------------------------
   SAME charges (same IDs, same values) in the same geometry and units, charges ADDED (fix
   deposit; or static sources woken) with all those of the evaluation still there and
   unchanged, or NONE. The sum of hashes is an integer sum (modulo 2^64): exact and the same
   however the atoms are distributed. When the scheme absorbs charge changes, an atom charged
   at the evaluation and now (not a static source then or now) whose charge changed counts as
   unchanged: the checksum is of the evaluation's charges, and its change is absorbed
   (doc/theory.md, eq. (5.5)); a charge that became 0 is a change (evaluated).
------------------------------------------------------------------------- */

CoulFMMTimeStepping::Continuity CoulFMMState::continuity(const CoulFMMTimeStepping &scheme,
                                                         int boundary, const Predicate &asleep_now)
{
  const bool absorb = scheme.absorbs();
  // [0]-[3] as CoulFMMTimeStepping::continuity() reads them; [4] changed since applied, [5]
  // absorbing, [6] absorbing and changed since applied
  uint64_t sums[7] = {0, 0, 0, 0, 0, 0, 0};
  double dq[2] = {0.0, 0.0};
  for (int i = 0; i < atom->nlocal; i++) {
    const double q = (atom->mask[i] & groupbit) ? atom->q[i] : 0.0, q_then = charge_then(i);
    // a static source (then or now) is not absorbed: its field is the static field's
    const bool absorbed = absorb && q != q_then && q_then != 0.0 && q != 0.0 &&
        !static_source_then(i) && !asleep_now(i);
    if (q != q_then && !absorbed) sums[1]++;
    if (q != q_then && q_then != 0.0 && !absorbed) sums[2]++;
    if (q != 0.0 && static_source_then(i) && !asleep_now(i)) sums[3]++;
    const bool changed = q != row[i][MTS::LAST_Q];
    if (changed) sums[4]++;
    if (absorbed) {
      sums[5]++;
      if (changed) sums[6]++;
      dq[0] += std::fabs(q - q_then);
      dq[1] += q - q_then;
    }
  }
  sums[0] = local_hashes();
  mpi.sum(sums, 7);
  if (absorb) mpi.sum(dq, 2);
  changes.since_applied = (double) sums[4];
  changes.absorbed = (double) sums[5];
  changes.absorbed_now = (double) sums[6];
  changes.sum_abs_dq = dq[0];
  changes.net_dq = dq[1];
  double box[4];
  cell(box);
  const bool periodic = boundary == static_cast<int>(gcfmm::Boundary::Periodic2D);
  if (!scheme.same_setting(boundary, force->qqrd2e, box, periodic)) return MTS::Continuity::NONE;
  return scheme.continuity(sums);
}

// unwrapping after a remap may differ in the last bits, hence a tolerance
MTS::Continuity CoulFMMState::continuation(const CoulFMMTimeStepping &scheme, int boundary,
                                          const Predicate &asleep_now)
{
  const MTS::Continuity c = continuity(scheme, boundary, asleep_now);
  if (c == MTS::Continuity::NONE) return c;
  const double tol = 1e-12 * std::max({domain->xprd, domain->yprd, domain->zprd});
  bool moved = false;
  double xu[3];
  for (int i = 0; i < atom->nlocal; i++) {
    if (charge_then(i) == 0.0) continue;
    domain->unmap(atom->x[i], atom->image[i], xu);
    for (int k = 0; k < 3; k++) moved = moved || fabs(xu[k] - position_applied(i)[k]) > tol;
  }
  return mpi.any(moved) ? MTS::Continuity::NONE : c;
}
