/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "fix_coul_fmm.h"

#include "coul_fmm_sleepers.h"
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
#include <cstring>
#include <exception>
#include <numeric>

using namespace LAMMPS_NS;
using namespace FixConst;

// per atom incl. ghosts for the near refresh (near_delta columns): displacement since the last
// evaluation, since the two evaluations of the slope, and whether the slope covers the atom
enum : int { DELTA_E = 0, DELTA_A = 3, DELTA_B = 6, DELTA_IN_SLOPE = 9, NEAR_COMM = 10 };

// per-atom state of the last evaluation (eval_state columns)
enum : int {
  EVAL_X = 0,         // unwrapped position at the evaluation (3)
  EVAL_Q = 3,         // charge at the evaluation (0 outside the group)
  EVAL_FIELD = 4,     // evaluated Ex, Ey, Ez, phi (4)
  EVAL_SLOPE = 8,     // change of the far part per step, from the last two evaluations (4)
  EVAL_LAST_X = 12,   // unwrapped position when a field was last applied (3)
  EVAL_SLOPE_A = 15,  // unwrapped positions at the two evaluations the slope was taken over
  EVAL_SLOPE_B = 18,  // (3 each): the trend of a pair inside the slope, for the near refresh
  EVAL_IN_SLOPE = 21, // 1 if the slope covers this atom's pairs (it existed at both evaluations)
  EVAL_ASLEEP = 22,   // 1 if the atom was a static source (fix sleep/gran) at the evaluation
  EVAL_COLS = 23
};
// restart files before EVAL_ASLEEP hold 22 columns
static constexpr int EVAL_COLS_V1 = 22;

// restart format: the global list starts with this marker (older files start with the step of
// the last evaluation, >= -1, and hold no charge checksum: they are evaluated afresh)
static constexpr double RESTART_FORMAT_CHECKSUM = -2.0;
// slots of the global restart list
enum : int {
  R_FORMAT, R_LAST, R_BOX, R_EVERY = R_BOX + 4, R_TOLERANCE, R_STRIDE, R_SLOPE, R_SUM_HI, R_SUM_LO,
  R_QQRD2E, R_BOUNDARY, RESTART_GLOBAL_SIZE
};

// hash of one charged atom (ID, charge bits) for the checksum of the charges: summed modulo
// 2^64 over the atoms, so the sum does not depend on their order or on the ranks holding them
// (splitmix64 finaliser: a changed charge or ID changes the sum except with odds ~2^-64)
static uint64_t mix64(uint64_t z)
{
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

static uint64_t charge_hash(tagint tag, double q)
{
  uint64_t bits;
  memcpy(&bits, &q, sizeof(bits));
  return mix64((uint64_t) tag ^ mix64(bits));
}

/* ---------------------------------------------------------------------- */

FixCoulFMM::FixCoulFMM(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), opts(new gcfmm::Options), solver_boundary(-1), every(1), tolerance(0.0),
    stride(1), mts_estimate(-1.0), nevaluations(0), extrapolate(true), near_cutoff(0.0), last_computed(-1),
    box_computed{0.0, 0.0, 0.0, 0.0}, charges_computed(0),
    qqrd2e_computed(0.0), boundary_computed(-1), bed_given(false), energy_local(0.0),
    energy_all(0.0), energy_summed(false), field(nullptr), eval_state(nullptr),
    near_delta(nullptr), nmax_ghost(0), list(nullptr), check_every(0), fresh(nullptr),
    nmax_check(0), check_last(0.0), check_max(0.0), check_num(0.0), check_den(0.0),
    near_now(nullptr), near_then(nullptr), nmax_near(0), slope_steps(0.0),
    logged(false), sleepers_static(true), sleep_fix(nullptr), sleeper_pair_energy(0.0)
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
  ilevel_respa = 0;
  create_attribute = 1;    // atoms created by other fixes get a zero stored field (set_arrays)
  restart_global = 1;      // the evaluation schedule and the stored field survive a restart
  restart_peratom = 1;
  comm_forward = NEAR_COMM;    // displacements since the evaluations, for the near refresh

  opts->accuracy = 1e-4;
  opts->images = 1;
  opts->farfield = gcfmm::FarField::Exact;

  int iarg = 3;
  while (iarg < narg) {
    const std::string key = arg[iarg];
    auto need = [&](int n) {
      if (iarg + n >= narg) utils::missing_cmd_args(FLERR, "fix coul/fmm " + key, error);
    };
    if (key == "accuracy") {
      need(1);
      opts->accuracy = utils::numeric(FLERR, arg[iarg + 1], false, lmp);
      if (!(opts->accuracy > 0.0 && opts->accuracy < 1.0))
        error->all(FLERR, iarg + 1, "Fix coul/fmm accuracy must be in (0, 1), got {}",
                   arg[iarg + 1]);
      iarg += 2;
    } else if (key == "order") {
      need(1);
      opts->order = utils::inumeric(FLERR, arg[iarg + 1], false, lmp);
      if (opts->order < 1 || opts->order > gcfmm::kMaxOrder)
        error->all(FLERR, iarg + 1, "Fix coul/fmm order must be in [1, {}], got {}",
                   gcfmm::kMaxOrder, arg[iarg + 1]);
      iarg += 2;
    } else if (key == "theta") {
      need(1);
      opts->theta = utils::numeric(FLERR, arg[iarg + 1], false, lmp);
      if (!(opts->theta > 0.0 && opts->theta < 1.0))
        error->all(FLERR, iarg + 1, "Fix coul/fmm theta must be in (0, 1), got {}", arg[iarg + 1]);
      iarg += 2;
    } else if (key == "leaf") {
      need(1);
      opts->leaf = utils::inumeric(FLERR, arg[iarg + 1], false, lmp);
      if (opts->leaf < 1)
        error->all(FLERR, iarg + 1, "Fix coul/fmm leaf must be >= 1, got {}", arg[iarg + 1]);
      iarg += 2;
    } else if (key == "images") {
      need(1);
      opts->images = utils::inumeric(FLERR, arg[iarg + 1], false, lmp);
      periodic_keyword = key;
      if (opts->images < 0)
        error->all(FLERR, iarg + 1, "Fix coul/fmm images must be >= 0, got {}", arg[iarg + 1]);
      iarg += 2;
    } else if (key == "farfield") {
      need(1);
      const std::string v = arg[iarg + 1];
      if (v == "exact")
        opts->farfield = gcfmm::FarField::Exact;
      else if (v == "average")
        opts->farfield = gcfmm::FarField::Average;
      else if (v == "none")
        opts->farfield = gcfmm::FarField::None;
      else
        error->all(FLERR, iarg + 1, "Fix coul/fmm farfield must be exact, average or none, got {}",
                   v);
      periodic_keyword = key;
      iarg += 2;
    } else if (key == "bed") {
      need(2);
      opts->bed_zlo = utils::numeric(FLERR, arg[iarg + 1], false, lmp);
      opts->bed_zhi = utils::numeric(FLERR, arg[iarg + 2], false, lmp);
      if (!(opts->bed_zhi > opts->bed_zlo))
        error->all(FLERR, iarg + 1, "Fix coul/fmm bed zlo must be < zhi, got {} {}", arg[iarg + 1],
                   arg[iarg + 2]);
      bed_given = true;
      iarg += 3;
    } else if (key == "every") {
      need(1);
      every = utils::inumeric(FLERR, arg[iarg + 1], false, lmp);
      if (every < 1) error->all(FLERR, iarg + 1, "Fix coul/fmm every must be >= 1, got {}", every);
      iarg += 2;
    } else if (key == "tolerance") {
      need(1);
      tolerance = utils::numeric(FLERR, arg[iarg + 1], false, lmp);
      if (!(tolerance >= 0.0 && tolerance < 1.0))
        error->all(FLERR, iarg + 1, "Fix coul/fmm tolerance must be in [0, 1), got {}",
                   arg[iarg + 1]);
      iarg += 2;
    } else if (key == "check") {
      need(1);
      check_every = utils::inumeric(FLERR, arg[iarg + 1], false, lmp);
      if (check_every < 0)
        error->all(FLERR, iarg + 1, "Fix coul/fmm check must be >= 0, got {}", check_every);
      iarg += 2;
    } else if (key == "extrapolate") {
      need(1);
      extrapolate = utils::logical(FLERR, arg[iarg + 1], false, lmp) == 1;
      iarg += 2;
    } else if (key == "near") {
      need(1);
      near_cutoff = utils::numeric(FLERR, arg[iarg + 1], false, lmp);
      if (!(near_cutoff >= 0.0))
        error->all(FLERR, iarg + 1, "Fix coul/fmm near cutoff must be >= 0, got {}", arg[iarg + 1]);
      iarg += 2;
    } else if (key == "sleepers") {
      need(1);
      const std::string v = arg[iarg + 1];
      if (v != "static" && v != "full")
        error->all(FLERR, iarg + 1, "Fix coul/fmm sleepers must be static or full, got {}", v);
      sleepers_static = v == "static";
      iarg += 2;
    } else {
      error->all(FLERR, iarg, "Unknown fix coul/fmm keyword: {}", key);
    }
  }
  if (tolerance > 0.0 && every < 2)
    error->all(FLERR, "Fix coul/fmm tolerance {} needs every > 1 (the largest evaluation interval)",
               tolerance);
  // adaptive: the interval is a power of two (then the evaluation steps of a shorter interval
  // include those of a longer one) starting from 1; every is the largest
  if (tolerance > 0.0) every = 1 << (int) std::floor(std::log2((double) every));
  stride = tolerance > 0.0 ? 1 : every;
  try {
    opts->validate();
  } catch (std::exception &e) {
    error->all(FLERR, "Fix coul/fmm: {}", e.what());
  }

  FixCoulFMM::grow_arrays(atom->nmax);
  atom->add_callback(Atom::GROW);
  atom->add_callback(Atom::RESTART);
  for (int i = 0; i < atom->nlocal; i++) FixCoulFMM::set_arrays(i);
}

