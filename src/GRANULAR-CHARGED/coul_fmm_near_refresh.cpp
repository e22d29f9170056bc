/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "coul_fmm_near_refresh.h"

#include "coul_fmm_state.h"

#include "coul_fmm_time_stepping.h"

#include "gcfmm/charge_pair_change.hpp"
#include "gcfmm/dipole_kernels.hpp"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "fix.h"
#include "force.h"
#include "memory.h"
#include "neigh_list.h"
#include "neigh_request.h"
#include "neighbor.h"

#include <algorithm>
#include <cmath>

using namespace LAMMPS_NS;
using MTS = CoulFMMTimeStepping;

namespace {
// a pair of the half list without newton counts once over all ranks: a ghost j is a local atom
// elsewhere (or an image here) whose own list holds the pair the other way round
double near_pair_weight(int j, int nlocal)
{
  return j < nlocal ? 1.0 : 0.5;
}
}    // namespace

CoulFMMNearRefresh::CoulFMMNearRefresh(LAMMPS *lmp, Fix *owner) :
    Pointers(lmp), fix(owner), list(nullptr), delta(nullptr), near_now(nullptr), near_then(nullptr),
    sending_charges(false), nmax_delta(0), nmax_out(0), pair_now{}, pair_then{}, pair_dg{}, pair_r2now(nullptr),
    pair_r2then(nullptr), simd_path(gcsimd::default_simd_path()), held_valid(false),
    leaving(false), near_pairs_evaluated(-1.0), pairs_lost(false), held_ncalls(-1), held_lastcall(-1), held_box{}
{
}

CoulFMMNearRefresh::~CoulFMMNearRefresh()
{
  memory->destroy(delta);
  memory->destroy(near_now);
  memory->destroy(near_then);
}

void CoulFMMNearRefresh::request(double cutoff)
{
  auto *req = neighbor->add_request(fix, NeighConst::REQ_NEWTON_OFF);
  req->set_cutoff(cutoff);
  const double ghost = cutoff + neighbor->skin;
  if (ghost > comm->cutghostuser) {
    comm->cutghostuser = ghost;
    if (comm->me == 0)
      utils::logmesg(lmp, "Fix coul/fmm {}: ghost cutoff raised to {:.6g} for near {:.6g}\n",
                     fix->id, ghost, cutoff);
  }
}

void CoulFMMNearRefresh::compute(const MTS &scheme, const CoulFMMState &state, bool into_then,
                                 double trend)
{
  const int nlocal = atom->nlocal;
  if (atom->nmax > nmax_out) {
    nmax_out = atom->nmax;
    memory->destroy(near_now);
    memory->destroy(near_then);
    memory->create(near_now, nmax_out, 4, "coul/fmm:near_now");
    memory->create(near_then, nmax_out, 4, "coul/fmm:near_then");
  }
  double **out = into_then ? near_then : near_now;
  leaving = false;
  for (int i = 0; i < nlocal; i++)
    for (int k = 0; k < 4; k++) out[i][k] = 0.0;
  if (into_then) {
    exchange_displacements(state);
    compute_all(scheme, trend, out);
  } else {
    // every rank decides alike: neighbor builds, evaluations and the box are global
    if (!holds_current()) hold_pairs(scheme, state);
    compute_held(scheme, trend, out);
    leaving = leaving || pairs_lost;
  }
  const double c = force->qqrd2e;
  for (int i = 0; i < nlocal; i++)
    for (int k = 0; k < 4; k++) out[i][k] *= c;
}

// each atom's Delta row (local atoms from the state, ghosts by the fix's forward communication)
void CoulFMMNearRefresh::exchange_displacements(const CoulFMMState &state)
{
  const int nlocal = atom->nlocal, nall = nlocal + atom->nghost;
  if (nall > nmax_delta) {
    nmax_delta = atom->nmax;
    memory->destroy(delta);
    memory->create(delta, nmax_delta, MTS::DELTA_COLS, "coul/fmm:near_delta");
  }
  double **x = atom->x;
  double xu[3];
  for (int i = 0; i < nlocal; i++) {
    domain->unmap(x[i], atom->image[i], xu);
    MTS::displacements(xu, state.evaluation(i), delta[i]);
  }
  comm->forward_comm(fix);
}

