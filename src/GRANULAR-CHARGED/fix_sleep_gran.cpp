/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "fix_sleep_gran.h"
#include "sleep_bed_reach.h"
#include "wall_gran_touch.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "fix_neigh_history.h"
#include "force.h"
#include "group.h"
#include "memory.h"
#include "modify.h"
#include "neigh_list.h"
#include "neighbor.h"
#include "pair.h"
#include "update.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

using namespace LAMMPS_NS;
using namespace FixConst;

namespace {
// what pack_forward_comm() and pack_reverse_comm() move
enum CommMode { COMM_FLAGS, COMM_PUSHED, COMM_PUSH, COMM_WAKE };
// slots of the global restart list
enum RestartSlot { R_FALLEN_ASLEEP, R_WOKEN, R_NSLOTS };
// the elements of the global vector (compute_vector's index)
enum VectorElement { V_AWAKE, V_SLEEPING, V_FALLEN_ASLEEP, V_WOKEN, V_NELEMENTS };
}    // namespace

/* ---------------------------------------------------------------------- */

FixSleepGran::FixSleepGran(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), speed_sleep(-1.0), force_sleep(-1.0), force_wake(-1.0), rest_time(-1.0),
    depth(0.0), every(100), rest_steps_needed(0), rest_rule(true), pairs_awake(0), asleep(nullptr),
    pushed(nullptr), rest_steps(nullptr), push(nullptr), wake_mark(nullptr), ncontact(nullptr),
    comm_mode(COMM_FLAGS),
    set_generation(0), fallen_asleep_total(0), woken_total(0), pair_history(nullptr),
    active_build(-1), active_generation(-1), buried_past_nfirst(false)
{
  if (!(atom->radius_flag && atom->rmass_flag && atom->omega_flag && atom->torque_flag))
    error->all(FLERR, "Fix {} requires atom attributes radius, rmass, omega and torque (atom_style sphere)", style);

  int iarg = 3;
  auto positive = [&](const char *key) {
    if (iarg + 2 > narg) utils::missing_cmd_args(FLERR, std::string("fix sleep/gran ") + key, error);
    const double v = utils::numeric(FLERR, arg[iarg + 1], false, lmp);
    if (!(v > 0.0) || !std::isfinite(v))
      error->all(FLERR, "Fix {} {} must be > 0, got {}", style, key, arg[iarg + 1]);
    iarg += 2;
    return v;
  };
  while (iarg < narg) {
    if (strcmp(arg[iarg], "speed") == 0) {
      speed_sleep = positive("speed");
    } else if (strcmp(arg[iarg], "force") == 0) {
      force_sleep = positive("force");
    } else if (strcmp(arg[iarg], "wake") == 0) {
      force_wake = positive("wake");
    } else if (strcmp(arg[iarg], "time") == 0) {
      if (iarg + 2 > narg) utils::missing_cmd_args(FLERR, "fix sleep/gran time", error);
      if (strcmp(arg[iarg + 1], "none") == 0) {
        rest_rule = false;    // only the depth rule puts atoms to sleep
        rest_time = 0.0;
      } else {
        rest_time = utils::numeric(FLERR, arg[iarg + 1], false, lmp);
        if (!(rest_time >= 0.0) || !std::isfinite(rest_time))
          error->all(FLERR, "Fix {} time must be >= 0 or none, got {}", style, arg[iarg + 1]);
      }
      iarg += 2;
    } else if (strcmp(arg[iarg], "every") == 0) {
      if (iarg + 2 > narg) utils::missing_cmd_args(FLERR, "fix sleep/gran every", error);
      every = utils::inumeric(FLERR, arg[iarg + 1], false, lmp);
      if (every < 1) error->all(FLERR, "Fix {} every must be >= 1, got {}", style, arg[iarg + 1]);
      iarg += 2;
    } else if (strcmp(arg[iarg], "depth") == 0) {
      depth = positive("depth");
    } else if (strcmp(arg[iarg], "pairs") == 0) {
      if (iarg + 2 > narg) utils::missing_cmd_args(FLERR, "fix sleep/gran pairs", error);
      if (strcmp(arg[iarg + 1], "all") == 0)
        pairs_awake = 0;
      else if (strcmp(arg[iarg + 1], "awake") == 0)
        pairs_awake = 1;
      else
        error->all(FLERR, "Fix {} pairs must be all or awake, got {}", style, arg[iarg + 1]);
      iarg += 2;
    } else {
      error->all(FLERR, "Unknown fix {} keyword {}", style, arg[iarg]);
    }
  }
  if (speed_sleep < 0.0 || force_sleep < 0.0 || force_wake < 0.0 || rest_time < 0.0)
    error->all(FLERR, "Fix {} needs the keywords speed, force, wake and time", style);
  if (!rest_rule && depth <= 0.0)
    error->all(FLERR, "Fix {} time none needs keyword depth (nothing would fall asleep)", style);

  scalar_flag = 1;
  vector_flag = 1;
  size_vector = V_NELEMENTS;
  global_freq = 1;
  extscalar = 0;
  extvector = 0;
  peratom_flag = 1;
  size_peratom_cols = 0;
  peratom_freq = 1;
  create_attribute = 1;    // created atoms are awake (set_arrays)
  restart_peratom = 1;
  restart_global = 1;
  comm_forward = 1;
  comm_reverse = 4;

  FixSleepGran::grow_arrays(atom->nmax);
  atom->add_callback(Atom::GROW);
  atom->add_callback(Atom::RESTART);
  for (int i = 0; i < atom->nmax; i++) {
    asleep[i] = pushed[i] = rest_steps[i] = wake_mark[i] = ncontact[i] = 0.0;
    push[i][0] = push[i][1] = push[i][2] = 0.0;
  }
}