/* ---------------------------------------------------------------------- */

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

/* ---------------------------------------------------------------------- */

int FixCoulFMM::setmask()
{
  return POST_FORCE | POST_FORCE_RESPA | MIN_POST_FORCE;
}

/* ----------------------------------------------------------------------
   context checks: charges, 3d, orthogonal box, free space or periodic in x and y only
------------------------------------------------------------------------- */

void FixCoulFMM::init()
{
  if (!atom->q_flag) error->all(FLERR, "Fix coul/fmm requires an atom style with charge (q)");
  // results are matched to atoms by ID; without IDs every atom would get atom 1's field
  if (!atom->tag_enable)
    error->all(FLERR, "Fix coul/fmm requires atom IDs (atom_modify id yes)");
  if (domain->dimension != 3) error->all(FLERR, "Fix coul/fmm requires a 3d simulation");
  if (domain->triclinic) error->all(FLERR, "Fix coul/fmm does not support triclinic boxes");
  const int px = domain->xperiodic, py = domain->yperiodic, pz = domain->zperiodic;
  if (!px && !py && !pz) {
    opts->boundary = gcfmm::Boundary::Free;
  } else if (px && py && !pz) {
    opts->boundary = gcfmm::Boundary::Periodic2D;
  } else {
    error->all(FLERR,
               "Fix coul/fmm requires boundary f f f (free space) or p p f (periodic in x and y, "
               "open in z), got periodicity {} {} {}",
               px ? "p" : "f", py ? "p" : "f", pz ? "p" : "f");
  }
  if (force->kspace && comm->me == 0)
    error->warning(FLERR,
                   "Fix coul/fmm is used together with a kspace style: Coulomb "
                   "interactions may be counted twice");
  // a pair style with a Coulomb part (coul/cut, lj/cut/coul/long, ... or a hybrid sub-style)
  // adds the same interactions again for the pairs within its cutoff
  if (force->pair && comm->me == 0) {
    int dim = 0;
    if (force->pair->extract("cut_coul", dim) || force->pair_match("coul", 0))
      error->warning(FLERR,
                     "Fix coul/fmm {} is used together with pair style {}, which computes "
                     "Coulomb interactions too: they are counted twice within its cutoff (use a "
                     "pair style without a coul part)",
                     id, force->pair_style);
  }
  if (opts->boundary == gcfmm::Boundary::Free) {
    // no periodic images in free space: images and farfield mean nothing there
    if (!periodic_keyword.empty() && comm->me == 0)
      error->warning(FLERR,
                     "Fix coul/fmm {}: keyword {} has no effect in free space (boundary f f f: "
                     "no periodic images, the field is the exact sum over all charges)",
                     id, periodic_keyword);
  } else if (opts->images == 0 && opts->farfield == gcfmm::FarField::Exact) {
    error->all(FLERR,
               "Fix coul/fmm farfield exact with boundary p p f needs images >= 1, got images 0 "
               "(the far-field kernel of the exact lattice sum is singular inside the cell "
               "then): use images >= 1, or farfield average or none");
  }
  // the near refresh follows pairs through a neighbor list of cutoff near; with near beyond
  // the periodic cell that list holds every pair with several of its images (LAMMPS then stops
  // with a neighbor-list overflow that does not name near), and refreshing it every step costs
  // more than evaluating every step (every 1)
  if (near_cutoff > 0.0 && every > 1 && opts->boundary == gcfmm::Boundary::Periodic2D) {
    const double cell = MIN(domain->xprd, domain->yprd);
    if (near_cutoff >= cell)
      error->all(FLERR,
                 "Fix coul/fmm near {:g} must be smaller than the periodic cell (Lx = {:g}, "
                 "Ly = {:g}): beyond it every pair is refreshed with several of its images, "
                 "which costs more than every 1",
                 near_cutoff, domain->xprd, domain->yprd);
  }
  // the exact far field meets the requested accuracy only for cells close to square
  if (opts->boundary == gcfmm::Boundary::Periodic2D && opts->farfield == gcfmm::FarField::Exact) {
    const double aspect = MAX(domain->xprd, domain->yprd) / MIN(domain->xprd, domain->yprd);
    if (aspect > gcfmm::PeriodicFarField::kMaxAspect)
      error->all(FLERR,
                 "Fix coul/fmm farfield exact supports cells with max(Lx, Ly) / min(Lx, Ly) <= "
                 "{:g}, got {:g}: use farfield average or none, or a cell closer to square",
                 gcfmm::PeriodicFarField::kMaxAspect, aspect);
  }
  if (bed_given && !(opts->boundary == gcfmm::Boundary::Periodic2D &&
                     opts->farfield == gcfmm::FarField::Average))
    error->all(FLERR,
               "Fix coul/fmm keyword bed applies only to farfield average with boundary p p f");
  if (thermo_virial && opts->boundary == gcfmm::Boundary::Periodic2D && comm->me == 0)
    error->warning(FLERR,
                   "Fix coul/fmm {} with boundary p p f contributes only the zz component of the "
                   "virial (the in-plane components of sum x_i F_i are not the lattice virial)",
                   id);
  check_other_coul_fmm_fixes();

  if (utils::strmatch(update->integrate_style, "^respa")) {
    ilevel_respa = (dynamic_cast<Respa *>(update->integrate))->nlevels - 1;
    if (respa_level >= 0) ilevel_respa = MIN(respa_level, ilevel_respa);
  }
  // the solver (tree memory, far-field operator) is kept across runs; the boundary is the only
  // option init() can change
  const bool solver_new = !solver || solver_boundary != (int) opts->boundary;
  if (solver_new) {
    try {
      solver = std::make_unique<gcfmm::Solver>(*opts);
    } catch (std::exception &e) {
      error->all(FLERR, "Fix coul/fmm: FMM library: {}", e.what());
    }
    solver_boundary = (int) opts->boundary;
  }
  logged = false;
  init_sleepers(solver_new);

  // near refresh: a half list without newton (each pair once per rank that owns one of its
  // atoms, so no reverse communication) of the pairs closer than the near cutoff, ghosts out to
  // it; with every 1 each step is an evaluation, so neither the list nor a slope is ever used
  if (near_cutoff > 0.0 && every == 1 && comm->me == 0)
    error->warning(FLERR, "Fix coul/fmm {}: near has no effect with every 1", id);
  if (tolerance > 0.0 && comm->me == 0 && !logged)
    utils::logmesg(lmp,
                   "Fix coul/fmm {}: evaluation interval adapted between 1 and {} steps to a "
                   "time-stepping error of {:.3g}\n",
                   id, every, tolerance);
  if (near_cutoff > 0.0 && every > 1) {
    auto *req = neighbor->add_request(this, NeighConst::REQ_NEWTON_OFF);
    req->set_cutoff(near_cutoff);
    const double ghost = near_cutoff + neighbor->skin;
    if (ghost > comm->cutghostuser) {
      comm->cutghostuser = ghost;
      if (comm->me == 0)
        utils::logmesg(lmp, "Fix coul/fmm {}: ghost cutoff raised to {:.6g} for near {:.6g}\n", id,
                       ghost, near_cutoff);
    }
  }
}

