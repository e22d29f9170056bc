/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "coul_fmm_evaluator.h"

#include "coul_fmm_sleepers.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "fix.h"
#include "force.h"
#include "group.h"
#include "memory.h"
#include "modify.h"
#include "pair.h"
#include "update.h"

#include "gcfmm/distributed_solver.hpp"
#include "gcfmm/far_field.hpp"
#include "gcfmm/options.hpp"
#include "gcfmm/solver.hpp"

#include <algorithm>
#include <array>
#include <exception>

using namespace LAMMPS_NS;

namespace {
// a coincidence involving a static source, with its message in atom IDs
struct SleeperCoincidence {
  std::string message;
};
}    // namespace

CoulFMMEvaluator::CoulFMMEvaluator(LAMMPS *lmp, const std::string &id, int bit) :
    Pointers(lmp), fix_id(id), groupbit(bit), opts(new gcfmm::Options), distributed(false),
    solver_boundary(-1), mpi(lmp), fresh(nullptr), nmax_fresh(0), sleep_fix(nullptr),
    pair_energy(0.0), logged(false)
{
}

CoulFMMEvaluator::~CoulFMMEvaluator()
{
  memory->destroy(fresh);
}

void CoulFMMEvaluator::set_geometry(gcfmm::Options &o, bool bed_given)
{
  const int px = domain->xperiodic, py = domain->yperiodic, pz = domain->zperiodic;
  if (!px && !py && !pz)
    o.boundary = gcfmm::Boundary::Free;
  else if (px && py && !pz)
    o.boundary = gcfmm::Boundary::Periodic2D;
  else
    error->all(FLERR,
               "Fix coul/fmm requires boundary f f f (free space) or p p f (periodic in x "
               "and y, open in z), got periodicity {} {} {}",
               px ? "p" : "f", py ? "p" : "f", pz ? "p" : "f");
  const bool periodic = o.boundary == gcfmm::Boundary::Periodic2D;
  const bool exact = periodic && o.farfield == gcfmm::FarField::Exact;
  if (exact && o.images == 0)
    error->all(FLERR,
               "Fix coul/fmm farfield exact with boundary p p f needs images >= 1, got "
               "images 0 (the far-field kernel of the exact lattice sum is singular inside the "
               "cell then): use images >= 1, or farfield average or none");
  // the exact far field meets the requested accuracy only for cells close to square
  const double aspect = MAX(domain->xprd, domain->yprd) / MIN(domain->xprd, domain->yprd);
  if (exact && aspect > gcfmm::PeriodicFarField::kMaxAspect)
    error->all(FLERR,
               "Fix coul/fmm farfield exact supports cells with max(Lx, Ly) / min(Lx, Ly) "
               "<= {:g}, got {:g}: use farfield average or none, or a cell closer to square",
               gcfmm::PeriodicFarField::kMaxAspect, aspect);
  if (bed_given && !(periodic && o.farfield == gcfmm::FarField::Average))
    error->all(FLERR,
               "Fix coul/fmm keyword bed applies only to farfield average with boundary p p f");
}

void CoulFMMEvaluator::check_counted_once(Fix *self)
{
  const bool me0 = comm->me == 0;
  if (force->kspace && me0)
    error->warning(FLERR,
                   "Fix coul/fmm is used together with a kspace style: Coulomb "
                   "interactions may be counted twice");
  // a pair style with a Coulomb part (coul/cut, lj/cut/coul/long, ... or a hybrid sub-style)
  // adds the same interactions again for the pairs within its cutoff
  int dim = 0;
  if (force->pair && me0 && (force->pair->extract("cut_coul", dim) || force->pair_match("coul", 0)))
    error->warning(FLERR,
                   "Fix coul/fmm {} is used together with pair style {}, which computes "
                   "Coulomb interactions too: they are counted twice within its cutoff (use a pair "
                   "style without a coul part)",
                   fix_id, force->pair_style);
  // fixes on disjoint groups are allowed, but do not see each other
  for (auto *other : modify->get_fix_by_style("^coul/fmm$")) {
    if (other == self) continue;
    const int both = groupbit | group->bitmask[other->igroup];
    double shared = 0.0;
    for (int i = 0; i < atom->nlocal; i++)
      if ((atom->mask[i] & both) == both && atom->q[i] != 0.0) shared += 1.0;
    mpi.sum(&shared, 1);
    if (shared > 0.0)
      error->all(FLERR,
                 "Fix coul/fmm {} and fix coul/fmm {} share {} charged atoms: their "
                 "Coulomb interactions would be counted twice",
                 fix_id, other->id, (bigint) shared);
    if (me0)
      error->warning(FLERR,
                     "Fix coul/fmm {} and fix coul/fmm {} act on disjoint groups: charges "
                     "of one group do not interact with those of the other",
                     fix_id, other->id);
  }
}

