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
#include "fix_sleep_gran.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "force.h"
#include "group.h"
#include "memory.h"
#include "modify.h"
#include "neigh_list.h"
#include "neigh_request.h"
#include "neighbor.h"
#include "pair.h"
#include "respa.h"
#include "update.h"

#include "gcfmm/far_field.hpp"
#include "gcfmm/options.hpp"
#include "gcfmm/solver.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <vector>

using namespace LAMMPS_NS;
using namespace FixConst;
using MTS = CoulFMMTimeStepping;

/* ---------------------------------------------------------------------- */

FixCoulFMM::FixCoulFMM(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), opts(new gcfmm::Options), mpi(new CoulFMMComm(lmp)), bed_given(false),
    sleepers_static(true), sleep_fix(nullptr), nevaluations(0), energy_local(0.0), energy_all(0.0), energy_summed(false), ilevel_respa(0), list(nullptr),
    field(nullptr), eval_state(nullptr), near_delta(nullptr), near_now(nullptr), near_then(nullptr),
    fresh(nullptr), nmax_ghost(0), nmax_near(0), nmax_check(0)
{
  scalar_flag = 1;
  extscalar = 1;
  vector_flag = 1;    // diagnostics: solver (error estimate, order, M2L, P2P), MTS check, schedule
  size_vector = 10;
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
  evaluator = std::make_unique<CoulFMMEvaluator>(lmp, id, groupbit);
  FixCoulFMM::grow_arrays(atom->nmax);
  atom->add_callback(Atom::GROW);
  atom->add_callback(Atom::RESTART);
  for (int i = 0; i < atom->nlocal; i++) FixCoulFMM::set_arrays(i);
}

// the keywords' values are checked once, by gcfmm::Options and CoulFMMTimeStepping::Settings
void FixCoulFMM::parse_keywords(int narg, char **arg)
{
  static const std::vector<std::string> keywords = {
      "accuracy", "order", "theta", "leaf", "images", "farfield", "bed", "every",
      "tolerance", "check", "extrapolate", "near", "sleepers"};
  MTS::Settings mts;
  for (int iarg = 3; iarg < narg; iarg += 2) {
    const std::string key = arg[iarg];
    if (std::find(keywords.begin(), keywords.end(), key) == keywords.end())
      error->all(FLERR, iarg, "Unknown fix coul/fmm keyword: {}", key);
    const int nvalues = key == "bed" ? 2 : 1;
    if (iarg + nvalues >= narg) utils::missing_cmd_args(FLERR, "fix coul/fmm " + key, error);
    const char *v = arg[iarg + 1];
    if (key == "accuracy") opts->accuracy = utils::numeric(FLERR, v, false, lmp);
    else if (key == "order") opts->order = utils::inumeric(FLERR, v, false, lmp);
    else if (key == "theta") opts->theta = utils::numeric(FLERR, v, false, lmp);
    else if (key == "leaf") opts->leaf = utils::inumeric(FLERR, v, false, lmp);
    else if (key == "images") opts->images = utils::inumeric(FLERR, v, false, lmp);
    else if (key == "every") mts.every = utils::inumeric(FLERR, v, false, lmp);
    else if (key == "tolerance") mts.tolerance = utils::numeric(FLERR, v, false, lmp);
    else if (key == "check") mts.check_every = utils::inumeric(FLERR, v, false, lmp);
    else if (key == "near") mts.near_cutoff = utils::numeric(FLERR, v, false, lmp);
    else if (key == "extrapolate") mts.extrapolate = utils::logical(FLERR, v, false, lmp) == 1;
    else if (key == "farfield") {
      const std::string f = v;
      if (f != "exact" && f != "average" && f != "none")
        error->all(FLERR, iarg + 1, "Fix coul/fmm farfield must be exact, average or none, got {}", f);
      opts->farfield = f == "exact" ? gcfmm::FarField::Exact
                                    : (f == "average" ? gcfmm::FarField::Average : gcfmm::FarField::None);
    } else if (key == "sleepers") {
      sleepers_static = std::string(v) == "static";
      if (!sleepers_static && std::string(v) != "full")
        error->all(FLERR, iarg + 1, "Fix coul/fmm sleepers must be static or full, got {}", v);
    } else if (key == "bed") {
      opts->bed_zlo = utils::numeric(FLERR, v, false, lmp);
      opts->bed_zhi = utils::numeric(FLERR, arg[iarg + 2], false, lmp);
      bed_given = true;
      iarg++;
    }
    if (key == "images" || key == "farfield") periodic_keyword = key;
  }
  try {
    opts->validate();
    stepping = std::make_unique<MTS>(mts);
  } catch (std::exception &e) {
    std::string what = e.what();
    if (what.rfind("gcfmm: ", 0) == 0) what = what.substr(7);
    error->all(FLERR, "Fix coul/fmm {}", what);
  }
}

