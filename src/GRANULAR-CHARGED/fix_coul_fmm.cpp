/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "fix_coul_fmm.h"

#include "coul_fmm_comm.h"
#include "coul_fmm_evaluator.h"
#include "coul_fmm_near_refresh.h"
#include "coul_fmm_polarizable.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "force.h"
#include "memory.h"
#include "modify.h"
#include "respa.h"
#include "update.h"

#include "gcfmm/far_field.hpp"
#include "gcfmm/options.hpp"
#include "gcfmm/solver.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <map>
#include <vector>

using namespace LAMMPS_NS;
using namespace FixConst;
using MTS = CoulFMMTimeStepping;

FixCoulFMM::FixCoulFMM(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), opts(new gcfmm::Options), mpi(new CoulFMMComm(lmp)),
    near(new CoulFMMNearRefresh(lmp, this)), bed_given(false), sleepers_static(true),
    distributed(false), nevaluations(0), energy_local(0.0), energy_all(0.0), energy_summed(false),
    ilevel_respa(0), field_cols(4), polar_force(nullptr), field(nullptr), eval_state(nullptr)
{
  scalar_flag = 1;
  extscalar = 1;
  vector_flag = 1;    // diagnostics: solver (error estimate, order, M2L, P2P), MTS check, schedule
  size_vector = 14;
  extvector = 0;
  global_freq = 1;
  energy_global_flag = 1;
  virial_global_flag = virial_peratom_flag = 1;
  peratom_flag = 1;
  size_peratom_cols = 4;
  peratom_freq = 1;
  dynamic_group_allow = 1;
  respa_level_support = 1;
  create_attribute = 1;    // atoms created by other fixes get a zero stored field (set_arrays)
  restart_global = 1;      // the evaluation schedule and the stored field survive a restart
  restart_peratom = 1;
  comm_forward = MTS::DELTA_COLS;    // displacements since the evaluations, for the near refresh

  parse_keywords(narg, arg);
  size_peratom_cols = field_cols;
  evaluator = std::make_unique<CoulFMMEvaluator>(lmp, id, groupbit);
  FixCoulFMM::grow_arrays(atom->nmax);
  atom->add_callback(Atom::GROW);
  atom->add_callback(Atom::RESTART);
  for (int i = 0; i < atom->nlocal; i++) FixCoulFMM::set_arrays(i);
}