void CoulFMMEvaluator::init(const gcfmm::Options &options, Fix *sleep, bool virial,
                            bool distribute)
{
  *opts = options;
  if (sleep && opts->boundary == gcfmm::Boundary::Periodic2D &&
      opts->farfield == gcfmm::FarField::Average)
    error->all(FLERR,
               "Fix coul/fmm {} farfield average cannot treat the sleepers of fix sleep/gran "
               "{} as a static source (the average field is no pair interaction): use farfield "
               "exact or none, or keyword sleepers full",
               fix_id, sleep->id);
  if (sleep && virial)
    error->all(FLERR,
               "Fix coul/fmm {}: the virial with the static sleepers of fix sleep/gran {} "
               "would lack the sleepers' share (their forces are not computed): use keyword "
               "sleepers full, or fix_modify {} virial no",
               fix_id, sleep->id, fix_id);
  // the solver (tree memory, far-field operator) is kept across runs; the boundary is the only
  // option init() can change
  const bool solver_new = solver_boundary != (int) opts->boundary || distribute != distributed ||
      (!solver && !distributed_solver);
  distributed = distribute;
  try {
    if (solver_new) {
      solver.reset();
      distributed_solver.reset();
      if (distributed)
        distributed_solver = std::make_unique<gcfmm::DistributedSolver>(*opts, mpi.collectives);
      else
        solver = std::make_unique<gcfmm::Solver>(*opts);
    }
    if (!sleep)
      sleepers.reset();
    else if (solver_new || !sleepers)
      sleepers = std::make_unique<CoulFMMSleepers>(lmp, *opts, groupbit);
  } catch (std::exception &e) {
    error->all(FLERR, "Fix coul/fmm: FMM library: {}", e.what());
  }
  solver_boundary = (int) opts->boundary;
  sleep_fix = sleep;
  logged = false;
}

void CoulFMMEvaluator::update_sleepers()
{
  if (!sleepers) return;
  // fix sleep/gran's state, through its extract() names (fix_sleep_gran.h)
  int dim = 0;
  const auto *asleep = static_cast<const double *>(sleep_fix->extract("sleeping", dim));
  sleepers->use(asleep, *static_cast<bigint *>(sleep_fix->extract("generation", dim)));
}

bool CoulFMMEvaluator::asleep(int i) const
{
  return sleepers && sleepers->asleep(i);
}

/* ----------------------------------------------------------------------
   how the stored evaluation relates to the atoms now: SAME charges (same IDs, same values) in
   the same geometry and units, charges ADDED (fix deposit; or static sources woken) with all
   those of the evaluation still there and unchanged, or NONE. The sum of hashes is an integer
   sum (modulo 2^64): exact and the same however the atoms are distributed.
------------------------------------------------------------------------- */