FixCoulFMM::~FixCoulFMM()
{
  if (copymode) return;
  atom->delete_callback(id, Atom::GROW);
  atom->delete_callback(id, Atom::RESTART);
  memory->destroy(field);
  memory->destroy(eval_state);
  memory->destroy(near_delta);
  memory->destroy(fresh);
  memory->destroy(near_now);
  memory->destroy(near_then);
}

int FixCoulFMM::setmask()
{
  return POST_FORCE | POST_FORCE_RESPA | MIN_POST_FORCE;
}

/* ---------------------------------------------------------------------- */

void FixCoulFMM::init()
{
  if (!atom->q_flag) error->all(FLERR, "Fix coul/fmm requires an atom style with charge (q)");
  // results are matched to atoms by ID; without IDs every atom would get atom 1's field
  if (!atom->tag_enable) error->all(FLERR, "Fix coul/fmm requires atom IDs (atom_modify id yes)");
  if (domain->dimension != 3) error->all(FLERR, "Fix coul/fmm requires a 3d simulation");
  if (domain->triclinic) error->all(FLERR, "Fix coul/fmm does not support triclinic boxes");
  check_boundary_and_options();
  check_other_coul_fmm_fixes();
  if (utils::strmatch(update->integrate_style, "^respa")) {
    ilevel_respa = (dynamic_cast<Respa *>(update->integrate))->nlevels - 1;
    if (respa_level >= 0) ilevel_respa = MIN(respa_level, ilevel_respa);
  }
  evaluator->init(*opts, sleepers_to_use());

  const auto &mts = stepping->settings();
  if (mts.tolerance > 0.0 && comm->me == 0)
    utils::logmesg(lmp, "Fix coul/fmm {}: evaluation interval adapted between 1 and {} steps to "
                   "a time-stepping error of {:.3g}\n", id, mts.every, mts.tolerance);
  // near refresh: a half list without newton (each pair once per rank that owns one of its
  // atoms, so no reverse communication) of the pairs closer than the near cutoff, ghosts out to
  // it; with every 1 each step is an evaluation, so neither the list nor a slope is ever used
  if (mts.near_cutoff > 0.0 && mts.every == 1 && comm->me == 0)
    error->warning(FLERR, "Fix coul/fmm {}: near has no effect with every 1", id);
  if (stepping->refreshes_near()) {
    auto *req = neighbor->add_request(this, NeighConst::REQ_NEWTON_OFF);
    req->set_cutoff(mts.near_cutoff);
    const double ghost = mts.near_cutoff + neighbor->skin;
    if (ghost > comm->cutghostuser) {
      comm->cutghostuser = ghost;
      if (comm->me == 0)
        utils::logmesg(lmp, "Fix coul/fmm {}: ghost cutoff raised to {:.6g} for near {:.6g}\n", id,
                       ghost, mts.near_cutoff);
    }
  }
}