void FixCoulFMM::parse_keywords(int narg, char **arg)
{
  MTS::Settings mts;
  // the keywords with one number, and where it goes
  const std::map<std::string, double *> reals = {{"accuracy", &opts->accuracy},
                                                 {"theta", &opts->theta},
                                                 {"tolerance", &mts.tolerance},
                                                 {"near", &mts.near_cutoff}};
  const std::map<std::string, int *> integers = {{"order", &opts->order},
                                                 {"leaf", &opts->leaf},
                                                 {"images", &opts->images},
                                                 {"every", &mts.every},
                                                 {"check", &mts.check_every}};
  CoulFMMPolarizable::Settings polar;
  bool any_polar = false;
  for (int iarg = 3; iarg < narg;) {
    const std::string key = arg[iarg];
    const bool known = reals.count(key) || integers.count(key) || key == "farfield" ||
        key == "bed" || key == "extrapolate" || key == "sleepers" || key == "solver" ||
        key == "efield" || key == "polarize" || key == "electrode" || key == "induction";
    if (!known) error->all(FLERR, iarg, "Unknown fix coul/fmm keyword: {}", key);
    // values of the keyword: polarize takes eps_p and an optional eps_m
    int nvals = key == "bed" ? 2 : (key == "efield" ? 3 : 1);
    if (key == "polarize" && iarg + 2 < narg && utils::is_double(arg[iarg + 2])) nvals = 2;
    if (iarg + nvals >= narg) utils::missing_cmd_args(FLERR, "fix coul/fmm " + key, error);
    const std::string v = arg[iarg + 1];
    if (reals.count(key)) {
      *reals.at(key) = utils::numeric(FLERR, v, false, lmp);
    } else if (integers.count(key)) {
      *integers.at(key) = utils::inumeric(FLERR, v, false, lmp);
    } else if (key == "extrapolate") {
      mts.extrapolate = utils::logical(FLERR, v, false, lmp) == 1;
    } else if (key == "farfield") {
      const gcfmm::FarField fields[] = {gcfmm::FarField::Exact, gcfmm::FarField::Average,
                                        gcfmm::FarField::None};
      opts->farfield = fields[one_of(iarg, {"exact", "average", "none"}, arg)];
    } else if (key == "sleepers") {
      sleepers_static = one_of(iarg, {"static", "full"}, arg) == 0;
    } else if (key == "solver") {
      distributed = one_of(iarg, {"distributed", "replicated"}, arg) == 0;
    } else if (key == "bed") {
      opts->bed_zlo = utils::numeric(FLERR, v, false, lmp);
      opts->bed_zhi = utils::numeric(FLERR, arg[iarg + 2], false, lmp);
      bed_given = true;
    } else if (key == "efield") {
      polar.efield = true;
      for (int a = 0; a < 3; a++) polar.field[a] = utils::numeric(FLERR, arg[iarg + 1 + a], false, lmp);
    } else if (key == "polarize") {
      polar.polarize = true;
      polar.eps_particle = utils::numeric(FLERR, v, false, lmp);
      if (nvals == 2) polar.eps_medium = utils::numeric(FLERR, arg[iarg + 2], false, lmp);
      if (!(polar.eps_particle > 0.0) || (nvals == 2 && !(polar.eps_medium > 0.0)))
        error->all(FLERR, iarg, "Fix coul/fmm polarize: permittivities must be > 0, got {}{}", v,
                   nvals == 2 ? std::string(" ") + arg[iarg + 2] : std::string());
    } else if (key == "electrode") {
      polar.electrode = true;
      polar.electrode_z = utils::numeric(FLERR, v, false, lmp);
    } else if (key == "induction") {
      polar.tolerance = utils::numeric(FLERR, v, false, lmp);
      if (!(polar.tolerance > 0.0 && polar.tolerance < 1.0))
        error->all(FLERR, iarg, "Fix coul/fmm induction must be in (0, 1), got {}", v);
    }
    if (key == "images" || key == "farfield") periodic_keyword = key;
    if (key == "efield" || key == "polarize" || key == "electrode") any_polar = true;
    iarg += 1 + nvals;
  }
  if (any_polar) {
    polarizable = std::make_unique<CoulFMMPolarizable>(lmp, polar, groupbit);
    if (polar.polarize) field_cols = 7;
  } else if (polar.tolerance > 0.0) {
    error->all(FLERR, "Fix coul/fmm induction needs polarize");
  }
  // each value is checked once, by gcfmm::Options and CoulFMMTimeStepping::Settings
  try {
    opts->validate();
    stepping = std::make_unique<MTS>(mts);
  } catch (std::exception &e) {
    std::string what = e.what();
    if (what.rfind("gcfmm: ", 0) == 0) what = what.substr(7);
    error->all(FLERR, "Fix coul/fmm {}", what);
  }
}

// the position of keyword arg[iarg]'s value among `words`, or an error listing them
int FixCoulFMM::one_of(int iarg, const std::vector<std::string> &words, char **arg)
{
  for (size_t k = 0; k < words.size(); k++)
    if (words[k] == arg[iarg + 1]) return (int) k;
  std::string list = words[0];
  for (size_t k = 1; k < words.size(); k++)
    list += (k + 1 < words.size() ? ", " : " or ") + words[k];
  error->all(FLERR, iarg + 1, "Fix coul/fmm {} must be {}, got {}", arg[iarg], list, arg[iarg + 1]);
  return -1;
}