/* ---------------------------------------------------------------------- */

FixSleepGran::~FixSleepGran()
{
  if (copymode) return;
  atom->delete_callback(id, Atom::GROW);
  atom->delete_callback(id, Atom::RESTART);
  memory->destroy(asleep);
  memory->destroy(pushed);
  memory->destroy(rest_steps);
  memory->destroy(push);
  memory->destroy(wake_mark);
  memory->destroy(ncontact);
}

/* ---------------------------------------------------------------------- */

int FixSleepGran::setmask()
{
  return PRE_FORCE | POST_FORCE;
}

/* ---------------------------------------------------------------------- */

void FixSleepGran::init()
{
  if (!force->pair_match("^granular", 0) || !force->pair->single_enable)
    error->all(FLERR, "Fix {} requires pair_style granular or granular/opt, not {}", style,
               force->pair_style ? force->pair_style : "none");
  if (modify->get_fix_by_style("^sleep/gran$").size() > 1)
    error->all(FLERR, "Only one fix sleep/gran may be defined");
  // only granular/opt leaves out the pairs of two sleepers: with any other style the keyword
  // would change nothing, and -sf opt would silently give another trajectory than the plain style
  if (pairs_awake && !force->pair_match("granular/opt", 1))
    error->all(FLERR,
               "Fix {} pairs awake requires pair_style granular/opt (or -sf opt), not {}: pair "
               "style {} computes every pair; use pairs all",
               style, force->pair_style, force->pair_style);
  // the pair style's contact flags, if its models keep a history (fix neigh/history)
  auto histories = modify->get_fix_by_style("^NEIGH_HISTORY$");
  if (histories.size() > 1)
    error->all(FLERR, "Fix {} needs a single granular pair style with one contact history", style);
  pair_history = histories.empty() ? nullptr : dynamic_cast<FixNeighHistory *>(histories.front());
  // an atom resting on a granular wall touches something: its wall contacts count with its pair
  // contacts (a wall whose model does not flag its contacts is left out, see the doc)
  walls.clear();
  for (auto *f : modify->get_fix_list()) {
    if (!utils::strmatch(f->style, "^wall/gran$") && !utils::strmatch(f->style, "^wall/gran/opt$"))
      continue;
    auto *wall = dynamic_cast<FixWallGran *>(f);
    if (wall && wall_gran_touch_flags(wall)) walls.push_back(wall);
  }
  for (auto *f : modify->get_fix_list()) {
    if (f->rigid_flag) error->all(FLERR, "Fix {} cannot be used with the rigid-body fix {}", style, f->id);
    if (utils::strmatch(f->style, "^deposit") || utils::strmatch(f->style, "^pour"))
      if (groupbit != 1 && f->groupbit != groupbit)
        error->all(FLERR,
                   "Fix {} group {} does not contain the atoms that fix {} {} inserts (group {}): "
                   "use group all or the same group",
                   style, group->names[igroup], f->style, f->id, group->names[f->igroup]);
  }
  if (update->whichflag == 2) error->all(FLERR, "Fix {} cannot be used with minimization", style);
  check_fix_order();
  active_build = active_generation = -1;    // the pair's list may be another one
  // fix bury/gran keeps its group (that of atom_modify first) equal to the atoms that may move
  // or be touched: its buried sleepers lie past atom->nfirst (LAMMPS orders them there at each
  // build), out of the pair's list and of the ghosts, with zero velocity, force and spin
  buried_past_nfirst = false;
  for (auto *f : modify->get_fix_by_style("^bury/gran$")) {
    int dim = -1;
    const auto *sleep_id = static_cast<const char *>(f->extract("sleep", dim));
    if (sleep_id && strcmp(sleep_id, id) == 0) buried_past_nfirst = true;
  }
  rest_steps_needed = static_cast<int>(std::ceil(rest_time / update->dt - 1e-9));
}