// free space or periodic in x and y only, and the options that make sense there
void FixCoulFMM::check_boundary_and_options()
{
  const int px = domain->xperiodic, py = domain->yperiodic, pz = domain->zperiodic;
  if (!px && !py && !pz) opts->boundary = gcfmm::Boundary::Free;
  else if (px && py && !pz) opts->boundary = gcfmm::Boundary::Periodic2D;
  else
    error->all(FLERR, "Fix coul/fmm requires boundary f f f (free space) or p p f (periodic in x "
               "and y, open in z), got periodicity {} {} {}", px ? "p" : "f", py ? "p" : "f", pz ? "p" : "f");
  const bool periodic = opts->boundary == gcfmm::Boundary::Periodic2D, me0 = comm->me == 0;
  if (force->kspace && me0)
    error->warning(FLERR, "Fix coul/fmm is used together with a kspace style: Coulomb "
                   "interactions may be counted twice");
  // a pair style with a Coulomb part (coul/cut, lj/cut/coul/long, ... or a hybrid sub-style)
  // adds the same interactions again for the pairs within its cutoff
  int dim = 0;
  if (force->pair && me0 && (force->pair->extract("cut_coul", dim) || force->pair_match("coul", 0)))
    error->warning(FLERR, "Fix coul/fmm {} is used together with pair style {}, which computes "
                   "Coulomb interactions too: they are counted twice within its cutoff (use a pair "
                   "style without a coul part)", id, force->pair_style);
  if (!periodic && !periodic_keyword.empty() && me0)
    error->warning(FLERR, "Fix coul/fmm {}: keyword {} has no effect in free space (boundary f f f: "
                   "no periodic images, the field is the exact sum over all charges)", id, periodic_keyword);
  const bool exact = periodic && opts->farfield == gcfmm::FarField::Exact;
  if (exact && opts->images == 0)
    error->all(FLERR, "Fix coul/fmm farfield exact with boundary p p f needs images >= 1, got images 0 "
               "(the far-field kernel of the exact lattice sum is singular inside the cell then): "
               "use images >= 1, or farfield average or none");
  // beyond the periodic cell the near list holds every pair with several of its images (LAMMPS
  // then stops with a neighbor-list overflow that does not name near), and refreshing it every
  // step costs more than evaluating every step (every 1)
  const double cell = MIN(domain->xprd, domain->yprd), near = stepping->settings().near_cutoff;
  if (periodic && stepping->refreshes_near() && near >= cell)
    error->all(FLERR, "Fix coul/fmm near {:g} must be smaller than the periodic cell (Lx = {:g}, "
               "Ly = {:g}): beyond it every pair is refreshed with several of its images, which "
               "costs more than every 1", near, domain->xprd, domain->yprd);
  // the exact far field meets the requested accuracy only for cells close to square
  const double aspect = MAX(domain->xprd, domain->yprd) / cell;
  if (exact && aspect > gcfmm::PeriodicFarField::kMaxAspect)
    error->all(FLERR, "Fix coul/fmm farfield exact supports cells with max(Lx, Ly) / min(Lx, Ly) <= "
               "{:g}, got {:g}: use farfield average or none, or a cell closer to square",
               gcfmm::PeriodicFarField::kMaxAspect, aspect);
  if (bed_given && !(periodic && opts->farfield == gcfmm::FarField::Average))
    error->all(FLERR, "Fix coul/fmm keyword bed applies only to farfield average with boundary p p f");
  if (thermo_virial && periodic && me0)
    error->warning(FLERR, "Fix coul/fmm {} with boundary p p f contributes only the zz component of "
                   "the virial (the in-plane components of sum x_i F_i are not the lattice virial)", id);
}

/* ----------------------------------------------------------------------
   two coul/fmm fixes sharing charged atoms would count their interactions twice; fixes on
   disjoint groups are allowed, but do not see each other
------------------------------------------------------------------------- */

void FixCoulFMM::check_other_coul_fmm_fixes()
{
  for (auto *other : modify->get_fix_by_style("^coul/fmm$")) {
    if (other == this) continue;
    const int both = groupbit | group->bitmask[other->igroup];
    double shared = 0.0;
    for (int i = 0; i < atom->nlocal; i++)
      if ((atom->mask[i] & both) == both && atom->q[i] != 0.0) shared += 1.0;
    mpi->sum(&shared, 1);
    if (shared > 0.0)
      error->all(FLERR, "Fix coul/fmm {} and fix coul/fmm {} share {} charged atoms: their Coulomb "
                 "interactions would be counted twice", id, other->id, (bigint) shared);
    if (comm->me == 0)
      error->warning(FLERR, "Fix coul/fmm {} and fix coul/fmm {} act on disjoint groups: charges of "
                     "one group do not interact with those of the other", id, other->id);
  }
}