void CoulFMMNearRefresh::share_charges()
{
  sending_charges = true;
  comm->forward_comm(fix, 1);
  sending_charges = false;
}

bool CoulFMMNearRefresh::charged(int i) const
{
  return (atom->mask[i] & fix->groupbit) && atom->q[i] != 0.0;
}

// the list's pairs of charged atoms of the group, in its order: visit(i, j, now) with their
// separation now, then done_with(i) after the pairs of each charged i
template <typename Visit, typename DoneWith>
void CoulFMMNearRefresh::for_each_charged_separation(Visit &&visit, DoneWith &&done_with) const
{
  double **x = atom->x;
  for (int ii = 0; ii < list->inum; ii++) {
    const int i = list->ilist[ii];
    if (!charged(i)) continue;
    for (int jj = 0; jj < list->numneigh[i]; jj++) {
      const int j = list->firstneigh[i][jj] & NEIGHMASK;
      if (!charged(j)) continue;
      double now[3];
      for (int k = 0; k < 3; k++) now[k] = x[i][k] - x[j][k];
      visit(i, j, now);
    }
    done_with(i);
  }
}

// as for_each_charged_separation, with the separation at the evaluation too (from the
// displacements): visit(i, j, now, then)
template <typename Visit, typename DoneWith>
void CoulFMMNearRefresh::for_each_charged_pair(Visit &&visit, DoneWith &&done_with) const
{
  for_each_charged_separation(
      [&](int i, int j, const double *now) {
        double then[3];
        MTS::separation_then(now, delta[i], delta[j], then);
        visit(i, j, now, then);
      },
      done_with);
}

// the pairs of charged atoms of the group in the list's order (their j and, per i, where
// they end): their separations now and at the evaluation, then the kernel differences of all
// of them in one call (SIMD), then the sums in the same order as pair by pair
void CoulFMMNearRefresh::compute_all(const MTS &scheme, double trend, double **out)
{
  const int nlocal = atom->nlocal;
  double *q = atom->q;
  int npairs = 0;
  for (int ii = 0; ii < list->inum; ii++)
    if (charged(list->ilist[ii])) npairs += list->numneigh[list->ilist[ii]];
  grow_pairs(npairs);
  pair_i.clear();
  int p = 0;
  for_each_charged_pair(
      [&](int, int j, const double *now, const double *then) {
        for (int k = 0; k < 3; k++) {
          pair_now[k][p] = now[k];
          pair_then[k][p] = then[k];
        }
        pair_j[p++] = j;
      },
      [&](int i) { pair_i.push_back({i, p}); });
  gcfmm::charge_pair_change(p, {pair_now[0], pair_now[1], pair_now[2]},
                            {pair_then[0], pair_then[1], pair_then[2]},
                            {pair_dg[0], pair_dg[1], pair_dg[2], pair_dg[3], pair_r2now, pair_r2then},
                            simd_path);

  // each pair once: at i from j q_j dg, at j from i -q_i dg (field) and q_i dg (potential). A
  // ghost j is a local atom elsewhere (or an image here) whose own list holds the pair the
  // other way round: only i is updated. Charges changed since the evaluation add their change
  // at the separation then (CoulFMMTimeStepping::add_charge_change).
  p = 0;
  for (const auto &[i, end] : pair_i) {
    double e[4] = {0.0, 0.0, 0.0, 0.0};
    const double dqi = q[i] - delta[i][MTS::DELTA_Q];
    for (; p < end; p++) {
      const int j = pair_j[p];
      const double now[3] = {pair_now[0][p], pair_now[1][p], pair_now[2][p]};
      double dg[4] = {pair_dg[0][p], pair_dg[1][p], pair_dg[2][p], pair_dg[3][p]};
      if (!scheme.near_pair_finish(now, pair_r2now[p], pair_r2then[p], delta[i], delta[j], trend,
                                   dg))
        continue;
      for (int k = 0; k < 4; k++) e[k] += q[j] * dg[k];
      if (j < nlocal) {
        for (int k = 0; k < 3; k++) out[j][k] -= q[i] * dg[k];
        out[j][3] += q[i] * dg[3];
      }
      const double dqj = q[j] - delta[j][MTS::DELTA_Q];
      if (dqi != 0.0 || dqj != 0.0) {
        gcfmm::FieldTerms<double> t;
        gcfmm::charge_terms<false>(1.0, pair_then[0][p], pair_then[1][p], pair_then[2][p],
                                   1.0 / std::sqrt(pair_r2then[p]), t);
        const double then[4] = {t.ex, t.ey, t.ez, t.pot};
        MTS::add_charge_change(dqi, dqj, then, e, j < nlocal ? out[j] : nullptr);
      }
    }
    for (int k = 0; k < 4; k++) out[i][k] += e[k];
  }
}