/* ---------------------------------------------------------------------- */

void FixCoulFMM::init_list(int /*id*/, NeighList *ptr)
{
  list = ptr;
}

/* ---------------------------------------------------------------------- */

void FixCoulFMM::setup(int vflag)
{
  // continue the schedule of the previous run (or of the restart file) when its stored field
  // still belongs to these atoms, charges and box: a run split into pieces, or continued from
  // a restart, then evaluates on the same steps as the uninterrupted run
  if (!stored_field_valid()) {
    last_computed = -1;
    if (tolerance > 0.0) stride = 1;
  }
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
  if (every > 1 && comm->me == 0)
    error->warning(FLERR,
                   "Fix coul/fmm {}: every {} is ignored during minimization (a minimizer needs "
                   "forces and energy of the current positions)",
                   id, every);
  min_post_force(vflag);
}

/* ----------------------------------------------------------------------
   a line search evaluates several trial positions within one step: always recompute
------------------------------------------------------------------------- */

void FixCoulFMM::min_post_force(int vflag)
{
  v_init(vflag);
  compute_field(false);
  last_computed = update->ntimestep;
  apply_field(vflag);
  remember_positions();
}

/* ----------------------------------------------------------------------
   at the start of a run the stored field can be continued if it belongs to the same atoms,
   charges and box (field_continuity; set between runs changes charges: then evaluate afresh)
   and no atom was moved since the field was last applied
------------------------------------------------------------------------- */

bool FixCoulFMM::stored_field_valid()
{
  if (field_continuity() != Continuity::SAME) return false;
  int moved = 0, moved_all = 0;
  // positions moved by a command between runs (displace_atoms, set): not the state the field
  // was advanced for; unwrapping after a remap may differ in the last bits, hence a tolerance
  const double tol = 1e-12 * MAX(MAX(domain->xprd, domain->yprd), domain->zprd);
  double xu[3];
  for (int i = 0; i < atom->nlocal; i++) {
    if (eval_state[i][EVAL_Q] == 0.0) continue;
    domain->unmap(atom->x[i], atom->image[i], xu);
    for (int k = 0; k < 3; k++)
      if (fabs(xu[k] - eval_state[i][EVAL_LAST_X + k]) > tol) moved = 1;
  }
  MPI_Allreduce(&moved, &moved_all, 1, MPI_INT, MPI_MAX, world);
  return moved_all == 0;
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
    int shared = 0, shared_all = 0;
    for (int i = 0; i < atom->nlocal; i++)
      if ((atom->mask[i] & both) == both && atom->q[i] != 0.0) shared++;
    MPI_Allreduce(&shared, &shared_all, 1, MPI_INT, MPI_SUM, world);
    if (shared_all > 0)
      error->all(FLERR,
                 "Fix coul/fmm {} and fix coul/fmm {} share {} charged atoms: their Coulomb "
                 "interactions would be counted twice",
                 id, other->id, shared_all);
    if (comm->me == 0)
      error->warning(FLERR,
                     "Fix coul/fmm {} and fix coul/fmm {} act on disjoint groups: charges of one "
                     "group do not interact with those of the other",
                     id, other->id);
  }
}

/* ---------------------------------------------------------------------- */

void FixCoulFMM::post_force(int vflag)
{
  v_init(vflag);
  const bigint step = update->ntimestep;
  // evaluate on the steps that are multiples of the interval (every, or with tolerance the
  // adapted power of two: a schedule that does not depend on where a run starts, since the
  // interval is part of the restart state), and whenever atoms were added or removed (e.g. fix
  // deposit, evaporate): a new atom must feel, and exert, the Coulomb force from its first step
  bool due = last_computed < 0 || (step % stride == 0 && step != last_computed);
  // and whenever the charges (values, atom IDs), qqrd2e or the geometry changed since the last
  // evaluation: a stored field would belong to other charges
  if (!due) due = field_continuity() != Continuity::SAME;
  if (due) {
    compute_field(true);
    last_computed = step;
  } else if (every > 1) {
    advance_field();
  }
  if (check_every > 0 && !due && step % check_every == 0) measure_mts_error();
  apply_field(vflag);
  remember_positions();
}

// where the atoms were when a field was last applied (a later run continues from there only)
void FixCoulFMM::remember_positions()
{
  for (int i = 0; i < atom->nlocal; i++)
    domain->unmap(atom->x[i], atom->image[i], &eval_state[i][EVAL_LAST_X]);
}

/* ----------------------------------------------------------------------
   gather the charged atoms of the group on every rank, sorted by atom ID, so that every rank
   builds the same tree and the result does not depend on the domain decomposition
------------------------------------------------------------------------- */

void FixCoulFMM::gather_charges()
{
  const int nlocal = atom->nlocal;
  double **x = atom->x;
  double *q = atom->q;
  int *mask = atom->mask;
  tagint *tag = atom->tag;

  buf.clear();
  const bool split = split_active() && split_now;
  for (int i = 0; i < nlocal; i++) {
    if (!(mask[i] & groupbit) || q[i] == 0.0 || (split && sleepers->asleep(i))) continue;
    buf.insert(buf.end(), {(double) tag[i], x[i][0], x[i][1], x[i][2], q[i]});
  }
  const int nprocs = comm->nprocs;
  std::vector<int> counts(nprocs), displs(nprocs);
  int mine = (int) buf.size();
  MPI_Allgather(&mine, 1, MPI_INT, counts.data(), 1, MPI_INT, world);
  int total = 0;
  for (int p = 0; p < nprocs; p++) {
    displs[p] = total;
    total += counts[p];
  }
  std::vector<double> all(total);
  MPI_Allgatherv(buf.data(), mine, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE,
                 world);
  // results go back to the owners in this rank-block order: 4 values per atom
  result_counts.resize(nprocs);
  for (int p = 0; p < nprocs; p++) result_counts[p] = 4 * (counts[p] / 5);

  const size_t n = total / 5;
  order.resize(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return all[5 * a] < all[5 * b];
  });
  gtag.resize(n);
  gx.resize(n);
  gy.resize(n);
  gz.resize(n);
  gq.resize(n);
  for (size_t k = 0; k < n; k++) {
    const double *r = &all[5 * order[k]];
    gtag[k] = (tagint) r[0];
    gx[k] = r[1];
    gy[k] = r[2];
    gz[k] = r[3];
    gq[k] = r[4];
  }
}