/* ----------------------------------------------------------------------
   the forces tested and zeroed in post_force() must be complete: no fix that adds forces in
   post_force may come after this one
------------------------------------------------------------------------- */

void FixSleepGran::check_fix_order()
{
  bool after = false;
  for (auto *f : modify->get_fix_list()) {
    if (f == this) {
      after = true;
      continue;
    }
    if (after && (f->setmask() & POST_FORCE))
      error->all(FLERR,
                 "Fix {} must be defined after every fix that adds forces; fix {} ({}) comes "
                 "after it",
                 style, f->id, f->style);
  }
}

/* ---------------------------------------------------------------------- */

void FixSleepGran::setup_pre_force(int /*vflag*/)
{
  exchange_flags();
  clear_push_and_contacts();
}

/* ---------------------------------------------------------------------- */

void FixSleepGran::setup(int /*vflag*/)
{
  hold_sleepers(false);
}

/* ----------------------------------------------------------------------
   ghosts are new after a neighbor list build: give them their owners' flags
------------------------------------------------------------------------- */

void FixSleepGran::pre_force(int /*vflag*/)
{
  if (neighbor->ago == 0) exchange_flags();
  clear_push_and_contacts();
}

/* ---------------------------------------------------------------------- */

void FixSleepGran::clear_push_and_contacts()
{
  auto clear = [&](int from, int to) {
    for (int i = from; i < to; i++) {
      push[i][0] = push[i][1] = push[i][2] = 0.0;
      ncontact[i] = 0.0;
    }
  };
  clear(0, nvisited());
  clear(atom->nlocal, atom->nlocal + atom->nghost);
}

/* ----------------------------------------------------------------------
   the local atoms visited each step: all of them, or with a fix bury/gran of this fix those
   before atom->nfirst (the others are buried sleepers: not listed, not ghosts, held at rest)
------------------------------------------------------------------------- */

int FixSleepGran::nvisited() const
{
  return buried_past_nfirst ? atom->nfirst : atom->nlocal;
}

/* ----------------------------------------------------------------------
   the contacts are read on commit steps only, and on every step by the rest rule
------------------------------------------------------------------------- */

bool FixSleepGran::counting_step() const
{
  return rest_rule || update->ntimestep % every == 0;
}

/* ---------------------------------------------------------------------- */

void FixSleepGran::exchange_flags()
{
  comm_mode = COMM_FLAGS;
  comm->forward_comm(this);
}

/* ---------------------------------------------------------------------- */

void FixSleepGran::post_force(int /*vflag*/)
{
  sum_contacts_and_push();
  if (force->newton_pair) {
    comm_mode = COMM_PUSH;
    comm->reverse_comm(this, 4);
  }
  if (counting_step()) count_wall_contacts();
  wake_pushed();

  // rest time of the awake atoms of the group (those woken now start counting next step);
  // with time none nothing reads it
  int *mask = atom->mask;
  const int nvisit = rest_rule ? nvisited() : 0;
  for (int i = 0; i < nvisit; i++) {
    if (asleep[i] != 0.0 || wake_mark[i] != 0.0) continue;
    if ((mask[i] & groupbit) && ncontact[i] > 0.0 && at_rest(i))
      rest_steps[i] += 1.0;
    else
      rest_steps[i] = 0.0;
  }

  // falling asleep happens only on commit steps (fall_asleep() sums its count over the ranks)
  const bigint before = fallen_asleep_total;
  if (update->ntimestep % every == 0) fall_asleep();
  if (fallen_asleep_total != before) {
    exchange_flags();
    set_generation++;
  }
  // with pairs awake the contacts of the sleepers woken now with other sleepers were not
  // computed on this step: their forces are incomplete, so they are held this step too and
  // move from the next, with all their contacts computed
  hold_sleepers(pairs_awake != 0);
}