FixCoulFMM::~FixCoulFMM()
{
  if (copymode) return;
  atom->delete_callback(id, Atom::GROW);
  atom->delete_callback(id, Atom::RESTART);
  memory->destroy(field);
  memory->destroy(eval_state);
  memory->destroy(polar_force);
}

int FixCoulFMM::setmask()
{
  return POST_FORCE | POST_FORCE_RESPA | MIN_POST_FORCE;
}

void FixCoulFMM::init()
{
  if (!atom->q_flag) error->all(FLERR, "Fix coul/fmm requires an atom style with charge (q)");
  // results are matched to atoms by ID; without IDs every atom would get atom 1's field
  if (!atom->tag_enable) error->all(FLERR, "Fix coul/fmm requires atom IDs (atom_modify id yes)");
  if (domain->dimension != 3) error->all(FLERR, "Fix coul/fmm requires a 3d simulation");
  if (domain->triclinic) error->all(FLERR, "Fix coul/fmm does not support triclinic boxes");
  check_boundary_and_options();
  evaluator->check_counted_once(this);
  if (utils::strmatch(update->integrate_style, "^respa")) {
    ilevel_respa = (dynamic_cast<Respa *>(update->integrate))->nlevels - 1;
    if (respa_level >= 0) ilevel_respa = MIN(respa_level, ilevel_respa);
  }
  auto sleep = modify->get_fix_by_style("^sleep/gran$");
  if (polarizable) {
    // doc/fix_coul_fmm.md, "Applied field, induced dipoles, electrode": every step, replicated
    if (distributed)
      error->all(FLERR, "Fix coul/fmm efield, polarize and electrode need solver replicated");
    if (!sleep.empty() && sleepers_static)
      error->all(FLERR,
                 "Fix coul/fmm efield, polarize and electrode need sleepers full with fix "
                 "sleep/gran (the static sleepers' field has no dipoles or images)");
    // LAMMPS's fix efield pushes the charges only: with efield here it would count the field
    // twice, with polarize it would leave the dipoles blind to it
    if (!modify->get_fix_by_style("^efield").empty()) {
      if (polarizable->settings().efield)
        error->all(FLERR,
                   "Fix coul/fmm efield and fix efield would both apply the field: use one");
      if (polarizable->settings().polarize)
        error->all(FLERR,
                   "Fix coul/fmm polarize with fix efield: fix efield's field would not "
                   "polarize the particles; give it to fix coul/fmm efield instead");
    }
    // the multiple time stepping of doc/polarization.md, section 8: the near pairs' change
    // with the dipoles held, the far part extrapolated (or held), no keyword check
    const auto &mts = stepping->settings();
    if (mts.check_every > 0 && comm->me == 0)
      error->warning(FLERR,
                     "Fix coul/fmm {}: check is ignored with efield, polarize or electrode (the "
                     "error of the time stepping is measured at every evaluation, vector element 9)",
                     id);
    const double half_cell = 0.5 * MIN(domain->xprd, domain->yprd);
    if (opts->boundary == gcfmm::Boundary::Periodic2D && mts.every > 1 && mts.near_cutoff >= half_cell)
      error->all(FLERR,
                 "Fix coul/fmm near {:g} with efield, polarize or electrode must be smaller than "
                 "half the periodic cell ({:g})",
                 mts.near_cutoff, half_cell);
    polarizable->init(*opts);
    polarizable->set_time_stepping(mts.every > 1 ? mts.near_cutoff : 0.0, mts.every > 1,
                                   mts.every > 1 && mts.extrapolate);
    return;
  }
  evaluator->init(
      *opts, sleep.empty() || !sleepers_static ? nullptr : sleep[0],
      thermo_virial, distributed);

  const auto &mts = stepping->settings();
  if (mts.tolerance > 0.0 && comm->me == 0)
    utils::logmesg(lmp,
                   "Fix coul/fmm {}: evaluation interval adapted between 1 and {} steps to "
                   "a time-stepping error of {:.3g}\n",
                   id, mts.every, mts.tolerance);
  if (mts.near_cutoff > 0.0 && mts.every == 1 && comm->me == 0)
    error->warning(FLERR,
                   "Fix coul/fmm {}: near has no effect with every 1 (each step is an "
                   "evaluation)",
                   id);
  if (stepping->refreshes_near()) near->request(mts.near_cutoff);
}

