/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "coul_fmm_polarizable.h"

#include "coul_fmm_backend.h"
#include "coul_fmm_state.h"
#include "coul_fmm_time_stepping.h"

#include "coul_fmm_comm.h"

#include "atom.h"
#include "fix.h"
#include "modify.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "force.h"
#include "update.h"

#include "gcfmm/coulomb_backend.hpp"
#include "gcfmm/dipole_kernels.hpp"
#include "gcfmm/far_field.hpp"
#include "gcfmm/near_pair_change.hpp"
#include "gcfmm/polarizable_solver.hpp"
#include "gcfmm/solver.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <numeric>

using namespace LAMMPS_NS;

CoulFMMPolarizable::CoulFMMPolarizable(LAMMPS *lmp, const Settings &settings, const Parts &p) :
    Pointers(lmp), s(settings), parts(p), groupbit(p.fix->groupbit), backend(*p.backend),
    mpi(p.backend->communication())
{
}

CoulFMMPolarizable::~CoulFMMPolarizable() = default;

/* ----------------------------------------------------------------------
   doc/fix_coul_fmm.rst, "Applied field, induced dipoles, electrode": every step, replicated
------------------------------------------------------------------------- */

void CoulFMMPolarizable::init()
{
  check_combinations();
  // the multiple time stepping of doc/polarization.md, section 8: the near pairs' change with
  // the dipoles held, the far part extrapolated (or held), no keyword check
  const auto &mts = parts.stepping->settings();
  const double half_cell = 0.5 * MIN(domain->xprd, domain->yprd);
  if (parts.opts->boundary == gcfmm::Boundary::Periodic2D && mts.every > 1 &&
      mts.near_cutoff >= half_cell)
    error->all(FLERR,
               "Fix coul/fmm near {:g} with efield, polarize or electrode must be smaller than "
               "half the periodic cell ({:g})",
               mts.near_cutoff, half_cell);
  init_solver(*parts.opts);
  set_time_stepping(mts.every > 1 ? mts.near_cutoff : 0.0, mts.every > 1,
                    mts.every > 1 && mts.extrapolate);
}

void CoulFMMPolarizable::check_combinations()
{
  if (parts.distributed)
    error->all(FLERR, "Fix coul/fmm efield, polarize and electrode need solver replicated");
  if (!modify->get_fix_by_style("^sleep/gran$").empty() && parts.sleepers_static)
    error->all(FLERR,
               "Fix coul/fmm efield, polarize and electrode need sleepers full with fix "
               "sleep/gran (the static sleepers' field has no dipoles or images)");
  // LAMMPS's fix efield pushes the charges only: with efield here it would count the field
  // twice, with polarize it would leave the dipoles blind to it
  if (!modify->get_fix_by_style("^efield").empty()) {
    if (s.efield)
      error->all(FLERR, "Fix coul/fmm efield and fix efield would both apply the field: use one");
    if (s.polarize)
      error->all(FLERR,
                 "Fix coul/fmm polarize with fix efield: fix efield's field would not "
                 "polarize the particles; give it to fix coul/fmm efield instead");
  }
  if (parts.qchange == QChange::ABSORB && comm->me == 0)
    error->warning(FLERR,
                   "Fix coul/fmm {}: qchange absorb has no effect with efield, polarize or "
                   "electrode (a changed charge is evaluated)",
                   parts.fix->id);
  if (parts.stepping->settings().check_every > 0 && comm->me == 0)
    error->warning(FLERR,
                   "Fix coul/fmm {}: check is ignored with efield, polarize or electrode (the "
                   "error of the time stepping is measured at every evaluation, vector element 9)",
                   parts.fix->id);
}

// F_i = q_i E_i + (p_i . grad) E_i and the energy of doc/polarization.md, eq. (3.4), evaluated
// on the schedule's steps and continued between them (section 8); other atoms or charges, or
// displacements too large for the periodic cell, are found by the continuation (advance)
bool CoulFMMPolarizable::evaluation_due()
{
  return parts.stepping->scheduled(update->ntimestep);
}

