/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "fix_coul_fmm.h"

#include "coul_fmm_backend.h"
#include "coul_fmm_charge_scheme.h"
#include "coul_fmm_near_refresh.h"
#include "coul_fmm_polarizable.h"
#include "coul_fmm_state.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "force.h"
#include "memory.h"
#include "modify.h"
#include "respa.h"
#include "update.h"

#include "gcfmm/options.hpp"

#include <cmath>
#include <exception>
#include <map>
#include <vector>

using namespace LAMMPS_NS;
using namespace FixConst;
using MTS = CoulFMMTimeStepping;

FixCoulFMM::FixCoulFMM(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), opts(new gcfmm::Options), backend(new CoulFMMBackend(lmp)),
    near(new CoulFMMNearRefresh(lmp, this)), field_cols(4), bed_given(false),
    sleepers_static(true), distributed(false), qchange(CoulFMMScheme::QChange::AUTO),
    energy_local(0.0), energy_all(0.0),
    energy_summed(false), ilevel_respa(0)
{
  scalar_flag = 1;
  extscalar = 1;
  vector_flag = 1;    // diagnostics: solver (error estimate, order, M2L, P2P), MTS check, schedule
  size_vector = 16;
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
  FixCoulFMM::grow_arrays(atom->nmax);
  atom->add_callback(Atom::GROW);
  atom->add_callback(Atom::RESTART);
  for (int i = 0; i < atom->nlocal; i++) FixCoulFMM::set_arrays(i);
}

namespace {
// keywords efield, polarize, electrode and induction, with their nvals values
void parse_polar(LAMMPS *lmp, int iarg, int nvals, char **arg, CoulFMMPolarizable::Settings &polar)
{
  Error *error = lmp->error;
  const std::string key = arg[iarg], v = arg[iarg + 1];
  if (key == "efield") {
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
}
}    // namespace

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
        key == "qchange" ||
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
    } else if (key == "qchange") {
      qchange = one_of(iarg, {"evaluate", "absorb"}, arg) == 0 ? CoulFMMScheme::QChange::EVALUATE
                                                               : CoulFMMScheme::QChange::ABSORB;
    } else if (key == "bed") {
      opts->bed_zlo = utils::numeric(FLERR, v, false, lmp);
      opts->bed_zhi = utils::numeric(FLERR, arg[iarg + 2], false, lmp);
      bed_given = true;
    } else {
      parse_polar(lmp, iarg, nvals, arg, polar);
    }
    if (key == "images" || key == "farfield") periodic_keyword = key;
    if (key == "efield" || key == "polarize" || key == "electrode") any_polar = true;
    iarg += 1 + nvals;
  }
  if (!any_polar && polar.tolerance > 0.0) error->all(FLERR, "Fix coul/fmm induction needs polarize");
  opts->induction_tolerance = polar.tolerance;    // 0 when not given: the library's default
  if (polar.polarize) field_cols = 7;
  create_parts(mts);
  if (any_polar)
    scheme = std::make_unique<CoulFMMPolarizable>(lmp, polar, parts());
  else
    scheme = std::make_unique<CoulFMMChargeScheme>(lmp, parts());
}


// the checked options and schedule, and the state
void FixCoulFMM::create_parts(const MTS::Settings &mts)
{
  // each value is checked once, by gcfmm::Options and CoulFMMTimeStepping::Settings
  try {
    opts->validate();
    stepping = std::make_unique<MTS>(mts);
  } catch (std::exception &e) {
    std::string what = e.what();
    if (what.rfind("gcfmm: ", 0) == 0) what = what.substr(7);
    error->all(FLERR, "Fix coul/fmm {}", what);
  }
  state = std::make_unique<CoulFMMState>(lmp, field_cols, groupbit);
}