void CoulFMMNearRefresh::record_evaluation(double near_cutoff)
{
  const double cutsq = near_cutoff * near_cutoff;
  const int nlocal = atom->nlocal;
  double mine = 0.0;
  for_each_charged_separation(
      [&](int, int j, const double *now) {
        const double r2 = now[0] * now[0] + now[1] * now[1] + now[2] * now[2];
        if (r2 < cutsq && r2 != 0.0) mine += near_pair_weight(j, nlocal);
      },
      [](int) {});
  MPI_Allreduce(&mine, &near_pairs_evaluated, 1, MPI_DOUBLE, MPI_SUM, world);
  pairs_lost = false;
}

void CoulFMMNearRefresh::box_now(double box[9]) const
{
  const double now[9] = {domain->boxlo[0], domain->boxlo[1], domain->boxlo[2],
                         domain->prd[0],   domain->prd[1],   domain->prd[2],
                         domain->xy,       domain->xz,       domain->yz};
  std::copy(now, now + 9, box);
}

bool CoulFMMNearRefresh::holds_current() const
{
  if (!held_valid || neighbor->ncalls != held_ncalls || neighbor->lastcall != held_lastcall)
    return false;
  double box[9];
  box_now(box);
  return std::equal(box, box + 9, held_box);
}

// the list's pairs of charged atoms of the group, with what stays fixed until the next list
// build or evaluation: the separation at the evaluation (its square and terms) and the change
// the slope carries. A pair coincident at the evaluation is never refreshed: left out.
void CoulFMMNearRefresh::hold_pairs(const MTS &scheme, const CoulFMMState &state)
{
  exchange_displacements(state);
  held.clear();
  held_i.clear();
  const double cut = scheme.settings().near_cutoff, cutsq = cut * cut;
  double near_mine = 0.0;
  for_each_charged_pair(
      [&](int i, int j, const double *now, const double *then) {
        const double r2then = then[0] * then[0] + then[1] * then[1] + then[2] * then[2];
        if (r2then == 0.0) return;
        if (r2then < cutsq) near_mine += near_pair_weight(j, atom->nlocal);
        // two static sources (sleepers of fix sleep/gran at the evaluation): neither moves until
        // one wakes, which forces an evaluation, and no slope covers them, so the pair's change
        // is zero to the last bit; left out of the held pairs, still counted above
        if (delta[i][MTS::DELTA_STATIC] != 0.0 && delta[j][MTS::DELTA_STATIC] != 0.0) return;
        HeldPair h;
        h.j = j;
        h.qi_then = delta[i][MTS::DELTA_Q];
        h.qj_then = delta[j][MTS::DELTA_Q];
        h.r2then = r2then;
        gcfmm::FieldTerms<double> t;
        gcfmm::charge_terms<false>(1.0, then[0], then[1], then[2], 1.0 / std::sqrt(r2then), t);
        h.terms_then[0] = t.ex;
        h.terms_then[1] = t.ey;
        h.terms_then[2] = t.ez;
        h.terms_then[3] = t.pot;
        scheme.slope_pair_change(now, delta[i], delta[j], h.slope_change);
        held.push_back(h);
      },
      [&](int i) { held_i.push_back({i, (int) held.size()}); });
  // every pair closer than the cutoff at the evaluation must still be in the list
  double near_held = 0.0;
  MPI_Allreduce(&near_mine, &near_held, 1, MPI_DOUBLE, MPI_SUM, world);
  if (near_pairs_evaluated < 0.0)
    near_pairs_evaluated = near_held;
  else if (near_held < near_pairs_evaluated)
    pairs_lost = true;
  held_valid = true;
  held_ncalls = neighbor->ncalls;
  held_lastcall = neighbor->lastcall;
  box_now(held_box);
}