bool CoulFMMPolarizable::continue_last(double &energy)
{
  return advance(parts.state->field_rows(), parts.state->force_rows(), energy);
}

// every evaluation of a run measures the continuation's error and adapts the interval to it
double CoulFMMPolarizable::evaluate(Evaluation why)
{
  CoulFMMTimeStepping &stepping = *parts.stepping;
  CoulFMMState &state = *parts.state;
  const bool predict = why != Evaluation::FRESH;
  const double energy = solve(state.field_rows(), state.force_rows(), predict, stepping.stride());
  nevaluations += 1.0;
  if (predict) {
    if (prediction_error() >= 0.0) stepping.adapt(prediction_error());
    stepping.evaluated.step = update->ntimestep;
  }
  return energy;
}

bool CoulFMMPolarizable::acts_on(int i) const
{
  return (atom->mask[i] & groupbit) != 0;
}

void CoulFMMPolarizable::init_solver(const gcfmm::Options &opts)
{
  if (s.polarize && !atom->radius_flag)
    error->all(FLERR,
               "Fix coul/fmm polarize requires per-atom radii (an atom style with radius, "
               "e.g. sphere)");
  // the bare kernel times qqrd2e is the Coulomb law in the medium of the dielectric command,
  // whose permittivity the polarizability (doc/polarization.md, eq. (3.2)) must use too
  if (s.polarize && s.eps_medium > 0.0 && std::fabs(s.eps_medium - force->dielectric) > 1e-12 * s.eps_medium)
    error->all(FLERR,
               "Fix coul/fmm polarize: medium permittivity {:g} differs from the dielectric "
               "command's {:g}, which scales every Coulomb force; set dielectric {:g}",
               s.eps_medium, force->dielectric, s.eps_medium);
  // a conductor has no tangential field at its surface: the applied field must be normal
  if (s.electrode && s.efield && (s.field[0] != 0.0 || s.field[1] != 0.0))
    error->all(FLERR,
               "Fix coul/fmm efield {:g} {:g} {:g} with electrode: a grounded plane allows only a "
               "field normal to it (efield 0 0 Ez)",
               s.field[0], s.field[1], s.field[2]);
  if (s.electrode && s.electrode_z >= domain->boxhi[2])
    error->all(FLERR, "Fix coul/fmm electrode {:g} is not below the box top {:g}", s.electrode_z,
               domain->boxhi[2]);
  periodic = opts.boundary == gcfmm::Boundary::Periodic2D;
  if (periodic && opts.farfield == gcfmm::FarField::Average)
    error->all(FLERR,
               "Fix coul/fmm efield, polarize and electrode need farfield exact or none (the "
               "average far field smears charges only)");
  backend.create(CoulFMMBackend::Kind::POLARIZABLE, opts, s.polarize);
  gcfmm::PolarizableSolver &solver = backend.polarizable().solver();
  induction_tolerance = solver.induction_tolerance();    // gcfmm::Options::induction_tolerance
  gcfmm::PolarizableEnvironment env;
  // LAMMPS field units (force = qe2f q E) -> bare units (force = qqrd2e q E_bare)
  const double to_bare = force->qe2f / force->qqrd2e;
  env.applied_field = {to_bare * s.field[0], to_bare * s.field[1], to_bare * s.field[2]};
  applied = env.applied_field;
  env.electrode = s.electrode;
  env.electrode_z = s.electrode_z;
  solver.set_environment(env);
}