/* ----------------------------------------------------------------------
   how the stored evaluation relates to the atoms now: SAME charges (same IDs, same values; the
   uncharged atoms do not matter) in the same geometry and units, charges ADDED (e.g. by fix
   deposit) with all those of the evaluation still there and unchanged, or NONE (nothing to
   continue: a charge changed (set, fix adapt), a charged atom left (fix evaporate), qqrd2e
   (dielectric, units), the boundary or the periodic cell changed). Checked every step between
   evaluations: an O(N) loop and one MPI_Allreduce of three integers. The sum of hashes is an
   integer sum (modulo 2^64), so it is exact and the same however the atoms are distributed.
------------------------------------------------------------------------- */

FixCoulFMM::Continuity FixCoulFMM::field_continuity()
{
  if (last_computed < 0) return Continuity::NONE;
  if (boundary_computed != (int) opts->boundary || force->qqrd2e != qqrd2e_computed)
    return Continuity::NONE;
  if (opts->boundary == gcfmm::Boundary::Periodic2D &&
      (domain->boxlo[0] != box_computed[0] || domain->boxlo[1] != box_computed[1] ||
       domain->xprd != box_computed[2] || domain->yprd != box_computed[3]))
    return Continuity::NONE;
  // [0] the hash sum of the evaluation's charges still present, [1] atoms whose charge differs
  // from the evaluation's (a created atom has charge 0 there, set_arrays), [2] those of them
  // that were charged at the evaluation (changed, not added)
  // [3] charged atoms that were static sources (asleep) at the evaluation and are awake now: they
  // have no stored field, like added atoms
  uint64_t local[4] = {0, 0, 0, 0}, all[4];
  const tagint *tag = atom->tag;
  if (split_active()) sleepers->use(sleep_fix->sleeping(), sleep_fix->generation());
  for (int i = 0; i < atom->nlocal; i++) {
    const double q = (atom->mask[i] & groupbit) ? atom->q[i] : 0.0;
    const double q_then = eval_state[i][EVAL_Q];
    if (q_then != 0.0) local[0] += charge_hash(tag[i], q_then);
    if (q != q_then) {
      local[1]++;
      if (q_then != 0.0) local[2]++;
    }
    if (q != 0.0 && eval_state[i][EVAL_ASLEEP] != 0.0 && !(split_active() && sleepers->asleep(i)))
      local[3]++;
  }
  MPI_Allreduce(local, all, 4, MPI_UINT64_T, MPI_SUM, world);
  if (all[0] != charges_computed || all[2] != 0) return Continuity::NONE;
  return all[1] == 0 && all[3] == 0 ? Continuity::SAME : Continuity::ADDED;
}

/* ----------------------------------------------------------------------
   a full evaluation (doc/theory.md, eqs. (5.2)-(5.4)). With the same atoms as at the last
   evaluation it first measures the error the time stepping had reached: the field that would
   have been applied now (stored field + extrapolation + near refresh) against the new one.
   The slope of the far part comes from the last two evaluations, S = (E(t_e) - E(t_p) - D) /
   (t_e - t_p), D the near-pair difference over t_p -> t_e (same pairs at both ends), and only
   over a whole interval: two evaluations also differ by the solver's own error (which changes
   when the tree does), and that difference divided by a short interval would be extrapolated
   over a long one. Otherwise the slope is kept (after a shortened interval, or for the atoms
   that were there before an insertion: a particle inserted far above the others changes their
   field by a nearly constant amount) or zeroed (nothing to continue; a minimizer step).
------------------------------------------------------------------------- */

void FixCoulFMM::compute_field(bool with_slope)
{
  const int nlocal = atom->nlocal;
  const bigint step = update->ntimestep;
  const Continuity cont = (with_slope && every > 1) ? field_continuity() : Continuity::NONE;
  const bool same = cont == Continuity::SAME;
  const bool keep_slope = cont != Continuity::NONE && extrapolate;
  const double steps = same ? (double) (step - last_computed) : 0.0;
  const bool new_slope = same && extrapolate && step - last_computed >= stride;
  const bool near = same && near_cutoff > 0.0;
  // the refresh the time stepping would have applied now, and D for the new slope
  if (near) grow_near_buffers();
  if (near) near_pair_difference(near_now, keep_slope ? trend_factor(steps) : 0.0);
  if (near && new_slope) near_pair_difference(near_then, -1.0);
  for (int i = 0; i < nlocal; i++) {
    double *st = eval_state[i];
    for (int k = 0; k < 4; k++) {
      // the field the time stepping would have applied now (overwritten below)
      field[i][k] = st[EVAL_FIELD + k] + (keep_slope ? steps * st[EVAL_SLOPE + k] : 0.0) +
          (near ? near_now[i][k] : 0.0);
      if (new_slope) st[EVAL_SLOPE + k] = st[EVAL_FIELD + k] + (near ? near_then[i][k] : 0.0);
      else if (!keep_slope) st[EVAL_SLOPE + k] = 0.0;
    }
    double xu[3];
    domain->unmap(atom->x[i], atom->image[i], xu);
    if (new_slope) {
      // the slope is taken over t_e -> now: remember both ends for the near refresh
      for (int k = 0; k < 3; k++) {
        st[EVAL_SLOPE_A + k] = st[EVAL_X + k];
        st[EVAL_SLOPE_B + k] = xu[k];
      }
    }
    if (!keep_slope) st[EVAL_IN_SLOPE] = 0.0;
    for (int k = 0; k < 3; k++) st[EVAL_X + k] = xu[k];
    st[EVAL_Q] = (atom->mask[i] & groupbit) ? atom->q[i] : 0.0;
    if (new_slope) st[EVAL_IN_SLOPE] = st[EVAL_Q] != 0.0 ? 1.0 : 0.0;
    // a static source gets no field, so no slope; awake again it starts as an added atom
    st[EVAL_ASLEEP] = split_active() && sleepers->asleep(i) ? 1.0 : 0.0;
    if (st[EVAL_ASLEEP] != 0.0) {
      for (int k = 0; k < 4; k++) st[EVAL_SLOPE + k] = 0.0;
      st[EVAL_IN_SLOPE] = 0.0;
    }
  }
  if (new_slope) slope_steps = steps;
  // what the stored field belongs to (field_continuity)
  uint64_t hash_local = 0;
  for (int i = 0; i < nlocal; i++)
    if (eval_state[i][EVAL_Q] != 0.0) hash_local += charge_hash(atom->tag[i], eval_state[i][EVAL_Q]);
  MPI_Allreduce(&hash_local, &charges_computed, 1, MPI_UINT64_T, MPI_SUM, world);
  qqrd2e_computed = force->qqrd2e;
  boundary_computed = (int) opts->boundary;
  box_computed[0] = domain->boxlo[0];
  box_computed[1] = domain->boxlo[1];
  box_computed[2] = domain->xprd;
  box_computed[3] = domain->yprd;
  evaluate_into(eval_state, EVAL_FIELD);
  nevaluations++;

  double sums[2] = {0.0, 0.0};
  for (int i = 0; i < nlocal; i++) {
    double *st = eval_state[i];
    // static sources have no field to predict
    const double q2 = st[EVAL_ASLEEP] != 0.0 ? 0.0 : st[EVAL_Q] * st[EVAL_Q];
    for (int k = 0; k < 4; k++) {
      const double predicted = field[i][k];
      if (k < 3) {
        sums[0] += q2 * (predicted - st[EVAL_FIELD + k]) * (predicted - st[EVAL_FIELD + k]);
        sums[1] += q2 * st[EVAL_FIELD + k] * st[EVAL_FIELD + k];
      }
      // S = (E(t) - E(t_e) - D) / (t - t_e); E(t_e) + D was put into the slope columns
      if (new_slope) st[EVAL_SLOPE + k] = (st[EVAL_FIELD + k] - st[EVAL_SLOPE + k]) / steps;
      field[i][k] = st[EVAL_FIELD + k];
    }
  }
  if (same) {
    double all[2];
    MPI_Allreduce(sums, all, 2, MPI_DOUBLE, MPI_SUM, world);
    adapt_stride(all[1] > 0.0 ? sqrt(all[0] / all[1]) : 0.0);
  }
}