/* ----------------------------------------------------------------------
   the contacts of this step (touching pairs but those of two sleepers) and, for each sleeper,
   the contact forces of its awake partners, recomputed by the pair's single() from the pair's
   neighbor list after the pair has advanced the contact histories by the step: one bookkeeping
   for every pair style, so that the wake decisions do not depend on the style. single() of a
   sliding model rewrites the history of a slipping contact (LAMMPS's mindlin does, and the
   Marshall set with it), at the level of rounding: the contact's history is restored after it,
   so that the trajectory is the one without this fix
------------------------------------------------------------------------- */

void FixSleepGran::sum_contacts_and_push()
{
  Pair *pair = force->pair;
  NeighList *list = pair->list;
  if (!list) return;
  double **x = atom->x;
  int *type = atom->type;
  const int nlocal = atom->nlocal;
  const int newton_pair = force->newton_pair;
  double *special_lj = force->special_lj;
  const int size_history = pair_history ? pair_history->get_dnum() : 0;
  kept_history.resize(size_history);
  update_active_entries(list);
  // on the steps whose contacts are not counted only the pushes are summed, over the entries
  // of awake-sleeper pairs
  const bool count = counting_step();
  for (const int ii : count ? active_entries : interface_entries) {
    const int i = list->ilist[ii];
    const int *jlist = list->firstneigh[i];
    const int *touch = pair_history ? pair_history->firstflag[i] : nullptr;
    for (int jj = 0; jj < list->numneigh[i]; jj++) {
      const double factor_lj = special_lj[(jlist[jj] >> SBBITS) & 3];
      const int j = jlist[jj] & NEIGHMASK;
      const bool pushes = (asleep[i] != 0.0) != (asleep[j] != 0.0);    // one asleep, one awake
      if (factor_lj == 0.0 || (asleep[i] != 0.0 && asleep[j] != 0.0)) continue;
      if (!count && !pushes) continue;
      if (!touching(i, j, jj, touch)) continue;
      const bool j_here = newton_pair || j < nlocal;
      if (count) {
        ncontact[i] += 1.0;
        if (j_here) ncontact[j] += 1.0;
      }
      if (!pushes) continue;
      double dx[3] = {x[i][0] - x[j][0], x[i][1] - x[j][1], x[i][2] - x[j][2]};
      const double rsq = dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2];
      double fpair = 0.0;
      double *history = pair_history ? &pair_history->firstvalue[i][size_history * jj] : nullptr;
      if (history) std::copy(history, history + size_history, kept_history.begin());
      pair->single(i, j, type[i], type[j], rsq, 1.0, factor_lj, fpair);
      if (history) std::copy(kept_history.begin(), kept_history.end(), history);
      // the force on i: normal (fpair along dx) plus the sliding force svector[0..2]
      for (int k = 0; k < 3; k++) {
        const double fk = factor_lj * (fpair * dx[k] + pair->svector[k]);
        if (asleep[i] != 0.0) push[i][k] += fk;
        if (asleep[j] != 0.0 && j_here) push[j][k] -= fk;
      }
    }
  }
}

/* ----------------------------------------------------------------------
   the wall contacts of the local atoms, on the steps whose contacts are counted (the walls'
   post_force came before this fix's): an atom alone on the floor is at rest on something
------------------------------------------------------------------------- */

void FixSleepGran::count_wall_contacts()
{
  const int nvisit = nvisited();
  for (auto *wall : walls) {
    double **touch = wall_gran_touch_flags(wall);
    const int *mask = atom->mask;
    const int wallbit = wall->groupbit;
    for (int i = 0; i < nvisit; i++)
      if ((mask[i] & wallbit) && touch[i][0] != 0.0) ncontact[i] += 1.0;
  }
}

/* ----------------------------------------------------------------------
   the entries of the pair's list that hold a pair with an awake atom (an awake atom, or a
   sleeper with an awake neighbor), and those that hold an awake-sleeper pair (the bed's
   surface, where pushes are summed), rebuilt after each neighbor list build and each change
   of the sleeping set
------------------------------------------------------------------------- */

void FixSleepGran::update_active_entries(const NeighList *list)
{
  if (active_build == neighbor->lastcall && active_generation == set_generation) return;
  active_build = neighbor->lastcall;
  active_generation = set_generation;
  active_entries.clear();
  interface_entries.clear();
  for (int ii = 0; ii < list->inum; ii++) {
    const int i = list->ilist[ii];
    const bool i_awake = asleep[i] == 0.0;
    bool awake_j = false, asleep_j = false;
    const int *jlist = list->firstneigh[i];
    for (int jj = 0; jj < list->numneigh[i] && !(awake_j && asleep_j); jj++) {
      if (asleep[jlist[jj] & NEIGHMASK] == 0.0) awake_j = true;
      else asleep_j = true;
    }
    if (i_awake || awake_j) active_entries.push_back(ii);
    if (i_awake ? asleep_j : awake_j) interface_entries.push_back(ii);
  }
}