// every rank: the group's atoms of all ranks, sorted by ID (CoulFMMComm::gather), with their
// polarizabilities from the radii
void CoulFMMPolarizable::gather()
{
  const int bit = groupbit;
  mpi.gather([this, bit](int i) { return (atom->mask[i] & bit) != 0; }, gathered,
              s.polarize ? atom->radius : nullptr);
  const double beta = s.polarize
      ? gcfmm::clausius_mossotti(s.eps_particle, s.eps_medium > 0.0 ? s.eps_medium : force->dielectric)
      : 0.0;
  galpha.assign(gathered.size(), 0.0);
  if (s.polarize)
    for (size_t k = 0; k < gathered.size(); k++)
      galpha[k] = gcfmm::polarizability(beta, gathered.radius[k]);
}

// this rank's atoms of the group and their index in the gathered order (binary search by ID)
void CoulFMMPolarizable::map_local()
{
  local_i.clear();
  local_k.clear();
  for (int i = 0; i < atom->nlocal; i++) {
    if (!(atom->mask[i] & groupbit)) continue;
    local_i.push_back(i);
    local_k.push_back(std::lower_bound(gathered.tag.begin(), gathered.tag.end(), atom->tag[i]) -
                      gathered.tag.begin());
  }
}

// the atom that is not above the electrode (every rank sees the same gathered atoms)
std::string CoulFMMPolarizable::below_electrode() const
{
  for (size_t k = 0; k < gathered.size(); k++)
    if (s.electrode && !(gathered.z[k] > s.electrode_z))
      return fmt::format("atom {} (z = {:g}) is not above the electrode (z = {:g})", gathered.tag[k],
                         gathered.z[k], s.electrode_z);
  return {};
}

void CoulFMMPolarizable::set_time_stepping(double cutoff, bool measure_error, bool extrapolate_far)
{
  near_cutoff = cutoff;
  measure = measure_error;
  extrapolate = extrapolate_far;
}

// the last evaluation's atoms, with the same charges, continued to their positions now: `then`
// is where each was at the evaluation, unwrapped alike (now minus its displacement, the
// nearest periodic copy of it), so that every pair keeps its copy from then to now
bool CoulFMMPolarizable::near_change(gcfmm::NearChange &change, const std::vector<size_t> &targets)
{
  const size_t n = gathered.size();
  if (eval.tag.empty() || eval.tag != gathered.tag || eval.q != gathered.q) return false;
  const double period[3] = {domain->xprd, domain->yprd, 0.0};
  now.resize(3 * n);
  then.resize(3 * n);
  for (size_t k = 0; k < n; k++) {
    const double r[3] = {gathered.x[k], gathered.y[k], gathered.z[k]};
    for (int a = 0; a < 3; a++) {
      double d = r[a] - eval.x[3 * k + a];
      if (periodic && a < 2) d -= period[a] * std::round(d / period[a]);
      now[3 * k + a] = r[a];
      then[3 * k + a] = r[a] - d;
    }
  }
  if (!near) {
    change.field.assign(3 * targets.size(), 0.0);
    change.pot.assign(targets.size(), 0.0);
    change.force.assign(3 * targets.size(), 0.0);
    return true;
  }
  bool done = false;
  backend.run(
      [&] {
        done = near->compute(n, now.data(), then.data(), eval.q.data(),
                             s.polarize ? eval.p.data() : nullptr, targets.data(), targets.size(),
                             change);
      },
      [this](size_t k) { return gathered.tag[k % gathered.size()]; }, true,
      [this] { return below_electrode(); });
  return done;
}