void FixCoulFMM::grow_near_buffers()
{
  if (atom->nmax <= nmax_near) return;
  nmax_near = atom->nmax;
  memory->destroy(near_now);
  memory->destroy(near_then);
  memory->create(near_now, nmax_near, 4, "coul/fmm:near_now");
  memory->create(near_then, nmax_near, 4, "coul/fmm:near_then");
}

// steps since the last evaluation over the steps the slope was taken over: the share of a
// pair's trend that the extrapolation has added by now
double FixCoulFMM::trend_factor(double steps) const
{
  return extrapolate && slope_steps > 0.0 ? steps / slope_steps : 0.0;
}

/* ----------------------------------------------------------------------
   keyword tolerance: halve the interval while the measured error exceeds the tolerance,
   double it when even the doubled interval would stay below half of it (doc/theory.md,
   eq. (5.4): the error grows as stride^2 with extrapolation, as stride without)
------------------------------------------------------------------------- */

void FixCoulFMM::adapt_stride(double error)
{
  mts_estimate = error;
  if (tolerance <= 0.0) return;
  const double growth = extrapolate ? 4.0 : 2.0;    // error factor per doubling
  while (error > tolerance && stride > 1) {
    stride /= 2;
    error /= growth;
  }
  if (mts_estimate * growth < 0.5 * tolerance && 2 * stride <= every) stride *= 2;
}

/* ----------------------------------------------------------------------
   fix sleep/gran: with keyword sleepers static (the default) the sleeping charges are a static
   source (coul_fmm_sleepers.h): not gathered, not targets (a sleeper does not move, and fix
   sleep/gran zeroes its force), their field at the awake atoms from a StaticSourceField built
   once per change of the sleeping set
------------------------------------------------------------------------- */

void FixCoulFMM::init_sleepers(bool solver_new)
{
  auto fixes = modify->get_fix_by_style("^sleep/gran$");
  sleep_fix = fixes.empty() ? nullptr : dynamic_cast<FixSleepGran *>(fixes.front());
  if (!sleep_fix || !sleepers_static) {
    sleepers.reset();
    return;
  }
  if (opts->boundary == gcfmm::Boundary::Periodic2D && opts->farfield == gcfmm::FarField::Average)
    error->all(FLERR,
               "Fix coul/fmm {} farfield average cannot treat the sleepers of fix sleep/gran {} as "
               "a static source (the average field is no pair interaction): use farfield exact or "
               "none, or keyword sleepers full",
               id, sleep_fix->id);
  if (thermo_virial)
    error->all(FLERR,
               "Fix coul/fmm {}: the virial with the static sleepers of fix sleep/gran {} would "
               "lack the sleepers' share (their forces are not computed): use keyword sleepers "
               "full, or fix_modify {} virial no",
               id, sleep_fix->id, id);
  if (solver_new || !sleepers) {
    try {
      sleepers = std::make_unique<CoulFMMSleepers>(lmp, *opts, groupbit);
    } catch (std::exception &e) {
      error->all(FLERR, "Fix coul/fmm: FMM library: {}", e.what());
    }
  }
}

namespace {
// a coincidence involving a static source, with its message in atom IDs
struct SleeperCoincidence {
  std::string message;
};
}    // namespace

// the sleepers' field at this rank's share of the awake targets (the reduce-scatter of
// evaluate_into() sums the shares; the solver's own parts are disjoint the same way)
void FixCoulFMM::add_sleepers_field(size_t n, double *pot, double *ex, double *ey, double *ez)
{
  const size_t first = n * comm->me / comm->nprocs, last = n * (comm->me + 1) / comm->nprocs;
  try {
    sleeper_qpot_local = sleepers->add_field(gx.data(), gy.data(), gz.data(), gq.data(), first,
                                             last, pot, ex, ey, ez);
  } catch (gcfmm::CoincidentParticles &e) {
    throw SleeperCoincidence{fmt::format(
        "atom {} is at the position of the sleeping atom {} (closer than {:g} of the solver's "
        "length unit): their Coulomb force is not defined",
        gtag[first + e.first()], sleepers->source_tag(e.second()), gcfmm::kCoincidenceRadius)};
  }
}

/* ----------------------------------------------------------------------
   the FMM field at the current positions: out[i][col .. col+3] = Ex, Ey, Ez, phi (LAMMPS
   units) for the local atoms, zero for atoms outside the group or uncharged
------------------------------------------------------------------------- */