// the boundary and the solver options the box allows (CoulFMMEvaluator::set_geometry), and
// settings that are ignored or cost more than they save
void FixCoulFMM::check_boundary_and_options()
{
  evaluator->set_geometry(*opts, bed_given);
  const bool periodic = opts->boundary == gcfmm::Boundary::Periodic2D, me0 = comm->me == 0;
  if (!periodic && !periodic_keyword.empty() && me0)
    error->warning(FLERR,
                   "Fix coul/fmm {}: keyword {} has no effect in free space (boundary f f f: "
                   "no periodic images, the field is the exact sum over all charges)",
                   id, periodic_keyword);
  // beyond the periodic cell the near list holds every pair with several of its images (LAMMPS
  // then stops with a neighbor-list overflow that does not name near), and refreshing it every
  // step costs more than evaluating every step (every 1)
  const double cell = MIN(domain->xprd, domain->yprd), near = stepping->settings().near_cutoff;
  if (periodic && stepping->refreshes_near() && near >= cell)
    error->all(FLERR,
               "Fix coul/fmm near {:g} must be smaller than the periodic cell (Lx = {:g}, "
               "Ly = {:g}): beyond it every pair is refreshed with several of its images, which "
               "costs more than every 1",
               near, domain->xprd, domain->yprd);
  if (thermo_virial && periodic && me0)
    error->warning(FLERR,
                   "Fix coul/fmm {} with boundary p p f contributes only the zz component of "
                   "the virial (the in-plane components of sum x_i F_i are not the lattice virial)",
                   id);
}

void FixCoulFMM::init_list(int /*id*/, NeighList *ptr)
{
  near->set_list(ptr);
}

void FixCoulFMM::setup(int vflag)
{
  // continue the schedule of the previous run (or of the restart file) when its stored field
  // still belongs to these atoms, charges and box: a run split into pieces, or continued from
  // a restart, then evaluates on the same steps as the uninterrupted run
  // (with efield, polarize or electrode: an evaluation at every setup)
  if (polarizable || !evaluator->continues(*stepping, eval_state)) stepping->restart_schedule();
  if (utils::strmatch(update->integrate_style, "^verlet")) {
    post_force(vflag);
  } else {
    auto *respa = dynamic_cast<Respa *>(update->integrate);
    respa->copy_flevel_f(ilevel_respa);
    post_force_respa(vflag, ilevel_respa, 0);
    respa->copy_f_flevel(ilevel_respa);
  }
}

void FixCoulFMM::post_force_respa(int vflag, int ilevel, int /*iloop*/)
{
  if (ilevel == ilevel_respa) post_force(vflag);
}

void FixCoulFMM::min_setup(int vflag)
{
  if (!polarizable && stepping->settings().every > 1 && comm->me == 0)
    error->warning(FLERR,
                   "Fix coul/fmm {}: every {} is ignored during minimization (a minimizer "
                   "needs forces and energy of the current positions)",
                   id, stepping->settings().every);
  min_post_force(vflag);
}

// a line search evaluates several trial positions within one step: always recompute
void FixCoulFMM::min_post_force(int vflag)
{
  v_init(vflag);
  if (polarizable) {
    post_force_polarizable(false);    // trial positions: no prediction from the last steps
    return;
  }
  compute_field(false);
  apply_field();
  remember_positions();
}