// this rank's outputs from the stored evaluation plus `change` (null: none); returns the energy
double CoulFMMPolarizable::store(double **field, double **force_out, const gcfmm::NearChange *change,
                                 double steps)
{
  const int cols = s.polarize ? 7 : 4;    // the fix's per-atom columns
  for (int i = 0; i < atom->nlocal; i++) {
    for (int k = 0; k < cols; k++) field[i][k] = 0.0;
    for (int k = 0; k < 3; k++) force_out[i][k] = 0.0;
  }
  const double c = backend.scale();
  double energy = 0.0;
  for (size_t t = 0; t < local_k.size(); t++) {
    const int i = local_i[t];
    const size_t k = local_k[t];
    double u = eval.energy[k];
    if (change) {
      // U_i changes by 1/2 q dphi - q E_a . dr with the dipole held (polarizable_energy_term)
      const gcfmm::Vec3 dr{now[3 * k] - then[3 * k], now[3 * k + 1] - then[3 * k + 1],
                           now[3 * k + 2] - then[3 * k + 2]};
      u += gcfmm::polarizable_energy_term(eval.q[k], change->pot[t], applied, dr, gcfmm::Vec3{});
    }
    for (int a = 0; a < 3; a++) {
      field[i][a] = c * (eval.field[3 * k + a] + (change ? change->field[3 * t + a] : 0.0));
      if (s.polarize) field[i][4 + a] = eval.p[3 * k + a];
      force_out[i][a] = c * (eval.force[3 * k + a] + (change ? change->force[3 * t + a] : 0.0) +
                             steps * eval.slope[3 * k + a]);
    }
    field[i][3] = atom->q[i] != 0.0 ? 2.0 * c * u / atom->q[i] : 0.0;
    energy += c * u;
  }
  return energy;
}

bool CoulFMMPolarizable::advance(double **field, double **force_out, double &energy)
{
  gather();
  map_local();
  gcfmm::NearChange change;
  if (!near_change(change, local_k)) return false;
  energy = store(field, force_out, &change, extrapolate ? (double) (update->ntimestep - eval.step) : 0.0);
  return true;
}