CoulFMMTimeStepping::Continuity CoulFMMEvaluator::continuity(const CoulFMMTimeStepping &scheme,
                                                             double **state)
{
  using MTS = CoulFMMTimeStepping;
  const double box[4] = {domain->boxlo[0], domain->boxlo[1], domain->xprd, domain->yprd};
  if (!scheme.same_setting((int) opts->boundary, force->qqrd2e, box,
                           opts->boundary == gcfmm::Boundary::Periodic2D))
    return MTS::Continuity::NONE;
  uint64_t sums[4] = {0, 0, 0, 0};    // as CoulFMMTimeStepping::continuity() reads them
  update_sleepers();
  for (int i = 0; i < atom->nlocal; i++) {
    const double q = (atom->mask[i] & groupbit) ? atom->q[i] : 0.0, q_then = state[i][MTS::Q];
    if (q_then != 0.0) sums[0] += coul_fmm_charge_hash(atom->tag[i], q_then);
    if (q != q_then) sums[1]++;
    if (q != q_then && q_then != 0.0) sums[2]++;
    if (q != 0.0 && state[i][MTS::ASLEEP] != 0.0 && !asleep(i)) sums[3]++;
  }
  mpi.sum(sums, 4);
  return scheme.continuity(sums);
}

// unwrapping after a remap may differ in the last bits, hence a tolerance
bool CoulFMMEvaluator::continues(const CoulFMMTimeStepping &scheme, double **state)
{
  using MTS = CoulFMMTimeStepping;
  if (continuity(scheme, state) != MTS::Continuity::SAME) return false;
  const double tol = 1e-12 * MAX(MAX(domain->xprd, domain->yprd), domain->zprd);
  bool moved = false;
  double xu[3];
  for (int i = 0; i < atom->nlocal; i++) {
    if (state[i][MTS::Q] == 0.0) continue;
    domain->unmap(atom->x[i], atom->image[i], xu);
    for (int k = 0; k < 3; k++) moved = moved || fabs(xu[k] - state[i][MTS::LAST_X + k]) > tol;
  }
  return !mpi.any(moved);
}

void CoulFMMEvaluator::measure_error(CoulFMMTimeStepping &scheme, double **applied)
{
  if (atom->nlocal > nmax_fresh) {
    nmax_fresh = atom->nmax;
    memory->destroy(fresh);
    memory->create(fresh, nmax_fresh, 4, "coul/fmm:fresh");
  }
  evaluate(fresh, 0, false);
  double sums[2] = {0.0, 0.0};
  for (int i = 0; i < atom->nlocal; i++)
    if (!asleep(i))
      CoulFMMTimeStepping::add_error_sums(atom->q[i] * atom->q[i], applied[i], fresh[i], sums);
  mpi.sum(sums, 2);
  scheme.record_check(sums);
}

void CoulFMMEvaluator::record(CoulFMMTimeStepping &scheme, double **state)
{
  auto &then = scheme.evaluated;
  then.charges = 0;
  for (int i = 0; i < atom->nlocal; i++)
    if (state[i][CoulFMMTimeStepping::Q] != 0.0)
      then.charges += coul_fmm_charge_hash(atom->tag[i], state[i][CoulFMMTimeStepping::Q]);
  mpi.sum(&then.charges, 1);
  then.step = update->ntimestep;
  then.qqrd2e = force->qqrd2e;
  then.boundary = (int) opts->boundary;
  const double box[4] = {domain->boxlo[0], domain->boxlo[1], domain->xprd, domain->yprd};
  std::copy(box, box + 4, then.box);
}

/* ---------------------------------------------------------------------- */

void CoulFMMEvaluator::evaluate(double **out, int col, bool split)
{
  update_sleepers();
  split = split && split_active();
  for (int i = 0; i < atom->nlocal; i++)
    for (int k = 0; k < 4; k++) out[i][col + k] = 0.0;
  if (split) {
    pair_energy = 0.0;    // a full evaluation (keyword check) keeps the split's
    // the same sleepers on every rank: a failure here is seen by all
    try {
      sleepers->prepare();
    } catch (gcfmm::CoincidentParticles &e) {
      error->all(FLERR,
                 "Fix coul/fmm: sleeping atoms {} and {} are at the same position: their "
                 "Coulomb force is not defined",
                 sleepers->source_tag(e.first()), sleepers->source_tag(e.second()));
    } catch (std::exception &e) {
      error->all(FLERR, "Fix coul/fmm: FMM library (static sleepers): {}", e.what());
    }
  }
  int *mask = atom->mask;
  double *q = atom->q;
  auto charged = [&](int i) {
    return (mask[i] & groupbit) && q[i] != 0.0 && !(split && asleep(i));
  };
  const bool done = distributed ? evaluate_distributed(charged, out, col, split)
                                : evaluate_replicated(charged, out, col, split);
  if (!done) return;
  record_diagnostics();
  log_parameters();
}