/* ----------------------------------------------------------------------
   fix sleep/gran with keyword sleepers static (the default): the sleeping charges are a static
   source (coul_fmm_sleepers.h), not targets (a sleeper does not move)
------------------------------------------------------------------------- */

FixSleepGran *FixCoulFMM::sleepers_to_use()
{
  auto fixes = modify->get_fix_by_style("^sleep/gran$");
  sleep_fix = fixes.empty() ? nullptr : dynamic_cast<FixSleepGran *>(fixes.front());
  if (!sleep_fix || !sleepers_static) return nullptr;
  if (opts->boundary == gcfmm::Boundary::Periodic2D && opts->farfield == gcfmm::FarField::Average)
    error->all(FLERR, "Fix coul/fmm {} farfield average cannot treat the sleepers of fix sleep/gran {} "
               "as a static source (the average field is no pair interaction): use farfield exact or "
               "none, or keyword sleepers full", id, sleep_fix->id);
  if (thermo_virial)
    error->all(FLERR, "Fix coul/fmm {}: the virial with the static sleepers of fix sleep/gran {} would "
               "lack the sleepers' share (their forces are not computed): use keyword sleepers full, "
               "or fix_modify {} virial no", id, sleep_fix->id, id);
  return sleep_fix;
}

void FixCoulFMM::init_list(int /*id*/, NeighList *ptr)
{
  list = ptr;
}

void FixCoulFMM::setup(int vflag)
{
  // continue the schedule of the previous run (or of the restart file) when its stored field
  // still belongs to these atoms, charges and box: a run split into pieces, or continued from
  // a restart, then evaluates on the same steps as the uninterrupted run
  if (!stored_field_valid()) stepping->restart_schedule();
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
  if (stepping->settings().every > 1 && comm->me == 0)
    error->warning(FLERR, "Fix coul/fmm {}: every {} is ignored during minimization (a minimizer "
                   "needs forces and energy of the current positions)", id, stepping->settings().every);
  min_post_force(vflag);
}

// a line search evaluates several trial positions within one step: always recompute
void FixCoulFMM::min_post_force(int vflag)
{
  v_init(vflag);
  compute_field(false);
  apply_field();
  remember_positions();
}

/* ----------------------------------------------------------------------
   at the start of a run the stored field can be continued if it belongs to the same atoms,
   charges and box and no atom was moved since the field was last applied (displace_atoms,
   set); unwrapping after a remap may differ in the last bits, hence a tolerance
------------------------------------------------------------------------- */

bool FixCoulFMM::stored_field_valid()
{
  if (field_continuity() != MTS::Continuity::SAME) return false;
  const double tol = 1e-12 * MAX(MAX(domain->xprd, domain->yprd), domain->zprd);
  bool moved = false;
  double xu[3];
  for (int i = 0; i < atom->nlocal; i++) {
    if (eval_state[i][MTS::Q] == 0.0) continue;
    domain->unmap(atom->x[i], atom->image[i], xu);
    for (int k = 0; k < 3; k++) moved = moved || fabs(xu[k] - eval_state[i][MTS::LAST_X + k]) > tol;
  }
  return !mpi->any(moved);
}

void FixCoulFMM::post_force(int vflag)
{
  v_init(vflag);
  const bigint step = update->ntimestep;
  // evaluate on the schedule's steps, whenever atoms were added or removed (fix deposit,
  // evaporate: a new atom must feel, and exert, the force from its first step) and whenever
  // the charges, qqrd2e or the geometry changed (a stored field would belong to other charges)
  const bool due = stepping->scheduled(step) || field_continuity() != MTS::Continuity::SAME;
  if (due)
    compute_field(true);
  else if (stepping->settings().every > 1) {
    advance_field();
  }
  const int check = stepping->settings().check_every;
  if (check > 0 && !due && step % check == 0) measure_mts_error();
  apply_field();
  remember_positions();
}

// where the atoms were when a field was last applied (a later run continues from there only)
void FixCoulFMM::remember_positions()
{
  for (int i = 0; i < atom->nlocal; i++)
    domain->unmap(atom->x[i], atom->image[i], &eval_state[i][MTS::LAST_X]);
}