void FixCoulFMM::evaluate_into(double **out, int col, bool split)
{
  if (sleep_fix && sleepers) sleepers->use(sleep_fix->sleeping(), sleep_fix->generation());
  split_now = split;
  gather_charges();
  split = split_active() && split;
  const size_t n = gtag.size();
  const int nlocal = atom->nlocal;
  for (int i = 0; i < nlocal; i++)
    for (int k = 0; k < 4; k++) out[i][col + k] = 0.0;
  if (split) {
    sleeper_pair_energy = sleeper_qpot_local = 0.0;
    // the same sleepers on every rank: a failure here is seen by all
    try {
      sleepers->prepare();
    } catch (gcfmm::CoincidentParticles &e) {
      error->all(FLERR, "Fix coul/fmm: sleeping atoms {} and {} are at the same position: their "
                 "Coulomb force is not defined", sleepers->source_tag(e.first()),
                 sleepers->source_tag(e.second()));
    } catch (std::exception &e) {
      error->all(FLERR, "Fix coul/fmm: FMM library (static sleepers): {}", e.what());
    }
  }
  if (n == 0) return;

  result.assign(4 * n, 0.0);
  double *pot = result.data(), *ex = pot + n, *ey = pot + 2 * n, *ez = pot + 3 * n;

  std::string failure;
  try {
    if (opts->boundary == gcfmm::Boundary::Periodic2D) {
      solver->set_box(domain->boxlo[0], domain->boxlo[1], domain->xprd, domain->yprd);
      // with boundary f in z every atom stays in the box: one far-field set-up for the run
      // instead of one each time the charges' z range grows (e.g. during a deposition)
      solver->set_z_range(domain->boxlo[2], domain->boxhi[2]);
    }
    solver->build(n, gx.data(), gy.data(), gz.data());
    // the ranks share the far field's anterpolation, which every one of them would otherwise
    // repeat: each computes its share, one in-place sum completes it (exact)
    const gcfmm::PartSum sum = [this](double *data, std::size_t count) {
      MPI_Allreduce(MPI_IN_PLACE, data, static_cast<int>(count), MPI_DOUBLE, MPI_SUM, world);
    };
    solver->evaluate(gq.data(), pot, ex, ey, ez, comm->me, comm->nprocs, sum);
    // the potential whose energy 1/2 sum q_i u_i has minus the applied forces as gradient
    // (differs from pot only for farfield average; doc/theory.md, eq. (4.10))
    solver->energy_potential(pot);
    if (split) add_sleepers_field(n, pot, ex, ey, ez);
  } catch (SleeperCoincidence &e) {
    failure = e.message;
  } catch (gcfmm::CoincidentParticles &e) {
    failure = fmt::format("atoms {} and {} are at the same position (closer than {:g} of the "
                          "solver's length unit): their Coulomb force is not defined",
                          gtag[e.first()], gtag[e.second()], gcfmm::kCoincidenceRadius);
  } catch (gcfmm::FarFieldTooLarge &e) {
    // the column's height (box or charges) sets the cost of the exact far field
    failure = fmt::format("{}. In LAMMPS terms: the charged column (or the box in z, with "
                          "boundary p p f) is {:.3g} times the cell side; use farfield average or "
                          "none, a box or a wall that keeps the particles lower (a lid), or "
                          "remove escaping particles (e.g. fix evaporate)",
                          e.what(), e.height_over_side());
  } catch (std::exception &e) {
    failure = e.what();
    if (failure.empty()) failure = "unknown error";
  }
  // a failure may be seen by one rank only (it owns the offending targets): agree on it
  int bad = failure.empty() ? comm->nprocs : comm->me, first = 0;
  MPI_Allreduce(&bad, &first, 1, MPI_INT, MPI_MIN, world);
  if (first < comm->nprocs) {
    int len = (int) failure.size();
    MPI_Bcast(&len, 1, MPI_INT, first, world);
    failure.resize(len);
    MPI_Bcast(&failure[0], len, MPI_CHAR, first, world);
    error->all(FLERR, Error::NOLASTLINE, "Fix coul/fmm: FMM library: {}", failure);
  }
  if (split) {
    double all = 0.0;
    MPI_Allreduce(&sleeper_qpot_local, &all, 1, MPI_DOUBLE, MPI_SUM, world);
    sleeper_pair_energy = 0.5 * force->qqrd2e * all;
  }

  // every target was computed by exactly one rank (zero elsewhere): a reduce-scatter in the
  // order of the gather sums the partitions and hands each rank its own atoms' results only
  owner_order.resize(4 * n);
  for (size_t k = 0; k < n; k++) {
    double *slot = &owner_order[4 * order[k]];
    slot[0] = ex[k];
    slot[1] = ey[k];
    slot[2] = ez[k];
    slot[3] = pot[k];
  }
  own_result.resize(result_counts[comm->me]);
  MPI_Reduce_scatter(owner_order.data(), own_result.data(), result_counts.data(), MPI_DOUBLE,
                     MPI_SUM, world);

  // the received block is in the order gather_charges() packed this rank's atoms
  // bare 1/r kernel -> LAMMPS units: qqrd2e includes the dielectric constant
  const double c = force->qqrd2e;
  int *mask = atom->mask;
  double *q = atom->q;
  size_t m = 0;
  for (int i = 0; i < nlocal; i++) {
    if (!(mask[i] & groupbit) || q[i] == 0.0 || (split && sleepers->asleep(i))) continue;
    for (int k = 0; k < 4; k++) out[i][col + k] = c * own_result[4 * m + k];
    m++;
  }

  if (!logged && comm->me == 0) {
    const auto &st = solver->stats();
    static const char *ffname[] = {"none", "average", "exact"};
    utils::logmesg(lmp,
                   "FMM Coulomb (fix coul/fmm {}): {} charged atoms, {}\n"
                   "  order = {}, theta = {:.3g}, leaf = {}, levels = {}{}\n"
                   "  estimated relative RMS force error = {:.3g} (requested accuracy {:.3g})\n",
                   id, n,
                   opts->boundary == gcfmm::Boundary::Free ? "free space" : "periodic in x y",
                   st.order, st.theta, st.leaf, st.levels,
                   opts->boundary == gcfmm::Boundary::Free
                       ? std::string()
                       : fmt::format(", images = {}, farfield = {}", opts->images,
                                     ffname[(int) opts->farfield]),
                   st.estimated_error, opts->accuracy);
  }
  logged = true;
}

/* ----------------------------------------------------------------------
   multiple time stepping between evaluations (doc/theory.md, eqs. (5.2)-(5.3)): the far part is
   extrapolated with its slope, the field of the pairs closer than the near cutoff follows the
   atoms,
     E_i(t) = E_i(t_e) + (t - t_e) S_i + C sum_{j: |r_ij(t)| < rc} q_j [K(r_ij(t)) - K(r_ij(t_e))]
   K(r) = r / |r|^3, with r_ij(t_e) = r_ij(t) - (d_i - d_j), d = displacement since the
   evaluation at t_e (the same for every image of an atom, so periodic images need no special
   case), S_i the slope of the far part (0 with extrapolate no)
------------------------------------------------------------------------- */

void FixCoulFMM::advance_field()
{
  const double steps = (double) (update->ntimestep - last_computed);
  if (near_cutoff > 0.0) {
    grow_near_buffers();
    near_pair_difference(near_now, trend_factor(steps));
  }
  for (int i = 0; i < atom->nlocal; i++)
    for (int k = 0; k < 4; k++)
      field[i][k] = eval_state[i][EVAL_FIELD + k] +
          (extrapolate ? steps * eval_state[i][EVAL_SLOPE + k] : 0.0) +
          (near_cutoff > 0.0 ? near_now[i][k] : 0.0);
}

/* ----------------------------------------------------------------------
   out[i] = C sum_j q_j [(K, 1/r)(r_ij(t)) - (K, 1/r)(r_ij(t_e))] for the local atoms, t_e the
   last evaluation, over the pairs closer than rc now (trend < 0: the D of a new slope) or now
   or at t_e (trend >= 0: the refresh between evaluations); with trend > 0, minus trend times
   the change over the slope's interval t_A -> t_B of the pairs beyond rc at t_B, whose trend
   the slope carries (doc/theory.md, eq. (5.3))
------------------------------------------------------------------------- */