double CoulFMMPolarizable::solve(double **field, double **force_out, bool predict, int stride)
{
  parts.state->check_charges(parts.fix->id);
  gather();
  map_local();
  const std::vector<tagint> &gtag = gathered.tag;
  const std::vector<double> &gz = gathered.z;
  const size_t n = gtag.size();
  // every atom's force the time stepping would have applied now without (held) and with the
  // far part's trend, to measure its error and to take the next trend (every rank alike)
  std::vector<double> held;
  const bigint step = update->ntimestep;
  const double steps = (double) (step - eval.step);
  if (measure) {
    gcfmm::NearChange change;
    all_k.resize(n);
    std::iota(all_k.begin(), all_k.end(), size_t(0));
    if (near_change(change, all_k)) {
      held.resize(3 * n);
      for (size_t k = 0; k < 3 * n; k++) held[k] = eval.force[k] + change.force[k];
    }
  }
  eval.tag.clear();
  if (n == 0) {
    last_prediction_error = -1.0;
    return store(field, force_out, nullptr, 0.0);
  }
  // warm start: the last solution of the atoms that are still there (both lists sorted by ID)
  gp.assign(3 * n, 0.0);
  const bool linear = predict && last_step == step - 1 && prev_step == step - 2;
  for (size_t k = 0, m = 0, l = 0; k < n && m < last_tag.size(); k++) {
    while (m < last_tag.size() && last_tag[m] < gtag[k]) m++;
    if (m == last_tag.size() || last_tag[m] != gtag[k]) continue;
    while (l < prev_tag.size() && prev_tag[l] < gtag[k]) l++;
    const bool both = linear && l < prev_tag.size() && prev_tag[l] == gtag[k];
    for (int a = 0; a < 3; a++)
      gp[3 * k + a] = both ? 2.0 * last_p[3 * m + a] - prev_p[3 * l + a] : last_p[3 * m + a];
  }
  // the solver's sources are the atoms, then (with an electrode) their images: every rank
  // solves the same system, so every rank sees the same failure
  eval.field.resize(3 * n);
  eval.force.resize(3 * n);
  eval.energy.resize(n);
  std::vector<double> e3(3 * n);
  gcfmm::BackendInput in;
  in.n = n;
  in.x = gathered.x.data();
  in.y = gathered.y.data();
  in.z = gz.data();
  in.q = gathered.q.data();
  in.alpha = s.polarize ? galpha.data() : nullptr;
  in.p = gp.data();
  gcfmm::BackendOutput out;
  out.ex = e3.data();
  out.ey = e3.data() + n;
  out.ez = e3.data() + 2 * n;
  out.force = eval.force.data();
  out.energy = eval.energy.data();
  backend.run(
      [&] {
        backend.set_cell();
        backend.solver().evaluate(in, out);
      },
      [&](size_t k) { return gtag[k % n]; }, true, [this] { return below_electrode(); });
  for (size_t k = 0; k < n; k++)
    for (int a = 0; a < 3; a++) eval.field[3 * k + a] = e3[a * n + k];
  const gcfmm::BackendStats rep = backend.solver().stats();
  diag.estimated_error = rep.estimated_error;
  diag.order = rep.order;
  diag.m2l = rep.m2l;
  diag.p2p = rep.p2p;
  diag.iterations = rep.iterations;
  diag.residual = rep.residual;
  if (s.polarize && !rep.converged)
    error->all(FLERR,
               "Fix coul/fmm polarize: the induced dipoles did not converge (residual {:.3g} > "
               "{:.3g} after {} iterations): the particles overlap too much for point dipoles",
               rep.residual, induction_tolerance,
               rep.iterations);
  prev_tag.swap(last_tag);
  prev_p.swap(last_p);
  prev_step = last_step;
  last_tag = gtag;
  last_p = gp;
  last_step = step;

  // the evaluation the time stepping continues
  eval.tag = gtag;
  eval.q = gathered.q;
  eval.x.resize(3 * n);
  for (size_t k = 0; k < n; k++) {
    eval.x[3 * k] = gathered.x[k];
    eval.x[3 * k + 1] = gathered.y[k];
    eval.x[3 * k + 2] = gz[k];
  }
  eval.p = gp;
  if (near_cutoff > 0.0) {
    gcfmm::NearGeometry geo;
    geo.periodic = periodic;
    geo.lx = domain->xprd;
    geo.ly = domain->yprd;
    geo.electrode = s.electrode;
    geo.electrode_z = s.electrode_z;
    near = std::make_unique<gcfmm::NearPairChange>(near_cutoff, geo);
  }

  // relative RMS of the continued forces (trend included) against these (eq. (8.2) of
  // doc/polarization.md); the new trend of the far part, eq. (8.3), from a whole interval (a
  // shorter one, after an insertion, would stretch the solver's own error between the two
  // evaluations over a longer one: the old trend is kept)
  last_prediction_error = -1.0;
  if (held.empty()) {
    eval.slope.assign(3 * n, 0.0);
  } else {
    using MTS = CoulFMMTimeStepping;
    double sums[2] = {0.0, 0.0};
    for (size_t k = 0; k < n; k++) {
      double predicted[3];
      for (int a = 0; a < 3; a++)
        predicted[a] = held[3 * k + a] + (extrapolate ? steps * eval.slope[3 * k + a] : 0.0);
      MTS::add_error_sums(1.0, predicted, &eval.force[3 * k], sums);
    }
    last_prediction_error = MTS::relative_rms(sums);
    if (!extrapolate)
      eval.slope.assign(3 * n, 0.0);
    else if (steps >= stride)
      for (size_t k = 0; k < 3 * n; k++) eval.slope[k] = MTS::slope(eval.force[k], held[k], steps);
  }
  eval.step = step;
  return store(field, force_out, nullptr, 0.0);
}


double CoulFMMPolarizable::memory_usage() const
{
  return (double) (gathered.x.capacity() * 6 + gp.capacity() + last_p.capacity() + prev_p.capacity() +
                   eval.x.capacity() * 6 + now.capacity() + then.capacity()) *
      sizeof(double) +
      (double) (gathered.tag.capacity() + last_tag.capacity() + prev_tag.capacity()) * sizeof(tagint);
}