/* ----------------------------------------------------------------------
   every rank holds all charges (sorted by atom ID: the same tree everywhere, results bit for
   bit independent of the rank count) and computes its share of the targets
------------------------------------------------------------------------- */

bool CoulFMMEvaluator::evaluate_replicated(const std::function<bool(int)> &charged, double **out,
                                           int col, bool split)
{
  mpi.gather(charged, gathered);
  const size_t n = gathered.size();
  if (n == 0) return false;
  diagnostics.charges = (double) n;
  result.assign(4 * n, 0.0);
  double *pot = result.data(), *ex = pot + n, *ey = pot + 2 * n, *ez = pot + 3 * n;
  double qpot = 0.0;    // sum q pot^sleepers over this rank's share
  const std::string failure = mpi.first_failure(guarded(
      [&] {
        if (opts->boundary == gcfmm::Boundary::Periodic2D) {
          solver->set_box(domain->boxlo[0], domain->boxlo[1], domain->xprd, domain->yprd);
          // boundary f in z keeps every atom in the box: one far-field set-up for the run
          // instead of one each time the charges' z range grows (e.g. during a deposition)
          solver->set_z_range(domain->boxlo[2], domain->boxhi[2]);
        }
        solver->build(n, gathered.x.data(), gathered.y.data(), gathered.z.data());
        // the ranks share the far field's anterpolation, which every one of them would
        // otherwise repeat: each computes its share, one in-place sum completes it (exact)
        const gcfmm::PartSum sum = [this](double *data, std::size_t count) {
          mpi.collectives.allreduce_sum(data, count);
        };
        solver->evaluate(gathered.q.data(), pot, ex, ey, ez, comm->me, comm->nprocs, sum);
        // the potential whose energy 1/2 sum q_i u_i has minus the applied forces as gradient
        // (differs from pot only for farfield average; doc/theory.md, eq. (4.10))
        solver->energy_potential(pot);
        // the sleepers' field at this rank's share of the awake targets (the return to the
        // owners sums the shares; the solver's own parts are disjoint the same way)
        const size_t first = n * comm->me / comm->nprocs, last = n * (comm->me + 1) / comm->nprocs;
        if (split) qpot = add_sleepers_field(gathered, first, last, pot, ex, ey, ez);
      },
      [&](size_t k) {
        return gathered.tag[k];
      }));
  if (!failure.empty())
    error->all(FLERR, Error::NOLASTLINE, "Fix coul/fmm: FMM library: {}", failure);
  if (split) sum_pair_energy(qpot);

  values.resize(4 * n);
  for (size_t k = 0; k < n; k++) {
    const double v[4] = {ex[k], ey[k], ez[k], pot[k]};
    std::copy(v, v + 4, &values[4 * k]);
  }
  mpi.return_to_owners(gathered, values, mine);
  // the received block is in the order gather() took this rank's atoms;
  // bare 1/r kernel -> LAMMPS units: qqrd2e includes the dielectric constant
  const double c = force->qqrd2e;
  size_t m = 0;
  for (int i = 0; i < atom->nlocal; i++) {
    if (!charged(i)) continue;
    for (int k = 0; k < 4; k++) out[i][col + k] = c * mine[4 * m + k];
    m++;
  }
  return true;
}

/* ----------------------------------------------------------------------
   every rank keeps its own charges: gcfmm::DistributedSolver exchanges the local essential
   trees (doc/fmm-distributed.md) through CoulFMMComm
------------------------------------------------------------------------- */