void FixCoulFMM::near_pair_difference(double **out, double trend)
{
  const int nlocal = atom->nlocal, nall = nlocal + atom->nghost;
  if (nall > nmax_ghost) {
    nmax_ghost = atom->nmax;
    memory->destroy(near_delta);
    memory->create(near_delta, nmax_ghost, NEAR_COMM, "coul/fmm:near_delta");
  }
  double **x = atom->x;
  double xu[3];
  for (int i = 0; i < nlocal; i++) {
    domain->unmap(x[i], atom->image[i], xu);
    for (int k = 0; k < 3; k++) {
      near_delta[i][DELTA_E + k] = xu[k] - eval_state[i][EVAL_X + k];
      near_delta[i][DELTA_A + k] = xu[k] - eval_state[i][EVAL_SLOPE_A + k];
      near_delta[i][DELTA_B + k] = xu[k] - eval_state[i][EVAL_SLOPE_B + k];
    }
    near_delta[i][DELTA_IN_SLOPE] = eval_state[i][EVAL_IN_SLOPE];
  }
  comm->forward_comm(this);

  // each pair once: the field at i from j is q_j g(r_ij) with g(r) = r / |r|^3, at j from i
  // -q_i g(r_ij); the potentials q_j / r and q_i / r. A ghost j is a local atom elsewhere (or
  // an image here) whose own list holds the pair the other way round: only i is updated.
  const double c = force->qqrd2e, near_cutsq = near_cutoff * near_cutoff;
  double *q = atom->q;
  int *mask = atom->mask;
  for (int i = 0; i < nlocal; i++)
    for (int k = 0; k < 4; k++) out[i][k] = 0.0;
  for (int ii = 0; ii < list->inum; ii++) {
    const int i = list->ilist[ii];
    if (!(mask[i] & groupbit) || q[i] == 0.0) continue;
    const int *jlist = list->firstneigh[i];
    double e[4] = {0.0, 0.0, 0.0, 0.0};
    for (int jj = 0; jj < list->numneigh[i]; jj++) {
      const int j = jlist[jj] & NEIGHMASK;
      if (!(mask[j] & groupbit) || q[j] == 0.0) continue;
      const double *di = near_delta[i], *dj = near_delta[j];
      double now[3], then[3];
      for (int k = 0; k < 3; k++) {
        now[k] = x[i][k] - x[j][k];
        then[k] = now[k] - (di[DELTA_E + k] - dj[DELTA_E + k]);
      }
      // refreshed: the pairs now closer than the cutoff and, between evaluations (trend >= 0),
      // also those that were at the last evaluation (their change is in no slope). The sets
      // depend on positions only (not on when the list was built), so split runs agree.
      const double rn2 = now[0] * now[0] + now[1] * now[1] + now[2] * now[2];
      const double rt2 = then[0] * then[0] + then[1] * then[1] + then[2] * then[2];
      if (rn2 >= near_cutsq && (trend < 0.0 || rt2 >= near_cutsq)) continue;
      if (rn2 == 0.0 || rt2 == 0.0) continue;    // coincident atoms are caught at evaluations
      const double in = 1.0 / sqrt(rn2), it = 1.0 / sqrt(rt2);
      const double sn = in * in * in, st = it * it * it;
      double dg[4];    // change of g and of 1/r since the evaluation
      for (int k = 0; k < 3; k++) dg[k] = sn * now[k] - st * then[k];
      dg[3] = in - it;
      // a pair that was beyond the cutoff at the later evaluation of the slope has its trend
      // in the slope: take it out, the pair is summed exactly (doc/theory.md, eq. (5.3))
      if (trend > 0.0 && di[DELTA_IN_SLOPE] != 0.0 && dj[DELTA_IN_SLOPE] != 0.0) {
        double rb[3], ra[3];
        for (int k = 0; k < 3; k++) {
          rb[k] = now[k] - (di[DELTA_B + k] - dj[DELTA_B + k]);
          ra[k] = now[k] - (di[DELTA_A + k] - dj[DELTA_A + k]);
        }
        const double rb2 = rb[0] * rb[0] + rb[1] * rb[1] + rb[2] * rb[2];
        const double ra2 = ra[0] * ra[0] + ra[1] * ra[1] + ra[2] * ra[2];
        if (rb2 >= near_cutsq && ra2 > 0.0) {
          const double ib = 1.0 / sqrt(rb2), ia = 1.0 / sqrt(ra2);
          const double sb = trend * ib * ib * ib, sa = trend * ia * ia * ia;
          for (int k = 0; k < 3; k++) dg[k] -= sb * rb[k] - sa * ra[k];
          dg[3] -= trend * (ib - ia);
        }
      }
      for (int k = 0; k < 4; k++) e[k] += q[j] * dg[k];
      if (j < nlocal) {
        for (int k = 0; k < 3; k++) out[j][k] -= q[i] * dg[k];
        out[j][3] += q[i] * dg[3];
      }
    }
    for (int k = 0; k < 4; k++) out[i][k] += e[k];
  }
  for (int i = 0; i < nlocal; i++)
    for (int k = 0; k < 4; k++) out[i][k] *= c;
}

/* ----------------------------------------------------------------------
   keyword check: the relative RMS difference between the applied force and the force of a
   fresh evaluation at the same positions, sqrt(sum q_i^2 |E_i - E_i,fresh|^2 / sum q_i^2
   |E_i,fresh|^2), i.e. the error that every/near add to the solver's own
------------------------------------------------------------------------- */

void FixCoulFMM::measure_mts_error()
{
  const int nlocal = atom->nlocal;
  if (nlocal > nmax_check) {
    nmax_check = atom->nmax;
    memory->destroy(fresh);
    memory->create(fresh, nmax_check, 4, "coul/fmm:fresh");
  }
  // with static sleepers: against a full evaluation of all charges, at the awake atoms (the
  // error of the split and of the time stepping together)
  evaluate_into(fresh, 0, false);
  double sums[2] = {0.0, 0.0}, all[2];
  for (int i = 0; i < nlocal; i++) {
    if (split_active() && sleepers->asleep(i)) continue;
    const double q2 = atom->q[i] * atom->q[i];
    for (int k = 0; k < 3; k++) {
      sums[0] += q2 * (field[i][k] - fresh[i][k]) * (field[i][k] - fresh[i][k]);
      sums[1] += q2 * fresh[i][k] * fresh[i][k];
    }
  }
  MPI_Allreduce(sums, all, 2, MPI_DOUBLE, MPI_SUM, world);
  const double err = all[1] > 0.0 ? sqrt(all[0] / all[1]) : 0.0;
  check_last = err;
  check_max = MAX(check_max, err);
  check_num += all[0];
  check_den += all[1];
}

/* ----------------------------------------------------------------------
   F_i = q_i E_i; energy 1/2 sum q_i phi_i; virial sum x_i F_i (see the doc for its scope)
------------------------------------------------------------------------- */

void FixCoulFMM::apply_field(int /*vflag*/)
{
  const int nlocal = atom->nlocal;
  double **x = atom->x;
  double **f = atom->f;
  double *q = atom->q;
  int *mask = atom->mask;
  energy_local = 0.0;
  energy_summed = false;
  double v[6];
  const bool periodic_xy = opts->boundary == gcfmm::Boundary::Periodic2D;
  for (int i = 0; i < nlocal; i++) {
    if (!(mask[i] & groupbit) || q[i] == 0.0) continue;
    const double fx = q[i] * field[i][0], fy = q[i] * field[i][1], fz = q[i] * field[i][2];
    f[i][0] += fx;
    f[i][1] += fy;
    f[i][2] += fz;
    energy_local += 0.5 * q[i] * field[i][3];
    if (evflag) {
      // with x and y periodic only the zz term of sum x_i F_i is the virial of the lattice
      // (image shifts have no z component); the in-plane terms are left out
      const bool in_plane = !periodic_xy;
      v[0] = in_plane ? fx * x[i][0] : 0.0;
      v[1] = in_plane ? fy * x[i][1] : 0.0;
      v[2] = fz * x[i][2];
      v[3] = in_plane ? fy * x[i][0] : 0.0;
      v[4] = in_plane ? fz * x[i][0] : 0.0;
      v[5] = in_plane ? fz * x[i][1] : 0.0;
      v_tally(i, v);
    }
  }
}

/* ---------------------------------------------------------------------- */