/* ----------------------------------------------------------------------
   pair i, j (entry jj of i's list) in contact: the pair style's contact flag when its models
   keep a history, else overlap
------------------------------------------------------------------------- */

bool FixSleepGran::touching(int i, int j, int jj, const int *touch) const
{
  if (touch) return touch[jj] != 0;
  double **x = atom->x;
  const double dx = x[i][0] - x[j][0], dy = x[i][1] - x[j][1], dz = x[i][2] - x[j][2];
  const double radsum = atom->radius[i] + atom->radius[j];
  return dx * dx + dy * dy + dz * dz < radsum * radsum;
}

/* ---------------------------------------------------------------------- */

bool FixSleepGran::at_rest(int i) const
{
  const double *v = atom->v[i], *w = atom->omega[i], *f = atom->f[i];
  const double r = atom->radius[i];
  const double vs2 = speed_sleep * speed_sleep;
  if (v[0] * v[0] + v[1] * v[1] + v[2] * v[2] >= vs2) return false;
  if ((w[0] * w[0] + w[1] * w[1] + w[2] * w[2]) * r * r >= vs2) return false;
  return f[0] * f[0] + f[1] * f[1] + f[2] * f[2] < force_sleep * force_sleep;
}

/* ----------------------------------------------------------------------
   a sleeper whose awake contact partners push it with more than `wake` wakes, and so do the
   sleepers touching it (through the pair style's list and contact flags; sleepers owned by
   another rank get the request by reverse communication)
------------------------------------------------------------------------- */

void FixSleepGran::wake_pushed()
{
  const int nlocal = atom->nlocal, nvisit = nvisited();
  const int nall = nlocal + atom->nghost;
  const double fw2 = force_wake * force_wake;
  int woken = 0;
  // also read by post_force(); the buried atoms' are not read
  for (int i = 0; i < nvisit; i++) wake_mark[i] = pushed[i] = 0.0;
  for (int i = nlocal; i < nall; i++) wake_mark[i] = pushed[i] = 0.0;
  for (int i = 0; i < nvisit; i++) {
    if (asleep[i] == 0.0) continue;
    const double *p = push[i];
    if (p[0] * p[0] + p[1] * p[1] + p[2] * p[2] > fw2) {
      wake_mark[i] = pushed[i] = 1.0;
      woken++;
    }
  }
  int any = 0;
  MPI_Allreduce(&woken, &any, 1, MPI_INT, MPI_MAX, world);
  if (!any) return;

  // the ghosts learn which sleepers were pushed; the sleepers touching them, local or ghost,
  // are marked, and ghost marks go to their owners
  comm_mode = COMM_PUSHED;
  comm->forward_comm(this);
  mark_touching_sleepers();
  comm_mode = COMM_WAKE;
  comm->reverse_comm(this, 1);

  int nwoken = 0;
  for (int i = 0; i < nvisit; i++) {
    if (wake_mark[i] == 0.0) continue;
    asleep[i] = 0.0;
    rest_steps[i] = 0.0;
    nwoken++;
  }
  bigint nw = nwoken, all = 0;
  MPI_Allreduce(&nw, &all, 1, MPI_LMP_BIGINT, MPI_SUM, world);
  woken_total += all;
  exchange_flags();
  set_generation++;
}

/* ----------------------------------------------------------------------
   wake_mark[j] = 1 for every sleeper j touching a pushed sleeper (local and ghost atoms of the
   pair style's list)
------------------------------------------------------------------------- */

void FixSleepGran::mark_touching_sleepers()
{
  NeighList *list = force->pair->list;
  if (!list) return;
  for (int ii = 0; ii < list->inum; ii++) {
    const int i = list->ilist[ii];
    const int *jlist = list->firstneigh[i];
    const int *touch = pair_history ? pair_history->firstflag[i] : nullptr;
    for (int jj = 0; jj < list->numneigh[i]; jj++) {
      const int j = jlist[jj] & NEIGHMASK;
      const bool i_pushes_j = pushed[i] != 0.0 && asleep[j] != 0.0 && pushed[j] == 0.0;
      const bool j_pushes_i = pushed[j] != 0.0 && asleep[i] != 0.0 && pushed[i] == 0.0;
      if (!(i_pushes_j || j_pushes_i) || !touching(i, j, jj, touch)) continue;
      if (j_pushes_i) wake_mark[i] = 1.0;
      if (i_pushes_j) wake_mark[j] = 1.0;
    }
  }
}

