/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "coul_fmm_evaluator.h"

#include "coul_fmm_backend.h"
#include "coul_fmm_sleepers.h"
#include "coul_fmm_state.h"

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

#include "gcfmm/coulomb_backend.hpp"
#include "gcfmm/far_field.hpp"
#include "gcfmm/options.hpp"

#include <algorithm>
#include <array>
#include <exception>

using namespace LAMMPS_NS;


CoulFMMEvaluator::CoulFMMEvaluator(LAMMPS *lmp, const std::string &id, int bit,
                                   CoulFMMBackend &solver_backend) :
    Pointers(lmp), fix_id(id), groupbit(bit), opts(new gcfmm::Options), backend(solver_backend),
    mpi(solver_backend.communication()), fresh(nullptr), nmax_fresh(0), sleep_fix(nullptr),
    pair_energy(0.0), logged(false)
{
}

CoulFMMEvaluator::~CoulFMMEvaluator()
{
  memory->destroy(fresh);
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
  const bool solver_new = backend.create(distribute ? CoulFMMBackend::Kind::DISTRIBUTED
                                                    : CoulFMMBackend::Kind::REPLICATED,
                                         *opts);
  if (!sleep)
    sleepers.reset();
  else if (solver_new || !sleepers)
    backend.run([&] { sleepers = std::make_unique<CoulFMMSleepers>(lmp, *opts, groupbit); },
                nullptr, true);
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

int CoulFMMEvaluator::boundary() const
{
  return (int) opts->boundary;
}

void CoulFMMEvaluator::measure_error(CoulFMMTimeStepping &scheme, CoulFMMState &state)
{
  if (atom->nlocal > nmax_fresh) {
    nmax_fresh = atom->nmax;
    memory->destroy(fresh);
    memory->create(fresh, nmax_fresh, 4, "coul/fmm:fresh");
  }
  evaluate([this](int i) { return fresh[i]; }, false);
  double sums[2] = {0.0, 0.0};
  for (int i = 0; i < atom->nlocal; i++)
    if (!asleep(i))
      CoulFMMTimeStepping::add_error_sums(atom->q[i] * atom->q[i], state.field(i), fresh[i], sums);
  mpi.sum(sums, 2);
  scheme.record_check(sums);
}

/* ----------------------------------------------------------------------
   the one evaluation: the charges in (collect), the solver with the static sleepers' field
   added at this rank's share of the targets, the field out to the atoms (hand_back)
------------------------------------------------------------------------- */

void CoulFMMEvaluator::evaluate(const Rows &out, bool split)
{
  update_sleepers();
  split = split && split_active();
  for (int i = 0; i < atom->nlocal; i++) std::fill(out(i), out(i) + 4, 0.0);
  if (split) {
    pair_energy = 0.0;    // a full evaluation (keyword check) keeps the split's
    // the same sleepers on every rank: a failure here is seen by all
    backend.run([this] { sleepers->prepare(backend.cell()); },
                [this](size_t k) { return sleepers->source_tag(k); }, true);
  }
  int *mask = atom->mask;
  double *q = atom->q;
  auto charged = [&](int i) {
    return (mask[i] & groupbit) && q[i] != 0.0 && !(split && asleep(i));
  };
  GatheredCharges &in = collect(charged);
  const size_t n = in.size();
  if (diagnostics.charges == 0.0) return;
  result.assign(4 * n, 0.0);
  double *pot = result.data(), *ex = pot + n, *ey = pot + 2 * n, *ez = pot + 3 * n;
  size_t first = 0, last = 0;
  backend.solver().share(n, first, last);
  double qpot = 0.0;    // sum q pot^sleepers over this rank's share
  gcfmm::BackendInput input;
  input.n = n;
  input.x = in.x.data();
  input.y = in.y.data();
  input.z = in.z.data();
  input.q = in.q.data();
  input.ids = ids.data();
  gcfmm::BackendOutput output;
  output.pot = pot;
  output.ex = ex;
  output.ey = ey;
  output.ez = ez;
  // the distributed solver reports the ids it was given (the atom IDs), the replicated one
  // indices in the gathered order
  const bool by_id = backend.distributed();
  backend.run(
      [&] {
        backend.set_cell();
        backend.solver().evaluate(input, output);
        // the potential whose energy 1/2 sum q_i u_i has minus the applied forces as gradient
        // (differs from pot only for farfield average; doc/theory.md, eq. (4.10))
        backend.solver().energy_potential(pot);
        // the sleepers' field at this rank's share of the awake targets
        if (split) qpot = add_sleepers_field(in, first, last, pot, ex, ey, ez);
      },
      [&](size_t k) { return by_id ? (tagint) k : in.tag[k]; }, false);
  if (split) sum_pair_energy(qpot);
  hand_back(charged, in, out);
  record_diagnostics();
  log_parameters();
}

/* ----------------------------------------------------------------------
   replicated: every rank holds all charges, sorted by atom ID (the same tree everywhere,
   results bit for bit independent of the rank count); distributed: each rank its own
------------------------------------------------------------------------- */

GatheredCharges &CoulFMMEvaluator::collect(const std::function<bool(int)> &charged)
{
  ids.clear();
  if (!backend.distributed()) {
    mpi.gather(charged, gathered);
    diagnostics.charges = (double) gathered.size();
    return gathered;
  }
  double **x = atom->x;
  local.x.clear();
  local.y.clear();
  local.z.clear();
  local.q.clear();
  local.tag.clear();
  for (int i = 0; i < atom->nlocal; i++) {
    if (!charged(i)) continue;
    local.x.push_back(x[i][0]);
    local.y.push_back(x[i][1]);
    local.z.push_back(x[i][2]);
    local.q.push_back(atom->q[i]);
    local.tag.push_back(atom->tag[i]);
    ids.push_back((int64_t) atom->tag[i]);
  }
  double total = (double) local.size();
  mpi.sum(&total, 1);
  diagnostics.charges = total;
  return local;
}

/* ----------------------------------------------------------------------
   the field in LAMMPS units to the local atoms: replicated, each value computed by one rank
   and summed to the owners in the order gather() took them; distributed, in place
------------------------------------------------------------------------- */

void CoulFMMEvaluator::hand_back(const std::function<bool(int)> &charged,
                                 const GatheredCharges &in, const Rows &out)
{
  const size_t n = in.size();
  const double *pot = result.data(), *ex = pot + n, *ey = pot + 2 * n, *ez = pot + 3 * n;
  values.resize(4 * n);
  for (size_t k = 0; k < n; k++) {
    const double v[4] = {ex[k], ey[k], ez[k], pot[k]};
    std::copy(v, v + 4, &values[4 * k]);
  }
  if (!backend.distributed()) mpi.return_to_owners(gathered, values, mine);
  const std::vector<double> &own = backend.distributed() ? values : mine;
  const double c = backend.scale();
  size_t m = 0;
  for (int i = 0; i < atom->nlocal; i++) {
    if (!charged(i)) continue;
    double *o = out(i);
    for (int k = 0; k < 4; k++) o[k] = c * own[4 * m + k];
    m++;
  }
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
    throw CoulFMMBackend::Failure(
        fmt::format("atom {} is at the position of the sleeping atom {} (closer than {:g} of "
                    "the solver's length unit): their Coulomb force is not defined",
                    targets.tag[first + e.first()], sleepers->source_tag(e.second()),
                    gcfmm::kCoincidenceRadius));
  }
}