void FixCoulFMM::post_force(int vflag)
{
  v_init(vflag);
  if (polarizable) {
    post_force_polarizable(true);
    return;
  }
  const bigint step = update->ntimestep;
  // evaluate on the schedule's steps, whenever atoms were added or removed (fix deposit,
  // evaporate: a new atom must feel, and exert, the force from its first step) and whenever
  // the charges, qqrd2e or the geometry changed (a stored field would belong to other charges)
  const bool due = stepping->scheduled(step) ||
      evaluator->continuity(*stepping, eval_state) != MTS::Continuity::SAME;
  if (due)
    compute_field(true);
  else if (stepping->settings().every > 1)
    advance_field();
  const int check = stepping->settings().check_every;
  if (check > 0 && !due && step % check == 0) evaluator->measure_error(*stepping, field);
  apply_field();
  remember_positions();
}

// where the atoms were when a field was last applied (a later run continues from there only)
void FixCoulFMM::remember_positions()
{
  for (int i = 0; i < atom->nlocal; i++)
    domain->unmap(atom->x[i], atom->image[i], &eval_state[i][MTS::LAST_X]);
}

// a full evaluation (doc/theory.md, eqs. (5.2)-(5.4)); with the same atoms as at the last one
// it first measures the error the time stepping had reached (CoulFMMTimeStepping::plan)
void FixCoulFMM::compute_field(bool with_slope)
{
  const int nlocal = atom->nlocal;
  evaluator->update_sleepers();
  const auto cont = with_slope && stepping->settings().every > 1
      ? evaluator->continuity(*stepping, eval_state)
      : MTS::Continuity::NONE;
  const MTS::Plan plan = stepping->plan(cont, with_slope, update->ntimestep);
  // the refresh the time stepping would have applied now, and D for a new slope
  if (plan.near) {
    near->compute(*stepping, eval_state, false,
                  plan.keep_slope ? stepping->trend_factor(plan.steps) : 0.0);
    if (plan.new_slope) near->compute(*stepping, eval_state, true, -1.0);
  }
  for (int i = 0; i < nlocal; i++) {
    double xu[3];
    domain->unmap(atom->x[i], atom->image[i], xu);
    const double q = (atom->mask[i] & groupbit) ? atom->q[i] : 0.0;
    stepping->begin_evaluation(plan, eval_state[i], xu, q, evaluator->asleep(i),
                               plan.near ? near->now()[i] : nullptr,
                               plan.near ? near->then()[i] : nullptr, field[i]);
  }
  evaluator->record(*stepping, eval_state);
  evaluator->evaluate(eval_state, MTS::FIELD, true);
  nevaluations++;
  double sums[2] = {0.0, 0.0};
  for (int i = 0; i < nlocal; i++) {
    stepping->end_evaluation(plan, eval_state[i], field[i], sums);
    for (int k = 0; k < 4; k++) field[i][k] = eval_state[i][MTS::FIELD + k];
  }
  if (plan.same) mpi->sum(sums, 2);
  stepping->finish_evaluation(plan, MTS::relative_rms(sums));
}

// eq. (5.2) between evaluations
void FixCoulFMM::advance_field()
{
  const double steps = (double) (update->ntimestep - stepping->evaluated.step);
  const bool refresh = stepping->settings().near_cutoff > 0.0;
  if (refresh) near->compute(*stepping, eval_state, false, stepping->trend_factor(steps));
  for (int i = 0; i < atom->nlocal; i++)
    stepping->predict(eval_state[i], steps, refresh ? near->now()[i] : nullptr, field[i]);
}

// F_i = q_i E_i; energy 1/2 sum q_i phi_i; virial sum x_i F_i (with x and y periodic only its
// zz term is the virial of the lattice: image shifts have no z component)
void FixCoulFMM::apply_field()
{
  double *q = atom->q;
  energy_local = 0.0;
  energy_summed = false;
  const bool in_plane = opts->boundary != gcfmm::Boundary::Periodic2D;
  for (int i = 0; i < atom->nlocal; i++) {
    if (!(atom->mask[i] & groupbit) || q[i] == 0.0) continue;
    const double fi[3] = {q[i] * field[i][0], q[i] * field[i][1], q[i] * field[i][2]};
    add_force(i, fi, in_plane);
    energy_local += 0.5 * q[i] * field[i][3];
  }
}