CoulFMMScheme::Parts FixCoulFMM::parts()
{
  return {this, opts.get(), stepping.get(), state.get(), backend.get(), near.get(),
          sleepers_static, distributed, qchange};
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
  backend->check_counted_once(this);
  if (utils::strmatch(update->integrate_style, "^respa")) {
    ilevel_respa = (dynamic_cast<Respa *>(update->integrate))->nlevels - 1;
    if (respa_level >= 0) ilevel_respa = MIN(respa_level, ilevel_respa);
  }
  scheme->init();
}

// the boundary and the solver options the box allows (CoulFMMBackend::set_geometry), and
// settings that are ignored or cost more than they save
void FixCoulFMM::check_boundary_and_options()
{
  backend->set_geometry(*opts, bed_given);
  check_accuracy_reachable();
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

// a requested accuracy is delivered or refused: finer than gcfmm::reachable_accuracy the solver
// would serve the request with a larger error than asked
void FixCoulFMM::check_accuracy_reachable()
{
  gcfmm::AccuracyParts parts;
  parts.dipoles = field_cols == 7;
  parts.static_sources = sleepers_static && !modify->get_fix_by_style("^sleep/gran$").empty();
  const gcfmm::ReachableAccuracy reach = gcfmm::reachable_accuracy(*opts, parts);
  if (opts->accuracy >= reach.accuracy) return;
  std::string why = reach.limit == gcfmm::AccuracyLimit::ExactFarField
      ? fmt::format("the exact periodic far field is calibrated down to {:g}", reach.charges)
      : fmt::format("order {} at theta {:g}", reach.order, reach.theta);
  if (reach.dipole_margin > 1.0)
    why += fmt::format(", times {:g} for the induced dipoles", reach.dipole_margin);
  if (reach.static_share < 1.0)
    why += fmt::format(", over {:g} for the static sleepers' share", reach.static_share);
  // two digits, rounded up: the suggested request is reachable
  const double digit = std::pow(10.0, std::floor(std::log10(reach.accuracy)) - 1.0);
  error->all(FLERR,
             "Fix coul/fmm {} accuracy {:g} is finer than the solver reaches with these "
             "settings: {:.3g} ({}); request accuracy {:.2g} or larger",
             id, opts->accuracy, reach.accuracy, why, std::ceil(reach.accuracy / digit) * digit);
}

void FixCoulFMM::init_list(int /*id*/, NeighList *ptr)
{
  near->set_list(ptr);
}

void FixCoulFMM::setup(int vflag)
{
  // a new run: its atoms and state may have been changed in between
  state->forget_hashes();
  if (!scheme->continues()) stepping->restart_schedule();
  near->forget_pairs();
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

// every scheme evaluates a minimizer's positions afresh (CoulFMMScheme::compute)
void FixCoulFMM::min_setup(int vflag)
{
  if (stepping->settings().every > 1 && comm->me == 0)
    error->warning(FLERR,
                   "Fix coul/fmm {}: every {} is ignored during minimization (a minimizer "
                   "needs forces and energy of the current positions)",
                   id, stepping->settings().every);
  min_post_force(vflag);
}

// the charge changes absorbed in this run (doc/fix_coul_fmm.rst, "Output"), when there were
// any; counted from the end of the last run (a run with pre no has no setup)
void FixCoulFMM::post_run()
{
  state->settle_positions();
  const auto &run = stepping->absorbed_this_run();
  if (run.changes > 0.0 && comm->me == 0)
    utils::logmesg(lmp,
                   "Fix coul/fmm {}: absorbed {:.0f} charge changes; {:.0f} evaluations forced "
                   "by their far part\n",
                   id, run.changes, run.forced);
  stepping->start_run_counts();
}

// a line search evaluates several trial positions within one step: no prediction
void FixCoulFMM::min_post_force(int vflag)
{
  apply(vflag, false);
}

void FixCoulFMM::post_force(int vflag)
{
  apply(vflag, true);
}

// the scheme's forces of this step to the atoms; energy 1/2 sum q_i phi_i (and the dipoles'
// terms); virial sum x_i F_i (with x and y periodic only its zz term is the virial of the
// lattice: image shifts have no z component); where the atoms were when the field was applied
void FixCoulFMM::apply(int vflag, bool predict)
{
  v_init(vflag);
  energy_local = scheme->compute(predict);
  energy_summed = false;
  const bool in_plane = opts->boundary != gcfmm::Boundary::Periodic2D;
  double **x = atom->x, **f = atom->f;
  for (int i = 0; i < atom->nlocal; i++) {
    if (!scheme->acts_on(i)) continue;
    const double *fi = state->force_on(i);
    for (int k = 0; k < 3; k++) f[i][k] += fi[k];
    if (!evflag) continue;
    double v[6] = {in_plane ? fi[0] * x[i][0] : 0.0,
                   in_plane ? fi[1] * x[i][1] : 0.0,
                   fi[2] * x[i][2],
                   in_plane ? fi[1] * x[i][0] : 0.0,
                   in_plane ? fi[2] * x[i][0] : 0.0,
                   in_plane ? fi[2] * x[i][1] : 0.0};
    v_tally(i, v);
  }
  state->remember_charges();
  // a minimizer may go back to other positions after its last force evaluation
  state->remember_positions(!predict);
}

// with static sleepers, plus their pair energy with the awake charges and among themselves
double FixCoulFMM::compute_scalar()
{
  if (!energy_summed) {
    energy_all = energy_local;
    backend->communication().sum(&energy_all, 1);
    energy_summed = true;
  }
  return scheme->total_energy(energy_all);
}

// doc/fix_coul_fmm.rst, "Output": 1-4 solver (error estimate, order, M2L, P2P), 5-7 keyword
// check (last, largest, all checks), 8 interval, 9 the MTS error at the last evaluation that
// continued a field, 10 evaluations, 11 bytes received by the busiest rank in the last
// evaluation, 12 the largest solver memory of a rank (bytes), 13-14 the induced dipoles
// iterations and residual at the last evaluation (polarize), 15 the charge changes absorbed and
// 16 the evaluations their far part forced, since the fix was defined
double FixCoulFMM::compute_vector(int n)
{
  const auto &d = scheme->diagnostics();
  const auto &absorbed = stepping->absorbed_total();
  const double values[16] = {d.estimated_error,
                             (double) d.order,
                             d.m2l,
                             d.p2p,
                             stepping->check_last(),
                             stepping->check_max(),
                             stepping->check_overall(),
                             (double) stepping->stride(),
                             stepping->last_estimate(),
                             scheme->evaluations(),
                             d.bytes_received,
                             d.solver_memory,
                             (double) d.iterations,
                             d.residual,
                             absorbed.changes,
                             absorbed.forced};
  return n >= 0 && n < 16 ? values[n] : 0.0;
}

double FixCoulFMM::memory_usage()
{
  return state->memory_usage() + near->memory_usage() + scheme->memory_usage();
}

void FixCoulFMM::grow_arrays(int nmax)
{
  state->grow(nmax);
  array_atom = state->field_rows();
}

void FixCoulFMM::copy_arrays(int i, int j, int /*delflag*/)
{
  state->copy(i, j);
}

// a created atom has no stored field; its charge 0 in the evaluation row marks it as new
void FixCoulFMM::set_arrays(int i)
{
  state->clear(i);
}

int FixCoulFMM::pack_exchange(int i, double *buf)
{
  return state->pack_exchange(i, buf);
}

int FixCoulFMM::unpack_exchange(int nlocal, double *buf)
{
  return state->unpack_exchange(nlocal, buf);
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
  return state->pack_restart(i, buf);
}

void FixCoulFMM::unpack_restart(int nlocal, int nth)
{
  double **extra = atom->extra;
  int m = 0;
  for (int i = 0; i < nth; i++) m += static_cast<int>(extra[nlocal][m]);
  state->unpack_restart(nlocal, &extra[nlocal][m]);
}

int FixCoulFMM::size_restart(int /*nlocal*/)
{
  return CoulFMMState::restart_size();
}

int FixCoulFMM::maxsize_restart()
{
  return CoulFMMState::restart_size();
}