void CoulFMMEvaluator::sum_pair_energy(double qpot)
{
  mpi.sum(&qpot, 1);
  pair_energy = 0.5 * backend.scale() * qpot;
}

/* ----------------------------------------------------------------------
   the global vector's solver elements of the last evaluation, the same on every rank: the
   parameters, M2L and P2P counts (all ranks), the largest bytes received by a rank (all of
   this evaluation's collectives) and the largest solver memory of a rank
------------------------------------------------------------------------- */

void CoulFMMEvaluator::record_diagnostics()
{
  const gcfmm::BackendStats st = backend.solver().stats();
  diagnostics.estimated_error = st.estimated_error;
  diagnostics.order = st.order;
  diagnostics.theta = st.theta;
  diagnostics.leaf = st.leaf;
  double counts[2] = {st.m2l, st.p2p};
  if (!st.counts_whole) mpi.sum(counts, 2);    // each rank's own interactions
  double maxima[2] = {mpi.collectives.take_received_bytes(), st.memory_bytes};
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
                 backend.distributed() ? "distributed" : "replicated", comm->nprocs, d.order, d.theta, d.leaf,
                 free_space ? std::string()
                            : fmt::format(", images = {}, farfield = {}", opts->images,
                                          ffname[(int) opts->farfield]),
                 d.estimated_error, opts->accuracy, d.bytes_received, d.solver_memory);
}

double CoulFMMEvaluator::sleeper_source_energy()
{
  return sleepers ? backend.scale() * sleepers->source_energy() : 0.0;
}

double CoulFMMEvaluator::memory_usage() const
{
  // gathered (or local) charges and results
  double bytes = (double) ((gathered.x.capacity() + local.x.capacity()) * 14) * sizeof(double);
  if (sleepers) bytes += sleepers->memory_usage();
  return bytes;
}