// the force on atom i, and its virial term (with x and y periodic only zz, see apply_field())
void FixCoulFMM::add_force(int i, const double *fi, bool in_plane)
{
  double **x = atom->x, **f = atom->f;
  for (int k = 0; k < 3; k++) f[i][k] += fi[k];
  if (!evflag) return;
  double v[6] = {in_plane ? fi[0] * x[i][0] : 0.0,
                 in_plane ? fi[1] * x[i][1] : 0.0,
                 fi[2] * x[i][2],
                 in_plane ? fi[1] * x[i][0] : 0.0,
                 in_plane ? fi[2] * x[i][0] : 0.0,
                 in_plane ? fi[2] * x[i][1] : 0.0};
  v_tally(i, v);
}

// efield, polarize, electrode: F_i = q_i E_i + (p_i . grad) E_i and the energy of
// doc/polarization.md, eq. (3.4), evaluated on the schedule's steps and continued between them
// (section 8); a minimizer's call (predict false) always evaluates; virial as in apply_field()
void FixCoulFMM::post_force_polarizable(bool predict)
{
  const bigint step = update->ntimestep;
  const bool continued = predict && !stepping->scheduled(step) &&
      polarizable->advance(field, polar_force, energy_local);
  if (!continued) {
    energy_local = polarizable->evaluate(field, polar_force, predict, stepping->stride());
    nevaluations++;
    if (predict) {
      if (polarizable->prediction_error() >= 0.0) stepping->adapt(polarizable->prediction_error());
      stepping->evaluated.step = step;
    }
  }
  energy_summed = false;
  const bool in_plane = opts->boundary != gcfmm::Boundary::Periodic2D;
  for (int i = 0; i < atom->nlocal; i++)
    if (atom->mask[i] & groupbit) add_force(i, polar_force[i], in_plane);
  remember_positions();
}

// with static sleepers, plus their pair energy with the awake charges and among themselves
double FixCoulFMM::compute_scalar()
{
  if (!energy_summed) {
    energy_all = energy_local;
    mpi->sum(&energy_all, 1);
    energy_summed = true;
  }
  if (!evaluator->split_active()) return energy_all;
  return energy_all + evaluator->sleeper_pair_energy() + evaluator->sleeper_source_energy();
}

// doc/fix_coul_fmm.md, "Output": 1-4 solver (error estimate, order, M2L, P2P), 5-7 keyword
// check (last, largest, all checks), 8 interval, 9 the MTS error at the last evaluation that
// continued a field, 10 evaluations, 11 bytes received by the busiest rank in the last
// evaluation, 12 the largest solver memory of a rank (bytes), 13-14 the induced dipoles
// iterations and residual at the last evaluation (polarize)
double FixCoulFMM::compute_vector(int n)
{
  const auto &d = evaluator->diagnostics_of_last();
  const bool pol = polarizable != nullptr;
  const double values[14] = {pol ? polarizable->estimated_error() : d.estimated_error,
                             pol ? (double) polarizable->order() : (double) d.order,
                             pol ? polarizable->m2l() : d.m2l,
                             pol ? polarizable->p2p() : d.p2p,
                             stepping->check_last(),
                             stepping->check_max(),
                             stepping->check_overall(),
                             (double) stepping->stride(),
                             stepping->last_estimate(),
                             (double) nevaluations,
                             d.bytes_received,
                             d.solver_memory,
                             polarizable ? (double) polarizable->iterations() : 0.0,
                             polarizable ? polarizable->residual() : 0.0};
  return n >= 0 && n < 14 ? values[n] : 0.0;
}

double FixCoulFMM::memory_usage()
{
  return (field_cols + 3.0 + MTS::COLS) * atom->nmax * sizeof(double) + near->memory_usage() +
      evaluator->memory_usage() + (polarizable ? polarizable->memory_usage() : 0.0);
}