/* ----------------------------------------------------------------------
   commit to sleep the atoms at rest for the rest time, and (keyword depth) those slower than
   10 x speed lying at least `depth` below the top of the bed in their column; either way only
   atoms that touch another or a granular wall (a contact counted this step)
------------------------------------------------------------------------- */

void FixSleepGran::fall_asleep()
{
  const int nlocal = atom->nlocal;
  int *mask = atom->mask;
  double **x = atom->x;

  std::vector<double> top;
  int nbx = 0, nby = 0;
  if (depth > 0.0) surface_heights(top, nbx, nby);

  double **v = atom->v;
  const double vdeep2 = 100.0 * speed_sleep * speed_sleep;
  bigint n = 0;
  for (int i = 0; i < nlocal; i++) {
    if (asleep[i] != 0.0 || !(mask[i] & groupbit)) continue;
    bool sleep = rest_rule && rest_steps[i] >= rest_steps_needed && rest_steps[i] >= 1.0;
    if (!sleep && depth > 0.0 && ncontact[i] > 0.0 &&
        v[i][0] * v[i][0] + v[i][1] * v[i][1] + v[i][2] * v[i][2] < vdeep2) {
      sleep = top[column_of(x[i], nbx, nby)] - x[i][2] >= depth;
    }
    if (!sleep) continue;
    asleep[i] = 1.0;
    n++;
  }
  bigint all = 0;
  MPI_Allreduce(&n, &all, 1, MPI_LMP_BIGINT, MPI_SUM, world);
  fallen_asleep_total += all;
}

/* ----------------------------------------------------------------------
   index of the column (of nbx x nby over the box in x, y) holding position x
------------------------------------------------------------------------- */

int FixSleepGran::column_of(const double *x, int nbx, int nby) const
{
  int bx = static_cast<int>((x[0] - domain->boxlo[0]) / domain->xprd * nbx);
  int by = static_cast<int>((x[1] - domain->boxlo[1]) / domain->yprd * nby);
  bx = MIN(MAX(bx, 0), nbx - 1);
  by = MIN(MAX(by, 0), nby - 1);
  return by * nbx + bx;
}

/* ----------------------------------------------------------------------
   highest top (z + radius) of the bed per column of x, y: the bed's atoms up to the first gap
   of more than two empty particle layers (sleep_bed_reach.h: a cluster hovering above the bed
   is not its top)
------------------------------------------------------------------------- */

void FixSleepGran::surface_heights(std::vector<double> &top, int &nbx, int &nby) const
{
  // columns one particle wide (the largest diameter): wider ones would put the particles of a
  // valley of the rough surface below a neighbouring peak
  double rmax = 0.0, rmax_all = 0.0;
  for (int i = 0; i < atom->nlocal; i++) rmax = MAX(rmax, atom->radius[i]);
  MPI_Allreduce(&rmax, &rmax_all, 1, MPI_DOUBLE, MPI_MAX, world);
  const double side = rmax_all > 0.0 ? 2.0 * rmax_all : depth;
  nbx = MAX(1, static_cast<int>(domain->xprd / side));
  nby = MAX(1, static_cast<int>(domain->yprd / side));
  const size_t ncol = static_cast<size_t>(nbx) * nby;
  top.assign(ncol, -1.0e300);

  // the bed: sleepers and the atoms in contact slower than 10 x speed (not those falling
  // onto it, nor slow ones hovering alone above a charged bed)
  double **x = atom->x, **v = atom->v;
  const double vbed2 = 100.0 * speed_sleep * speed_sleep;
  auto in_bed = [&](int i) {
    return asleep[i] != 0.0 ||
        (ncontact[i] != 0.0 && v[i][0] * v[i][0] + v[i][1] * v[i][1] + v[i][2] * v[i][2] < vbed2);
  };
  double span[2] = {-1.0e300, -1.0e300}, span_all[2];    // -lowest, highest z of the bed
  for (int i = 0; i < atom->nlocal; i++)
    if (in_bed(i)) {
      span[0] = MAX(span[0], -x[i][2]);
      span[1] = MAX(span[1], x[i][2]);
    }
  MPI_Allreduce(span, span_all, 2, MPI_DOUBLE, MPI_MAX, world);
  if (span_all[1] < -1.0e299) return;    // no bed yet
  const double zlo = -span_all[0];
  const int nbz = static_cast<int>((span_all[1] - zlo) / side) + 1;
  auto layer_of = [&](double z) { return MIN(MAX(static_cast<int>((z - zlo) / side), 0), nbz - 1); };

  std::vector<unsigned char> mine(ncol * nbz, 0), occupied(ncol * nbz, 0);
  for (int i = 0; i < atom->nlocal; i++)
    if (in_bed(i)) mine[column_of(x[i], nbx, nby) * static_cast<size_t>(nbz) + layer_of(x[i][2])] = 1;
  MPI_Allreduce(mine.data(), occupied.data(), static_cast<int>(mine.size()), MPI_UNSIGNED_CHAR,
                MPI_MAX, world);
  const std::vector<int> reach = GranularCharged::bed_reach(
      occupied, nbx, nby, nbz, domain->xperiodic != 0, domain->yperiodic != 0, 2);

  std::vector<double> mytop(ncol, -1.0e300);
  for (int i = 0; i < atom->nlocal; i++) {
    if (!in_bed(i)) continue;
    const int c = column_of(x[i], nbx, nby);
    if (layer_of(x[i][2]) < reach[c]) mytop[c] = MAX(mytop[c], x[i][2] + atom->radius[i]);
  }
  MPI_Allreduce(mytop.data(), top.data(), static_cast<int>(ncol), MPI_DOUBLE, MPI_MAX, world);
}