bool CoulFMMEvaluator::evaluate_distributed(const std::function<bool(int)> &charged, double **out,
                                            int col, bool split)
{
  double **x = atom->x;
  local.x.clear();
  local.y.clear();
  local.z.clear();
  local.q.clear();
  local.tag.clear();
  ids.clear();
  for (int i = 0; i < atom->nlocal; i++) {
    if (!charged(i)) continue;
    local.x.push_back(x[i][0]);
    local.y.push_back(x[i][1]);
    local.z.push_back(x[i][2]);
    local.q.push_back(atom->q[i]);
    local.tag.push_back(atom->tag[i]);
    ids.push_back((int64_t) atom->tag[i]);
  }
  const size_t n = local.size();
  double total = (double) n;
  mpi.sum(&total, 1);
  diagnostics.charges = total;
  if (total == 0.0) return false;
  result.assign(4 * n, 0.0);
  double *pot = result.data(), *ex = pot + n, *ey = pot + 2 * n, *ez = pot + 3 * n;
  double qpot = 0.0;
  const std::string failure = mpi.first_failure(guarded(
      [&] {
        if (opts->boundary == gcfmm::Boundary::Periodic2D) {
          distributed_solver->set_box(domain->boxlo[0], domain->boxlo[1], domain->xprd,
                                      domain->yprd);
          distributed_solver->set_z_range(domain->boxlo[2], domain->boxhi[2]);
        }
        distributed_solver->evaluate(n, local.x.data(), local.y.data(), local.z.data(),
                                     local.q.data(), ids.data(), pot, ex, ey, ez);
        distributed_solver->energy_potential(pot);
        if (split) qpot = add_sleepers_field(local, 0, n, pot, ex, ey, ez);
      },
      // DistributedSolver reports the ids it was given: the atom IDs
      [&](size_t id) {
        return (tagint) id;
      }));
  if (!failure.empty())
    error->all(FLERR, Error::NOLASTLINE, "Fix coul/fmm: FMM library: {}", failure);
  if (split) sum_pair_energy(qpot);
  const double c = force->qqrd2e;
  size_t m = 0;
  for (int i = 0; i < atom->nlocal; i++) {
    if (!charged(i)) continue;
    const double v[4] = {ex[m], ey[m], ez[m], pot[m]};
    for (int k = 0; k < 4; k++) out[i][col + k] = c * v[k];
    m++;
  }
  return true;
}

// ADD the sleepers' field at the targets [first, last) of `targets`; sum q pot^sleepers there
double CoulFMMEvaluator::add_sleepers_field(const GatheredCharges &targets, size_t first,
                                            size_t last, double *pot, double *ex, double *ey,
                                            double *ez)
{
  try {
    return sleepers->add_field(targets.x.data(), targets.y.data(), targets.z.data(),
                               targets.q.data(), first, last, pot, ex, ey, ez);
  } catch (gcfmm::CoincidentParticles &e) {
    throw SleeperCoincidence{
        fmt::format("atom {} is at the position of the sleeping atom {} (closer than {:g} of "
                    "the solver's length unit): their Coulomb force is not defined",
                    targets.tag[first + e.first()], sleepers->source_tag(e.second()),
                    gcfmm::kCoincidenceRadius)};
  }
}

void CoulFMMEvaluator::sum_pair_energy(double qpot)
{
  mpi.sum(&qpot, 1);
  pair_energy = 0.5 * force->qqrd2e * qpot;
}