/* ----------------------------------------------------------------------
   how the stored evaluation relates to the atoms now: SAME charges (same IDs, same values) in
   the same geometry and units, charges ADDED (fix deposit; or static sources woken) with all
   those of the evaluation still there and unchanged, or NONE. The sum of hashes is an integer
   sum (modulo 2^64): exact and the same however the atoms are distributed.
------------------------------------------------------------------------- */

MTS::Continuity FixCoulFMM::field_continuity()
{
  const double box[4] = {domain->boxlo[0], domain->boxlo[1], domain->xprd, domain->yprd};
  if (!stepping->same_setting((int) opts->boundary, force->qqrd2e, box,
                              opts->boundary == gcfmm::Boundary::Periodic2D))
    return MTS::Continuity::NONE;
  uint64_t sums[4] = {0, 0, 0, 0};    // as CoulFMMTimeStepping::continuity() reads them
  evaluator->update_sleepers();
  for (int i = 0; i < atom->nlocal; i++) {
    const double q = (atom->mask[i] & groupbit) ? atom->q[i] : 0.0, q_then = eval_state[i][MTS::Q];
    if (q_then != 0.0) sums[0] += coul_fmm_charge_hash(atom->tag[i], q_then);
    if (q != q_then) sums[1]++;
    if (q != q_then && q_then != 0.0) sums[2]++;
    if (q != 0.0 && eval_state[i][MTS::ASLEEP] != 0.0 && !evaluator->asleep(i)) sums[3]++;
  }
  mpi->sum(sums, 4);
  return stepping->continuity(sums);
}

// what the new evaluation belongs to (field_continuity)
void FixCoulFMM::record_evaluation()
{
  auto &then = stepping->evaluated;
  then.charges = 0;
  for (int i = 0; i < atom->nlocal; i++)
    if (eval_state[i][MTS::Q] != 0.0) then.charges += coul_fmm_charge_hash(atom->tag[i], eval_state[i][MTS::Q]);
  mpi->sum(&then.charges, 1);
  then.step = update->ntimestep;
  then.qqrd2e = force->qqrd2e;
  then.boundary = (int) opts->boundary;
  const double box[4] = {domain->boxlo[0], domain->boxlo[1], domain->xprd, domain->yprd};
  std::copy(box, box + 4, then.box);
}

/* ----------------------------------------------------------------------
   a full evaluation (doc/theory.md, eqs. (5.2)-(5.4)); with the same atoms as at the last one
   it first measures the error the time stepping had reached (CoulFMMTimeStepping::plan)
------------------------------------------------------------------------- */

void FixCoulFMM::compute_field(bool with_slope)
{
  const int nlocal = atom->nlocal;
  evaluator->update_sleepers();
  const auto cont = with_slope && stepping->settings().every > 1 ? field_continuity() : MTS::Continuity::NONE;
  const MTS::Plan plan = stepping->plan(cont, with_slope, update->ntimestep);
  // the refresh the time stepping would have applied now, and D for a new slope
  if (plan.near) {
    grow_near_buffers();
    near_pair_difference(near_now, plan.keep_slope ? stepping->trend_factor(plan.steps) : 0.0);
    if (plan.new_slope) near_pair_difference(near_then, -1.0);
  }
  for (int i = 0; i < nlocal; i++) {
    double xu[3];
    domain->unmap(atom->x[i], atom->image[i], xu);
    const double q = (atom->mask[i] & groupbit) ? atom->q[i] : 0.0;
    stepping->begin_evaluation(plan, eval_state[i], xu, q, evaluator->asleep(i),
                               plan.near ? near_now[i] : nullptr, plan.near ? near_then[i] : nullptr,
                               field[i]);
  }
  record_evaluation();
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
  const bool near = stepping->settings().near_cutoff > 0.0;
  if (near) {
    grow_near_buffers();
    near_pair_difference(near_now, stepping->trend_factor(steps));
  }
  for (int i = 0; i < atom->nlocal; i++)
    stepping->predict(eval_state[i], steps, near ? near_now[i] : nullptr, field[i]);
}

/* ----------------------------------------------------------------------
   out[i] = C sum_j q_j (change of (K, 1/r) of pair ij since the evaluation) for the local atoms,
   over the near list (CoulFMMTimeStepping::near_pair_change, eq. (5.3))
------------------------------------------------------------------------- */