double FixCoulFMM::compute_scalar()
{
  if (!energy_summed) {
    MPI_Allreduce(&energy_local, &energy_all, 1, MPI_DOUBLE, MPI_SUM, world);
    energy_summed = true;
  }
  // static sleepers: their pair energy with the awake charges (constant between evaluations)
  // and among themselves (once per sleeping set)
  if (split_active()) return energy_all + sleeper_pair_energy + force->qqrd2e * sleepers->source_energy();
  return energy_all;
}

/* ----------------------------------------------------------------------
   1: estimated relative RMS force error, 2: expansion order, 3: M2L interactions,
   4: particle pairs summed directly (all of the last evaluation, the same on every rank);
   keyword check: 5 the last measured MTS error, 6 the largest, 7 that of all checks together
   (sums of squares over all checks: weighted by the field, unlike the largest, which a
   check at a nearly vanishing field can dominate); 8 the evaluation interval now, 9 the MTS
   error measured at the last scheduled evaluation (-1: none yet), 10 evaluations so far
------------------------------------------------------------------------- */

double FixCoulFMM::compute_vector(int n)
{
  if (n == 4) return check_last;
  if (n == 5) return check_max;
  if (n == 6) return check_den > 0.0 ? sqrt(check_num / check_den) : 0.0;
  if (n == 7) return (double) stride;
  if (n == 8) return mts_estimate;
  if (n == 9) return (double) nevaluations;
  if (!solver) return 0.0;
  const auto &st = solver->stats();
  switch (n) {
    case 0:
      return st.estimated_error;
    case 1:
      return st.order;
    case 2:
      return (double) st.m2l_count;
    case 3:
      return (double) st.p2p_pairs;
    default:
      return 0.0;
  }
}

/* ---------------------------------------------------------------------- */

double FixCoulFMM::memory_usage()
{
  double bytes = (4.0 + EVAL_COLS) * atom->nmax * sizeof(double) +
      (double) NEAR_COMM * nmax_ghost * sizeof(double) + 8.0 * nmax_near * sizeof(double);
  bytes += (double) (gx.capacity() * 14) * sizeof(double);    // gathered atoms and results
  if (sleepers) bytes += sleepers->memory_usage();
  return bytes;
}

/* ---------------------------------------------------------------------- */

void FixCoulFMM::grow_arrays(int nmax)
{
  memory->grow(field, nmax, 4, "coul/fmm:field");
  memory->grow(eval_state, nmax, EVAL_COLS, "coul/fmm:eval_state");
  array_atom = field;
}

void FixCoulFMM::copy_arrays(int i, int j, int /*delflag*/)
{
  for (int k = 0; k < 4; k++) field[j][k] = field[i][k];
  for (int k = 0; k < EVAL_COLS; k++) eval_state[j][k] = eval_state[i][k];
}

// a created atom has no stored field; its charge 0 in eval_state marks it as new
void FixCoulFMM::set_arrays(int i)
{
  for (int k = 0; k < 4; k++) field[i][k] = 0.0;
  for (int k = 0; k < EVAL_COLS; k++) eval_state[i][k] = 0.0;
}

int FixCoulFMM::pack_exchange(int i, double *buf_out)
{
  for (int k = 0; k < 4; k++) buf_out[k] = field[i][k];
  for (int k = 0; k < EVAL_COLS; k++) buf_out[4 + k] = eval_state[i][k];
  return 4 + EVAL_COLS;
}

int FixCoulFMM::unpack_exchange(int nlocal, double *buf_in)
{
  for (int k = 0; k < 4; k++) field[nlocal][k] = buf_in[k];
  for (int k = 0; k < EVAL_COLS; k++) eval_state[nlocal][k] = buf_in[4 + k];
  return 4 + EVAL_COLS;
}

int FixCoulFMM::pack_forward_comm(int n, int *list_send, double *buf_out, int /*pbc_flag*/,
                                  int * /*pbc*/)
{
  int m = 0;
  for (int i = 0; i < n; i++)
    for (int k = 0; k < NEAR_COMM; k++) buf_out[m++] = near_delta[list_send[i]][k];
  return m;
}

void FixCoulFMM::unpack_forward_comm(int n, int first, double *buf_in)
{
  int m = 0;
  for (int i = first; i < first + n; i++)
    for (int k = 0; k < NEAR_COMM; k++) near_delta[i][k] = buf_in[m++];
}

/* ----------------------------------------------------------------------
   restart: the step, box, charge checksum, qqrd2e and boundary of the last evaluation
   (global), the applied and the evaluated field with the evaluation positions and charges (per atom)
------------------------------------------------------------------------- */

void FixCoulFMM::write_restart(FILE *fp)
{
  if (comm->me == 0) {
    // the 64-bit checksum as two 32-bit halves (exact in doubles)
    double list_out[RESTART_GLOBAL_SIZE] = {RESTART_FORMAT_CHECKSUM,
                                            (double) last_computed,
                                            box_computed[0],
                                            box_computed[1],
                                            box_computed[2],
                                            box_computed[3],
                                            (double) every,
                                            tolerance,
                                            (double) stride,
                                            slope_steps,
                                            (double) (charges_computed >> 32),
                                            (double) (charges_computed & 0xffffffffULL),
                                            qqrd2e_computed,
                                            (double) boundary_computed};
    int size = sizeof(list_out);
    fwrite(&size, sizeof(int), 1, fp);
    fwrite(list_out, sizeof(double), RESTART_GLOBAL_SIZE, fp);
  }
}

void FixCoulFMM::restart(char *buf)
{
  auto *list_in = (double *) buf;
  // a file without the charge checksum (older format): evaluate afresh
  if (list_in[R_FORMAT] != RESTART_FORMAT_CHECKSUM) return;
  // a different every or tolerance gives a different schedule: evaluate afresh
  if ((int) list_in[R_EVERY] != every || list_in[R_TOLERANCE] != tolerance) return;
  stride = (int) list_in[R_STRIDE];
  slope_steps = list_in[R_SLOPE];
  last_computed = (bigint) list_in[R_LAST];
  for (int k = 0; k < 4; k++) box_computed[k] = list_in[R_BOX + k];
  charges_computed = ((uint64_t) list_in[R_SUM_HI] << 32) | (uint64_t) list_in[R_SUM_LO];
  qqrd2e_computed = list_in[R_QQRD2E];
  boundary_computed = (int) list_in[R_BOUNDARY];
}

int FixCoulFMM::pack_restart(int i, double *buf_out)
{
  buf_out[0] = 5 + EVAL_COLS;    // count first, as atom->extra is shared by the fixes
  for (int k = 0; k < 4; k++) buf_out[1 + k] = field[i][k];
  for (int k = 0; k < EVAL_COLS; k++) buf_out[5 + k] = eval_state[i][k];
  return 5 + EVAL_COLS;
}

void FixCoulFMM::unpack_restart(int nlocal, int nth)
{
  double **extra = atom->extra;
  int m = 0;
  for (int i = 0; i < nth; i++) m += static_cast<int>(extra[nlocal][m]);
  // files written before EVAL_ASLEEP hold EVAL_COLS_V1 columns: the rest start at zero
  const int cols = MIN(EVAL_COLS, MAX(EVAL_COLS_V1, static_cast<int>(extra[nlocal][m]) - 5));
  m++;
  for (int k = 0; k < 4; k++) field[nlocal][k] = extra[nlocal][m++];
  for (int k = 0; k < EVAL_COLS; k++) eval_state[nlocal][k] = k < cols ? extra[nlocal][m++] : 0.0;
}

int FixCoulFMM::size_restart(int /*nlocal*/)
{
  return 5 + EVAL_COLS;
}

int FixCoulFMM::maxsize_restart()
{
  return 5 + EVAL_COLS;
}