void FixCoulFMM::grow_arrays(int nmax)
{
  memory->grow(field, nmax, field_cols, "coul/fmm:field");
  memory->grow(polar_force, nmax, 3, "coul/fmm:polar_force");
  memory->grow(eval_state, nmax, MTS::COLS, "coul/fmm:eval_state");
  array_atom = field;
}

void FixCoulFMM::copy_arrays(int i, int j, int /*delflag*/)
{
  for (int k = 0; k < field_cols; k++) field[j][k] = field[i][k];
  for (int k = 0; k < MTS::COLS; k++) eval_state[j][k] = eval_state[i][k];
}

// a created atom has no stored field; its charge 0 in eval_state marks it as new
void FixCoulFMM::set_arrays(int i)
{
  for (int k = 0; k < field_cols; k++) field[i][k] = 0.0;
  for (int k = 0; k < MTS::COLS; k++) eval_state[i][k] = 0.0;
}

int FixCoulFMM::pack_exchange(int i, double *buf)
{
  for (int k = 0; k < field_cols; k++) buf[k] = field[i][k];
  for (int k = 0; k < MTS::COLS; k++) buf[field_cols + k] = eval_state[i][k];
  return field_cols + MTS::COLS;
}

int FixCoulFMM::unpack_exchange(int nlocal, double *buf)
{
  for (int k = 0; k < field_cols; k++) field[nlocal][k] = buf[k];
  for (int k = 0; k < MTS::COLS; k++) eval_state[nlocal][k] = buf[field_cols + k];
  return field_cols + MTS::COLS;
}

int FixCoulFMM::pack_forward_comm(int n, int *list_send, double *buf, int /*pbc_flag*/,
                                  int * /*pbc*/)
{
  return near->pack(n, list_send, buf);
}

void FixCoulFMM::unpack_forward_comm(int n, int first, double *buf)
{
  near->unpack(n, first, buf);
}

// restart: the step, box, charge checksum, qqrd2e and boundary of the last evaluation and the
// schedule (global); the applied field and the evaluation state (per atom)
void FixCoulFMM::write_restart(FILE *fp)
{
  if (comm->me != 0) return;
  double list_out[MTS::RESTART_SIZE];
  stepping->write_restart(list_out);
  int size = sizeof(list_out);
  fwrite(&size, sizeof(int), 1, fp);
  fwrite(list_out, sizeof(double), MTS::RESTART_SIZE, fp);
}

// a file of an older format or of other settings is not continued: evaluate afresh
void FixCoulFMM::restart(char *buf)
{
  stepping->read_restart((double *) buf);
}

int FixCoulFMM::pack_restart(int i, double *buf)
{
  buf[0] = 5 + MTS::COLS;    // count first, as atom->extra is shared by the fixes
  for (int k = 0; k < 4; k++) buf[1 + k] = field[i][k];
  for (int k = 0; k < MTS::COLS; k++) buf[5 + k] = eval_state[i][k];
  return 5 + MTS::COLS;
}

void FixCoulFMM::unpack_restart(int nlocal, int nth)
{
  double **extra = atom->extra;
  int m = 0;
  for (int i = 0; i < nth; i++) m += static_cast<int>(extra[nlocal][m]);
  // files written before the ASLEEP column hold COLS_V1 columns: the rest start at zero
  const int cols = MIN(MTS::COLS, MAX(MTS::COLS_V1, static_cast<int>(extra[nlocal][m]) - 5));
  m++;
  for (int k = 0; k < 4; k++) field[nlocal][k] = extra[nlocal][m++];
  for (int k = 4; k < field_cols; k++) field[nlocal][k] = 0.0;
  for (int k = 0; k < MTS::COLS; k++) eval_state[nlocal][k] = k < cols ? extra[nlocal][m++] : 0.0;
}

int FixCoulFMM::size_restart(int /*nlocal*/)
{
  return 5 + MTS::COLS;
}

int FixCoulFMM::maxsize_restart()
{
  return 5 + MTS::COLS;
}