void FixCoulFMM::grow_near_buffers()
{
  if (atom->nmax <= nmax_near) return;
  nmax_near = atom->nmax;
  memory->destroy(near_now);
  memory->destroy(near_then);
  memory->create(near_now, nmax_near, 4, "coul/fmm:near_now");
  memory->create(near_then, nmax_near, 4, "coul/fmm:near_then");
}

void FixCoulFMM::near_pair_difference(double **out, double trend)
{
  const int nlocal = atom->nlocal, nall = nlocal + atom->nghost;
  if (nall > nmax_ghost) {
    nmax_ghost = atom->nmax;
    memory->destroy(near_delta);
    memory->create(near_delta, nmax_ghost, MTS::DELTA_COLS, "coul/fmm:near_delta");
  }
  double **x = atom->x, *q = atom->q;
  int *mask = atom->mask;
  double xu[3];
  for (int i = 0; i < nlocal; i++) {
    domain->unmap(x[i], atom->image[i], xu);
    MTS::displacements(xu, eval_state[i], near_delta[i]);
  }
  comm->forward_comm(this);
  // each pair once: at i from j q_j dg, at j from i -q_i dg (field) and q_i dg (potential). A
  // ghost j is a local atom elsewhere (or an image here) whose own list holds the pair the
  // other way round: only i is updated.
  for (int i = 0; i < nlocal; i++)
    for (int k = 0; k < 4; k++) out[i][k] = 0.0;
  for (int ii = 0; ii < list->inum; ii++) {
    const int i = list->ilist[ii];
    if (!(mask[i] & groupbit) || q[i] == 0.0) continue;
    double e[4] = {0.0, 0.0, 0.0, 0.0}, dg[4];
    for (int jj = 0; jj < list->numneigh[i]; jj++) {
      const int j = list->firstneigh[i][jj] & NEIGHMASK;
      if (!(mask[j] & groupbit) || q[j] == 0.0) continue;
      const double now[3] = {x[i][0] - x[j][0], x[i][1] - x[j][1], x[i][2] - x[j][2]};
      if (!stepping->near_pair_change(now, near_delta[i], near_delta[j], trend, dg)) continue;
      for (int k = 0; k < 4; k++) e[k] += q[j] * dg[k];
      if (j < nlocal) {
        for (int k = 0; k < 3; k++) out[j][k] -= q[i] * dg[k];
        out[j][3] += q[i] * dg[3];
      }
    }
    for (int k = 0; k < 4; k++) out[i][k] += e[k];
  }
  const double c = force->qqrd2e;
  for (int i = 0; i < nlocal; i++)
    for (int k = 0; k < 4; k++) out[i][k] *= c;
}

/* ----------------------------------------------------------------------
   keyword check: the applied force against a fresh evaluation at the same positions (with
   static sleepers a full one: the error of the split and of the time stepping together)
------------------------------------------------------------------------- */

void FixCoulFMM::measure_mts_error()
{
  if (atom->nlocal > nmax_check) {
    nmax_check = atom->nmax;
    memory->destroy(fresh);
    memory->create(fresh, nmax_check, 4, "coul/fmm:fresh");
  }
  evaluator->evaluate(fresh, 0, false);
  double sums[2] = {0.0, 0.0};
  for (int i = 0; i < atom->nlocal; i++)
    if (!evaluator->asleep(i)) MTS::add_error_sums(atom->q[i] * atom->q[i], field[i], fresh[i], sums);
  mpi->sum(sums, 2);
  stepping->record_check(sums);
}

/* ----------------------------------------------------------------------
   F_i = q_i E_i; energy 1/2 sum q_i phi_i; virial sum x_i F_i (with x and y periodic only its
   zz term is the virial of the lattice: image shifts have no z component)
------------------------------------------------------------------------- */