/* ----------------------------------------------------------------------
   a sleeper stays where it is: the integrator sees zero velocity, spin, force and torque; so
   does, with woken_too, an atom woken on this step (wake_mark, set by wake_pushed())
------------------------------------------------------------------------- */

void FixSleepGran::hold_sleepers(bool woken_too)
{
  double **v = atom->v, **w = atom->omega, **f = atom->f, **t = atom->torque;
  const int nvisit = nvisited();
  for (int i = 0; i < nvisit; i++) {
    if (asleep[i] == 0.0 && !(woken_too && wake_mark[i] != 0.0)) continue;
    v[i][0] = v[i][1] = v[i][2] = 0.0;
    w[i][0] = w[i][1] = w[i][2] = 0.0;
    f[i][0] = f[i][1] = f[i][2] = 0.0;
    t[i][0] = t[i][1] = t[i][2] = 0.0;
  }
}

/* ----------------------------------------------------------------------
   the sleepers of all ranks, counted where they are asked for (compute_scalar, compute_vector:
   called on every rank), so that the count is right whenever the flags changed: after
   read_restart (the flags come with the atoms, before any run), delete_atoms, a wake
------------------------------------------------------------------------- */

bigint FixSleepGran::sleeping_count() const
{
  bigint n = 0, all = 0;
  for (int i = 0; i < atom->nlocal; i++)
    if (asleep[i] != 0.0) n++;
  MPI_Allreduce(&n, &all, 1, MPI_LMP_BIGINT, MPI_SUM, world);
  return all;
}

bigint FixSleepGran::awake_count() const
{
  return atom->natoms - sleeping_count();
}

/* ----------------------------------------------------------------------
   the scalar: the awake count (the atoms still integrated), as vector element 1
------------------------------------------------------------------------- */

double FixSleepGran::compute_scalar()
{
  return static_cast<double>(awake_count());
}

/* ----------------------------------------------------------------------
   1 awake atoms, 2 sleeping atoms, 3 atoms fallen asleep, 4 atoms woken (3, 4 since the fix
   was defined, kept across restarts)
------------------------------------------------------------------------- */

double FixSleepGran::compute_vector(int n)
{
  switch (n) {
    case V_AWAKE:
      return static_cast<double>(awake_count());
    case V_SLEEPING:
      return static_cast<double>(sleeping_count());
    case V_FALLEN_ASLEEP:
      return static_cast<double>(fallen_asleep_total);
    default:
      return static_cast<double>(woken_total);
  }
}

/* ---------------------------------------------------------------------- */

void *FixSleepGran::extract(const char *name, int &dim)
{
  if (strcmp(name, "sleeping") == 0) {
    dim = 1;
    return asleep;
  }
  if (strcmp(name, "generation") == 0) {
    dim = 0;
    return &set_generation;
  }
  if (strcmp(name, "push") == 0) {
    dim = 2;
    return push;
  }
  if (strcmp(name, "contacts") == 0) {
    dim = 1;
    return ncontact;
  }
  if (strcmp(name, "pairs_awake") == 0) {
    dim = 0;
    return &pairs_awake;
  }
  return nullptr;
}