// between evaluations: per held pair only the separation now and its terms (all of them in one
// call, SIMD); dg = (K, 1/r)(now) - (K, 1/r)(then) - trend (slope change), summed in the list's
// order as compute_all does
void CoulFMMNearRefresh::compute_held(const MTS &scheme, double trend, double **out)
{
  const int nlocal = atom->nlocal;
  double **x = atom->x, *q = atom->q;
  grow_pairs((int) held.size());
  std::size_t p = 0;
  for (const auto &[i, end] : held_i) {
    const double xi[3] = {x[i][0], x[i][1], x[i][2]};
    for (; p < (std::size_t) end; p++) {
      const double *xj = x[held[p].j];
      for (int k = 0; k < 3; k++) pair_now[k][p] = xi[k] - xj[k];
    }
  }
  gcfmm::charge_terms_at(held.size(), {pair_now[0], pair_now[1], pair_now[2]},
                         {pair_dg[0], pair_dg[1], pair_dg[2], pair_dg[3], pair_r2now}, simd_path);
  const double cut = scheme.settings().near_cutoff, reach = cut + 0.5 * neighbor->skin;
  const double cutsq = cut * cut, reachsq = reach * reach;
  p = 0;
  for (const auto &[i, end] : held_i) {
    double e[4] = {0.0, 0.0, 0.0, 0.0};
    for (; p < (std::size_t) end; p++) {
      const HeldPair &h = held[p];
      if (h.r2then < cutsq && pair_r2now[p] >= reachsq) leaving = true;
      if (!scheme.near_pair_refreshed(pair_r2now[p], h.r2then, true)) continue;
      const int j = h.j;
      double dg[4];
      for (int k = 0; k < 4; k++) dg[k] = pair_dg[k][p] - h.terms_then[k] - trend * h.slope_change[k];
      for (int k = 0; k < 4; k++) e[k] += q[j] * dg[k];
      if (j < nlocal) {
        for (int k = 0; k < 3; k++) out[j][k] -= q[i] * dg[k];
        out[j][3] += q[i] * dg[3];
      }
      MTS::add_charge_change(q[i] - h.qi_then, q[j] - h.qj_then, h.terms_then, e,
                             j < nlocal ? out[j] : nullptr);
    }
    for (int k = 0; k < 4; k++) out[i][k] += e[k];
  }
}

// twelve arrays of at least n (and at least one, so that the pointers are valid for n = 0);
// grown by half again at least, as the pair count creeps up with a growing bed
void CoulFMMNearRefresh::grow_pairs(int n)
{
  if (pair_buffer.size() >= 12 * std::max<std::size_t>(n, 1)) return;
  const std::size_t cap = std::max<std::size_t>(n, pair_buffer.size() / 12 * 3 / 2 + 1);
  pair_buffer.assign(12 * cap, 0.0);
  double *b = pair_buffer.data();
  for (auto &a : pair_now) a = b, b += cap;
  for (auto &a : pair_then) a = b, b += cap;
  for (auto &a : pair_dg) a = b, b += cap;
  pair_r2now = b;
  pair_r2then = b + cap;
  pair_j.resize(cap);
}

int CoulFMMNearRefresh::pack(int n, int *list_send, double *buf) const
{
  int m = 0;
  if (sending_charges) {
    for (int i = 0; i < n; i++) buf[m++] = atom->q[list_send[i]];
    return m;
  }
  for (int i = 0; i < n; i++)
    for (int k = 0; k < MTS::DELTA_COLS; k++) buf[m++] = delta[list_send[i]][k];
  return m;
}

void CoulFMMNearRefresh::unpack(int n, int first, const double *buf)
{
  int m = 0;
  if (sending_charges) {
    for (int i = first; i < first + n; i++) atom->q[i] = buf[m++];
    return;
  }
  for (int i = first; i < first + n; i++)
    for (int k = 0; k < MTS::DELTA_COLS; k++) delta[i][k] = buf[m++];
}

double CoulFMMNearRefresh::memory_usage() const
{
  return ((double) MTS::DELTA_COLS * nmax_delta + 8.0 * nmax_out + pair_buffer.size()) *
      sizeof(double) + (double) pair_j.size() * sizeof(int) +
      (double) pair_i.capacity() * sizeof(pair_i[0]) +
      (double) held.capacity() * sizeof(HeldPair) + (double) held_i.capacity() * sizeof(held_i[0]);
}