void FixCoulFMM::apply_field()
{
  double **x = atom->x, **f = atom->f, *q = atom->q;
  energy_local = 0.0;
  energy_summed = false;
  const bool in_plane = opts->boundary != gcfmm::Boundary::Periodic2D;
  for (int i = 0; i < atom->nlocal; i++) {
    if (!(atom->mask[i] & groupbit) || q[i] == 0.0) continue;
    const double fx = q[i] * field[i][0], fy = q[i] * field[i][1], fz = q[i] * field[i][2];
    f[i][0] += fx;
    f[i][1] += fy;
    f[i][2] += fz;
    energy_local += 0.5 * q[i] * field[i][3];
    if (!evflag) continue;
    double v[6] = {in_plane ? fx * x[i][0] : 0.0, in_plane ? fy * x[i][1] : 0.0, fz * x[i][2],
                   in_plane ? fy * x[i][0] : 0.0, in_plane ? fz * x[i][0] : 0.0,
                   in_plane ? fz * x[i][1] : 0.0};
    v_tally(i, v);
  }
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

/* ----------------------------------------------------------------------
   doc/fix_coul_fmm.md, "Output": 1-4 solver (error estimate, order, M2L, P2P), 5-7 keyword
   check (last, largest, all checks), 8 interval, 9 the MTS error at the last evaluation that
   continued a field, 10 evaluations
------------------------------------------------------------------------- */

double FixCoulFMM::compute_vector(int n)
{
  if (n == 4) return stepping->check_last();
  if (n == 5) return stepping->check_max();
  if (n == 6) return stepping->check_overall();
  if (n == 7) return (double) stepping->stride();
  if (n == 8) return stepping->last_estimate();
  if (n == 9) return (double) nevaluations;
  const gcfmm::Stats *st = evaluator->stats();
  if (!st) return 0.0;
  if (n == 0) return st->estimated_error;
  if (n == 1) return st->order;
  if (n == 2) return (double) st->m2l_count;
  if (n == 3) return (double) st->p2p_pairs;
  return 0.0;
}

double FixCoulFMM::memory_usage()
{
  double bytes = (4.0 + MTS::COLS) * atom->nmax * sizeof(double) +
      (double) MTS::DELTA_COLS * nmax_ghost * sizeof(double) + 8.0 * nmax_near * sizeof(double);
  return bytes + evaluator->memory_usage();
}

/* ---------------------------------------------------------------------- */

void FixCoulFMM::grow_arrays(int nmax)
{
  memory->grow(field, nmax, 4, "coul/fmm:field");
  memory->grow(eval_state, nmax, MTS::COLS, "coul/fmm:eval_state");
  array_atom = field;
}

void FixCoulFMM::copy_arrays(int i, int j, int /*delflag*/)
{
  for (int k = 0; k < 4; k++) field[j][k] = field[i][k];
  for (int k = 0; k < MTS::COLS; k++) eval_state[j][k] = eval_state[i][k];
}

// a created atom has no stored field; its charge 0 in eval_state marks it as new
void FixCoulFMM::set_arrays(int i)
{
  for (int k = 0; k < 4; k++) field[i][k] = 0.0;
  for (int k = 0; k < MTS::COLS; k++) eval_state[i][k] = 0.0;
}

int FixCoulFMM::pack_exchange(int i, double *buf)
{
  for (int k = 0; k < 4; k++) buf[k] = field[i][k];
  for (int k = 0; k < MTS::COLS; k++) buf[4 + k] = eval_state[i][k];
  return 4 + MTS::COLS;
}

int FixCoulFMM::unpack_exchange(int nlocal, double *buf)
{
  for (int k = 0; k < 4; k++) field[nlocal][k] = buf[k];
  for (int k = 0; k < MTS::COLS; k++) eval_state[nlocal][k] = buf[4 + k];
  return 4 + MTS::COLS;
}

int FixCoulFMM::pack_forward_comm(int n, int *list_send, double *buf, int /*pbc_flag*/, int * /*pbc*/)
{
  int m = 0;
  for (int i = 0; i < n; i++)
    for (int k = 0; k < MTS::DELTA_COLS; k++) buf[m++] = near_delta[list_send[i]][k];
  return m;
}

void FixCoulFMM::unpack_forward_comm(int n, int first, double *buf)
{
  int m = 0;
  for (int i = first; i < first + n; i++)
    for (int k = 0; k < MTS::DELTA_COLS; k++) near_delta[i][k] = buf[m++];
}

/* ----------------------------------------------------------------------
   restart: the step, box, charge checksum, qqrd2e and boundary of the last evaluation and the
   schedule (global); the applied field and the evaluation state (per atom)
------------------------------------------------------------------------- */

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