// run the solver; "" or what failed, in LAMMPS terms (tag_of: an index of the solver's
// CoincidentParticles -> atom ID)
std::string CoulFMMEvaluator::guarded(const std::function<void()> &run,
                                      const std::function<tagint(size_t)> &tag_of)
{
  try {
    run();
  } catch (SleeperCoincidence &e) {
    return e.message;
  } catch (gcfmm::CoincidentParticles &e) {
    return fmt::format("atoms {} and {} are at the same position (closer than {:g} of the "
                       "solver's length unit): their Coulomb force is not defined",
                       tag_of(e.first()), tag_of(e.second()), gcfmm::kCoincidenceRadius);
  } catch (gcfmm::FarFieldTooLarge &e) {
    // the column's height (box or charges) sets the cost of the exact far field
    return fmt::format("{}. In LAMMPS terms: the charged column (or the box in z, with "
                       "boundary p p f) is {:.3g} times the cell side; use farfield average or "
                       "none, a box or a wall that keeps the particles lower (a lid), or "
                       "remove escaping particles (e.g. fix evaporate)",
                       e.what(), e.height_over_side());
  } catch (std::exception &e) {
    const std::string what = e.what();
    return what.empty() ? "unknown error" : what;
  }
  return "";
}

/* ----------------------------------------------------------------------
   the global vector's solver elements of the last evaluation, the same on every rank: the
   parameters, M2L and P2P counts (all ranks), the largest bytes received by a rank (all of
   this evaluation's collectives) and the largest solver memory of a rank
------------------------------------------------------------------------- */

void CoulFMMEvaluator::record_diagnostics()
{
  // gcfmm::Stats and gcfmm::DistributedStats name the parameters alike
  auto parameters = [this](const auto &st) {
    diagnostics.estimated_error = st.estimated_error;
    diagnostics.order = st.order;
    diagnostics.theta = st.theta;
    diagnostics.leaf = st.leaf;
    return std::array<double, 2>{(double) st.m2l_count, (double) st.p2p_pairs};
  };
  double maxima[2] = {mpi.collectives.take_received_bytes(), 0.0};
  std::array<double, 2> counts;
  if (distributed) {
    counts = parameters(distributed_solver->stats());
    maxima[1] = (double) distributed_solver->stats().memory_bytes;
    mpi.sum(counts.data(), 2);    // each rank's own interactions
  } else {
    counts = parameters(solver->stats());    // the whole evaluation's, on every rank
    maxima[1] = (double) solver->memory_bytes();
  }
  mpi.collectives.allreduce_max(maxima, 2);
  // the diagnostics' own reduction is not the evaluation's
  mpi.collectives.take_received_bytes();
  diagnostics.m2l = counts[0];
  diagnostics.p2p = counts[1];
  diagnostics.bytes_received = maxima[0];
  diagnostics.solver_memory = maxima[1];
}

void CoulFMMEvaluator::log_parameters()
{
  if (logged) return;
  logged = true;
  if (comm->me != 0) return;
  static const char *ffname[] = {"none", "average", "exact"};
  const bool free_space = opts->boundary == gcfmm::Boundary::Free;
  const auto &d = diagnostics;
  utils::logmesg(lmp,
                 "FMM Coulomb (fix coul/fmm {}): {} charged atoms, {}, {} solver on {} ranks\n"
                 "  order = {}, theta = {:.3g}, leaf = {}{}\n"
                 "  estimated relative RMS force error = {:.3g} (requested accuracy {:.3g})\n"
                 "  largest bytes received by a rank per evaluation = {:.4g}, largest solver "
                 "memory of a rank = {:.4g} bytes\n",
                 fix_id, (bigint) d.charges, free_space ? "free space" : "periodic in x y",
                 distributed ? "distributed" : "replicated", comm->nprocs, d.order, d.theta, d.leaf,
                 free_space ? std::string()
                            : fmt::format(", images = {}, farfield = {}", opts->images,
                                          ffname[(int) opts->farfield]),
                 d.estimated_error, opts->accuracy, d.bytes_received, d.solver_memory);
}

double CoulFMMEvaluator::sleeper_source_energy()
{
  return sleepers ? force->qqrd2e * sleepers->source_energy() : 0.0;
}

double CoulFMMEvaluator::memory_usage() const
{
  // gathered (or local) charges and results
  double bytes = (double) ((gathered.x.capacity() + local.x.capacity()) * 14) * sizeof(double);
  if (sleepers) bytes += sleepers->memory_usage();
  return bytes;
}