/* ---------------------------------------------------------------------- */

double FixSleepGran::memory_usage()
{
  return static_cast<double>(atom->nmax) * 8 * sizeof(double);
}

/* ---------------------------------------------------------------------- */

void FixSleepGran::grow_arrays(int nmax)
{
  memory->grow(asleep, nmax, "sleep/gran:asleep");
  memory->grow(pushed, nmax, "sleep/gran:pushed");
  memory->grow(rest_steps, nmax, "sleep/gran:rest_steps");
  memory->grow(push, nmax, 3, "sleep/gran:push");
  memory->grow(wake_mark, nmax, "sleep/gran:wake_mark");
  memory->grow(ncontact, nmax, "sleep/gran:ncontact");
  vector_atom = asleep;
}

void FixSleepGran::copy_arrays(int i, int j, int /*delflag*/)
{
  asleep[j] = asleep[i];
  rest_steps[j] = rest_steps[i];
}

void FixSleepGran::set_arrays(int i)
{
  asleep[i] = rest_steps[i] = 0.0;
}

int FixSleepGran::pack_exchange(int i, double *buf)
{
  buf[0] = asleep[i];
  buf[1] = rest_steps[i];
  return 2;
}

int FixSleepGran::unpack_exchange(int nlocal, double *buf)
{
  asleep[nlocal] = buf[0];
  rest_steps[nlocal] = buf[1];
  return 2;
}

/* ---------------------------------------------------------------------- */

int FixSleepGran::pack_forward_comm(int n, int *list, double *buf, int /*pbc_flag*/, int * /*pbc*/)
{
  const double *flags = comm_mode == COMM_PUSHED ? pushed : asleep;
  for (int k = 0; k < n; k++) buf[k] = flags[list[k]];
  return n;
}

void FixSleepGran::unpack_forward_comm(int n, int first, double *buf)
{
  double *flags = comm_mode == COMM_PUSHED ? pushed : asleep;
  for (int k = 0; k < n; k++) flags[first + k] = buf[k];
}

int FixSleepGran::pack_reverse_comm(int n, int first, double *buf)
{
  int m = 0;
  for (int i = first; i < first + n; i++) {
    if (comm_mode == COMM_PUSH) {
      buf[m++] = push[i][0];
      buf[m++] = push[i][1];
      buf[m++] = push[i][2];
      buf[m++] = ncontact[i];
    } else {
      buf[m++] = wake_mark[i];
    }
  }
  return m;
}

void FixSleepGran::unpack_reverse_comm(int n, int *list, double *buf)
{
  int m = 0;
  for (int k = 0; k < n; k++) {
    const int j = list[k];
    if (comm_mode == COMM_PUSH) {
      push[j][0] += buf[m++];
      push[j][1] += buf[m++];
      push[j][2] += buf[m++];
      ncontact[j] += buf[m++];
    } else {
      const double mark = buf[m++];    // read once: MAX() would evaluate it twice
      if (mark > wake_mark[j]) wake_mark[j] = mark;
    }
  }
}

/* ---------------------------------------------------------------------- */

void FixSleepGran::write_restart(FILE *fp)
{
  if (comm->me != 0) return;
  double list[R_NSLOTS];
  list[R_FALLEN_ASLEEP] = static_cast<double>(fallen_asleep_total);
  list[R_WOKEN] = static_cast<double>(woken_total);
  int size = R_NSLOTS * sizeof(double);
  fwrite(&size, sizeof(int), 1, fp);
  fwrite(list, sizeof(double), R_NSLOTS, fp);
}

void FixSleepGran::restart(char *buf)
{
  auto *list = reinterpret_cast<double *>(buf);
  fallen_asleep_total = static_cast<bigint>(list[R_FALLEN_ASLEEP]);
  woken_total = static_cast<bigint>(list[R_WOKEN]);
}

int FixSleepGran::pack_restart(int i, double *buf)
{
  buf[0] = 3;    // values of this fix, the count included
  buf[1] = asleep[i];
  buf[2] = rest_steps[i];
  return 3;
}

void FixSleepGran::unpack_restart(int nlocal, int nth)
{
  double **extra = atom->extra;
  int m = 0;
  for (int k = 0; k < nth; k++) m += static_cast<int>(extra[nlocal][m]);
  m++;
  asleep[nlocal] = extra[nlocal][m++];
  rest_steps[nlocal] = extra[nlocal][m++];
}

int FixSleepGran::size_restart(int /*nlocal*/)
{
  return 3;
}

int FixSleepGran::maxsize_restart()
{
  return 3;
}
