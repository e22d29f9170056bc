/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "fix_bury_gran.h"

#include "bury_cells.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "fix_neigh_history.h"
#include "force.h"
#include "group.h"
#include "modify.h"
#include "my_page.h"
#include "neigh_history_arrays.h"
#include "neighbor.h"
#include "update.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <type_traits>
#include <unordered_set>
#include <utility>

using namespace LAMMPS_NS;
using namespace FixConst;

namespace {
// the elements of the global vector (compute_vector's index)
enum VectorElement { V_ACTIVE, V_BURIED, V_RECOMPUTES, V_FORCED, V_NELEMENTS };

// LAMMPS keeps the group of comm_modify group protected in Comm with no accessor: read it
// through a pointer to the member formed in a derived class
struct CommBorderGroup : public Comm {
  static int of(const Comm *c) { return c->*(&CommBorderGroup::bordergroup); }
};

}    // namespace

/* ---------------------------------------------------------------------- */

FixBuryGran::FixBuryGran(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), id_sleep(nullptr), active_group(-1), active_bit(0), halo(-1.0),
    sleep_fix(nullptr), history(nullptr), dnum(0), seen_generation(-1), restart_dnum(-1),
    nactive(0), nburied(0), nrecompute(0), nforced(0)
{
  if (!atom->radius_flag) error->all(FLERR, "Fix {} requires atom attribute radius (atom_style sphere)", style);
  if (!atom->tag_enable) error->all(FLERR, "Fix {} requires atom IDs", style);
  if (domain->dimension != 3) error->all(FLERR, "Fix {} requires a 3d simulation", style);

  nevery = 1;
  int iarg = 3;
  while (iarg < narg) {
    if (iarg + 2 > narg) utils::missing_cmd_args(FLERR, std::string("fix bury/gran ") + arg[iarg], error);
    if (strcmp(arg[iarg], "sleep") == 0) {
      delete[] id_sleep;
      id_sleep = utils::strdup(arg[iarg + 1]);
    } else if (strcmp(arg[iarg], "active") == 0) {
      active_group = group->find(arg[iarg + 1]);
      if (active_group < 0)
        error->all(FLERR, "Fix {} active: no group {} (define it first, e.g. group {} empty)", style,
                   arg[iarg + 1], arg[iarg + 1]);
      if (active_group == 0) error->all(FLERR, "Fix {} active: the group cannot be all", style);
      if (active_group == igroup)
        error->all(FLERR, "Fix {} active: group {} is the fix group; it must be a group of its own",
                   style, arg[iarg + 1]);
    } else if (strcmp(arg[iarg], "halo") == 0) {
      halo = utils::numeric(FLERR, arg[iarg + 1], false, lmp);
      if (!(halo > 0.0) || !std::isfinite(halo))
        error->all(FLERR, "Fix {} halo must be > 0 (distance units), got {}", style, arg[iarg + 1]);
    } else if (strcmp(arg[iarg], "every") == 0) {
      nevery = utils::inumeric(FLERR, arg[iarg + 1], false, lmp);
      if (nevery < 1) error->all(FLERR, "Fix {} every must be >= 1, got {}", style, arg[iarg + 1]);
    } else {
      error->all(FLERR, "Unknown fix {} keyword {}", style, arg[iarg]);
    }
    iarg += 2;
  }
  if (!id_sleep || active_group < 0 || halo < 0.0)
    error->all(FLERR, "Fix {} needs the keywords sleep, active and halo", style);
  active_bit = group->bitmask[active_group];

  vector_flag = 1;
  size_vector = V_NELEMENTS;
  global_freq = 1;
  extvector = 0;
  create_attribute = 1;    // created atoms have no kept histories (set_arrays)
  restart_peratom = 1;
  force_reneighbor = 1;    // next_reneighbor is set when the group changed between builds
  next_reneighbor = -1;
  maxexchange_dynamic = 1;
  maxexchange = 1;

  FixBuryGran::grow_arrays(atom->nmax);
  atom->add_callback(Atom::GROW);
  atom->add_callback(Atom::RESTART);
}

/* ---------------------------------------------------------------------- */

FixBuryGran::~FixBuryGran()
{
  if (copymode) return;
  atom->delete_callback(id, Atom::GROW);
  atom->delete_callback(id, Atom::RESTART);
  delete[] id_sleep;
}

/* ---------------------------------------------------------------------- */

int FixBuryGran::setmask()
{
  return PRE_EXCHANGE | PRE_NEIGHBOR | END_OF_STEP;
}

/* ---------------------------------------------------------------------- */

void FixBuryGran::init()
{
  const std::string gname = group->names[active_group];
  if (group->find(gname) != active_group)
    error->all(FLERR, "Fix {} active: group {} no longer exists", style, gname);
  if (!atom->firstgroupname || gname != atom->firstgroupname)
    error->all(FLERR, "Fix {} active {} requires the command: atom_modify first {}", style, gname, gname);
  if (neighbor->includegroup != active_group)
    error->all(FLERR, "Fix {} active {} requires the command: neigh_modify include {}", style, gname, gname);
  if (CommBorderGroup::of(comm) != active_group)
    error->all(FLERR, "Fix {} active {} requires the command: comm_modify group {}", style, gname, gname);
  if (update->whichflag == 2) error->all(FLERR, "Fix {} cannot be used with minimization", style);

  sleep_fix = modify->get_fix_by_id(id_sleep);
  if (!sleep_fix) error->all(FLERR, "Fix {} sleep: no fix with ID {}", style, id_sleep);
  if (strcmp(sleep_fix->style, "sleep/gran") != 0)
    error->all(FLERR, "Fix {} sleep: fix {} is {}, not sleep/gran", style, id_sleep, sleep_fix->style);
  int dim = -1;
  if (!sleep_fix->extract("sleeping", dim) || dim != 1 || !sleep_fix->extract("generation", dim) || dim != 0)
    error->all(FLERR, "Fix {} sleep: fix {} gives no sleeping flags", style, id_sleep);

  // the pair's contact histories; fix NEIGH_HISTORY must come first (its pre_exchange fills
  // the partner arrays read in pre_neighbor)
  auto histories = modify->get_fix_by_style("^NEIGH_HISTORY");
  if (histories.size() > 1)
    error->all(FLERR, "Fix {} needs a single granular pair style with one contact history", style);
  history = histories.empty() ? nullptr : dynamic_cast<FixNeighHistory *>(histories.front());
  dnum = history ? neigh_history_arrays(history).dnum : 0;
  if (restart_dnum >= 0 && history && restart_dnum != dnum)
    error->all(FLERR, "Fix {}: the kept contact histories of the restart have {} values per contact, "
               "the pair style's {}", style, restart_dnum, dnum);

  int isleep = -1, ihistory = -1, ime = -1;
  const auto &fixes = modify->get_fix_list();
  for (int i = 0; i < (int) fixes.size(); i++) {
    if (fixes[i] == sleep_fix) isleep = i;
    if (fixes[i] == history) ihistory = i;
    if (fixes[i] == this) ime = i;
  }
  if (isleep > ime)
    error->all(FLERR, "Fix {} must be defined after fix {} ({})", style, id_sleep, sleep_fix->style);
  if (history && ihistory > ime)
    error->all(FLERR, "Fix {} must come after the pair style's fix {} (define the pair style first)",
               style, history->id);
  // a buried atom stays where it is because nothing integrates it: LAMMPS clears forces only
  // up to atom->nfirst, and fix sleep/gran holds only the atoms before it
  for (auto *f : fixes)
    if (f->time_integrate && f->igroup != active_group)
      error->all(FLERR,
                 "Fix {} active {}: fix {} ({}) integrates group {}; with buried atoms every "
                 "integrator must have group {}",
                 style, gname, f->id, f->style, group->names[f->igroup], gname);
  // atoms inserted in pre_exchange must be there when the rule is applied, before the exchange
  for (int i = ime + 1; i < (int) fixes.size(); i++)
    if (utils::strmatch(fixes[i]->style, "^deposit") || utils::strmatch(fixes[i]->style, "^pour"))
      error->all(FLERR, "Fix {} must be defined after fix {} ({}), which inserts atoms", style,
                 fixes[i]->id, fixes[i]->style);
}

/* ---------------------------------------------------------------------- */

void *FixBuryGran::extract(const char *name, int &dim)
{
  if (strcmp(name, "sleep") == 0) {
    dim = 0;
    return id_sleep;
  }
  return nullptr;
}

/* ----------------------------------------------------------------------
   before the run's first exchange: the group, checked against the neighbor cutoff (known only
   after Neighbor::init(), which comes after the fixes' init())
------------------------------------------------------------------------- */

void FixBuryGran::setup_pre_exchange()
{
  double rmax = 0.0, rmax_all = 0.0;
  for (int i = 0; i < atom->nlocal; i++) rmax = MAX(rmax, atom->radius[i]);
  MPI_Allreduce(&rmax, &rmax_all, 1, MPI_DOUBLE, MPI_MAX, world);
  // The neighbors (within cutneighmax) of every atom whose force is integrated must be listed.
  // An awake atom's lie within cutneighmax of it. On the step of a wake, the woken atoms'
  // forces were computed with the list of the last build: a pushed sleeper touches an awake
  // atom, a sleeper woken with it touches the pushed one (each contact within 2 rmax), and its
  // neighbors lie within cutneighmax of it; the awake atom has moved up to skin / 2 since the
  // build.
  const double needed = neighbor->cutneighmax + 4.0 * rmax_all + neighbor->skin;
  if (halo < needed)
    error->all(FLERR,
               "Fix {} halo {} is below the neighbor cutoff {} plus twice the largest diameter "
               "{} plus the skin {}: use halo >= {}",
               style, halo, neighbor->cutneighmax, 2.0 * rmax_all, neighbor->skin, needed);
  apply_rule();
  int dim = 0;
  seen_generation = *static_cast<bigint *>(sleep_fix->extract("generation", dim));
  next_reneighbor = -1;
  update_maxexchange();
}

/* ----------------------------------------------------------------------
   each build: the group from the current positions (the awake atoms moved since the last one),
   applied before the exchange orders the atoms and the borders send the ghosts
------------------------------------------------------------------------- */

void FixBuryGran::pre_exchange()
{
  apply_rule();
  int dim = 0;
  seen_generation = *static_cast<bigint *>(sleep_fix->extract("generation", dim));
  update_maxexchange();
}

/* ---------------------------------------------------------------------- */

void FixBuryGran::setup_pre_neighbor()
{
  keep_and_restore_histories();
}

void FixBuryGran::pre_neighbor()
{
  keep_and_restore_histories();
}

/* ----------------------------------------------------------------------
   the sleeping set changed (fix sleep/gran commits and wakes in post_force): the group again,
   and a build at the next step if it changed on any rank
------------------------------------------------------------------------- */

void FixBuryGran::end_of_step()
{
  int dim = 0;
  const bigint generation = *static_cast<bigint *>(sleep_fix->extract("generation", dim));
  if (generation == seen_generation) return;
  seen_generation = generation;
  if (apply_rule()) {
    next_reneighbor = update->ntimestep + 1;
    nforced++;
  }
}

/* ----------------------------------------------------------------------
   the group: the awake atoms, the atoms outside the fix group, and the sleepers with an awake
   atom within halo (in x, y and z, on a grid of cells one largest diameter wide in x and y and
   a quarter of that in z). Returns whether it changed on any rank.
------------------------------------------------------------------------- */

bool FixBuryGran::apply_rule()
{
  using GranularCharged::column_index;
  const int nlocal = atom->nlocal;
  double **x = atom->x;
  int *mask = atom->mask;
  int dim = 0;
  const double *asleep = static_cast<double *>(sleep_fix->extract("sleeping", dim));
  auto is_sleeper = [&](int i) { return (mask[i] & groupbit) && asleep[i] != 0.0; };

  // the largest radius, and the lowest and highest sleeper of the fix group, over all ranks
  double mine_max[3] = {0.0, -INFINITY, -INFINITY}, all_max[3];    // rmax, -zlo, zhi
  for (int i = 0; i < nlocal; i++) {
    mine_max[0] = MAX(mine_max[0], atom->radius[i]);
    if (!is_sleeper(i)) continue;
    mine_max[1] = MAX(mine_max[1], -x[i][2]);
    mine_max[2] = MAX(mine_max[2], x[i][2]);
  }
  MPI_Allreduce(mine_max, all_max, 3, MPI_DOUBLE, MPI_MAX, world);
  const double rmax_all = all_max[0];
  const bool any_sleeper = all_max[2] > -INFINITY;

  // cells one largest diameter wide in x and y (the columns of fix sleep/gran's depth rule),
  // cut into slabs of a quarter of that in z: the rule keeps sleepers up to the cells' sizes
  // beyond halo, less in z, where the bed is deep
  const double side = rmax_all > 0.0 ? 2.0 * rmax_all : halo;
  const double *prd = domain->prd, *lo = domain->boxlo;
  const int periodic[3] = {domain->xperiodic, domain->yperiodic, domain->zperiodic};
  int n[3], k[3];
  double w[3];
  for (int d = 0; d < 3; d++) {
    n[d] = MAX(1, static_cast<int>(prd[d] / (d == 2 ? 0.25 * side : side)));
    w[d] = prd[d] / n[d];
    k[d] = MAX(1, static_cast<int>(std::ceil(halo / w[d])));
  }
  // only the slabs within k[2] of a sleeper's slab decide anything (non-periodic z): an awake
  // atom farther in z is farther than the window from every sleeper; the grid is cut to them
  int z0 = 0, nz = n[2];
  if (any_sleeper && !periodic[2]) {
    z0 = MAX(0, column_index(-all_max[1], lo[2], w[2], n[2], false) - k[2]);
    nz = MIN(n[2] - 1, column_index(all_max[2], lo[2], w[2], n[2], false) + k[2]) - z0 + 1;
  }
  const int grid[3] = {n[0], n[1], nz};
  // the cell of x, or -1 for a slab outside the grid
  auto cell_of = [&](const double *xi) -> long {
    const int cz = column_index(xi[2], lo[2], w[2], n[2], periodic[2]) - z0;
    if (cz < 0 || cz >= nz) return -1;
    const int cy = column_index(xi[1], lo[1], w[1], n[1], periodic[1]);
    const int cx = column_index(xi[0], lo[0], w[0], n[0], periodic[0]);
    return (static_cast<long>(cz) * n[1] + cy) * n[0] + cx;
  };

  // the cells holding an awake atom, over all ranks, widened by halo in x, y and z (at least
  // the 26 neighbours): a sleeper within halo of an awake atom, in each coordinate, is in one
  // of them. Without sleepers nothing is buried and no grid is needed.
  std::vector<unsigned char> near;
  if (any_sleeper) {
    std::vector<unsigned char> mine(static_cast<size_t>(n[0]) * n[1] * nz, 0);
    near.assign(mine.size(), 0);
    for (int i = 0; i < nlocal; i++) {
      if (asleep[i] != 0.0) continue;
      const long c = cell_of(x[i]);
      if (c >= 0) mine[c] = 1;
    }
    MPI_Allreduce(mine.data(), near.data(), (int) mine.size(), MPI_UNSIGNED_CHAR, MPI_MAX, world);
    for (int d = 0; d < 3; d++) GranularCharged::window_any(near, grid, d, k[d], periodic[d]);
  }

  bigint counts[3] = {0, 0, 0}, all[3] = {0, 0, 0};    // changed, active, buried
  for (int i = 0; i < nlocal; i++) {
    const bool keep = !is_sleeper(i) || near[cell_of(x[i])] != 0;
    const bool in = mask[i] & active_bit;
    if (keep != in) {
      counts[0]++;
      if (keep) mask[i] |= active_bit;
      else mask[i] &= ~active_bit;
    }
    counts[keep ? 1 : 2]++;
  }
  MPI_Allreduce(counts, all, 3, MPI_LMP_BIGINT, MPI_SUM, world);
  nactive = all[1];
  nburied = all[2];
  nrecompute++;
  return all[0] > 0;
}

/* ----------------------------------------------------------------------
   after the borders of a build, before the pair's fix NEIGH_HISTORY copies the partner arrays
   into the new list (its post_neighbor): a contact with an atom outside the group is not in the
   new list and its history would be dropped, so it is kept per atom here (each atom keeps its
   own side, as fix NEIGH_HISTORY stores it); a kept contact whose two atoms are both in the
   group again goes back into fix NEIGH_HISTORY's partner arrays
------------------------------------------------------------------------- */

void FixBuryGran::keep_and_restore_histories()
{
  if (!history) return;
  NeighHistoryArrays h = neigh_history_arrays(history);
  const int nlocal = atom->nlocal;
  const int nall = nlocal + atom->nghost;
  int *mask = atom->mask;
  tagint *tag = atom->tag;

  // the group's atoms here (local ones in it, and ghosts: comm_modify group sends only those)
  std::unordered_set<tagint> in_set;
  const bool use_map = atom->map_style != Atom::MAP_NONE;
  if (!use_map) {
    in_set.reserve(nall);
    for (int i = 0; i < nall; i++)
      if (mask[i] & active_bit) in_set.insert(tag[i]);
  }
  auto in_group = [&](tagint t) {
    if (!use_map) return in_set.count(t) > 0;
    const int m = atom->map(t);
    return m >= 0 && (mask[m] & active_bit);
  };

  const int width = 1 + dnum;
  std::vector<double> back;
  for (int k = 0; k < nlocal; k++) {
    const bool k_in = mask[k] & active_bit;
    // keep the contacts that leave the list
    for (int m = 0; m < h.npartner[k]; m++) {
      const tagint p = h.partner[k][m];
      if (k_in && in_group(p)) continue;
      std::vector<double> &kk = kept[k];
      kk.push_back(static_cast<double>(p));
      kk.insert(kk.end(), &h.valuepartner[k][dnum * m], &h.valuepartner[k][dnum * (m + 1)]);
    }
    if (!k_in || kept[k].empty()) continue;

    // give back the kept contacts whose partner is in the group again
    std::vector<double> &kk = kept[k];
    back.clear();
    size_t w = 0;
    for (size_t e = 0; e < kk.size(); e += width) {
      const auto p = static_cast<tagint>(kk[e]);
      bool listed = false;
      for (int m = 0; !listed && m < h.npartner[k]; m++) listed = h.partner[k][m] == p;
      if (in_group(p)) {
        if (!listed) back.insert(back.end(), kk.begin() + e, kk.begin() + e + width);
      } else {
        std::copy(kk.begin() + e, kk.begin() + e + width, kk.begin() + w);
        w += width;
      }
    }
    kk.resize(w);
    if (back.empty()) continue;
    const int n0 = h.npartner[k];
    const int n = n0 + static_cast<int>(back.size()) / width;
    tagint *ip = h.ipage->get(n);
    double *dp = h.dpage->get(dnum * n);
    if (!ip || !dp)
      error->one(FLERR, "Fix {}: neighbor history overflow giving back kept contacts, boost "
                 "neigh_modify one", style);
    std::copy(h.partner[k], h.partner[k] + n0, ip);
    std::copy(h.valuepartner[k], h.valuepartner[k] + dnum * n0, dp);
    for (int m = n0; m < n; m++) {
      const double *entry = &back[static_cast<size_t>(m - n0) * width];
      ip[m] = static_cast<tagint>(entry[0]);
      std::copy(entry + 1, entry + width, dp + dnum * m);
    }
    h.partner[k] = ip;
    h.valuepartner[k] = dp;
    h.npartner[k] = n;
  }
  update_maxexchange();
}

/* ---------------------------------------------------------------------- */

void FixBuryGran::update_maxexchange()
{
  size_t most = 0;
  for (int i = 0; i < atom->nlocal; i++) most = std::max(most, kept[i].size());
  maxexchange = 1 + static_cast<int>(most);
}

/* ----------------------------------------------------------------------
   1 atoms in the active group, 2 buried atoms (as of the last application of the rule),
   3 applications of the rule, 4 builds forced (since the fix was defined)
------------------------------------------------------------------------- */

double FixBuryGran::compute_vector(int n)
{
  switch (n) {
    case V_ACTIVE:
      return static_cast<double>(nactive);
    case V_BURIED:
      return static_cast<double>(nburied);
    case V_RECOMPUTES:
      return static_cast<double>(nrecompute);
    default:
      return static_cast<double>(nforced);
  }
}

/* ---------------------------------------------------------------------- */

double FixBuryGran::memory_usage()
{
  double bytes = static_cast<double>(kept.size()) * sizeof(std::vector<double>);
  for (const auto &k : kept) bytes += static_cast<double>(k.capacity()) * sizeof(double);
  return bytes;
}

/* ---------------------------------------------------------------------- */

void FixBuryGran::grow_arrays(int nmax)
{
  if ((int) kept.size() < nmax) kept.resize(nmax);
}

void FixBuryGran::copy_arrays(int i, int j, int /*delflag*/)
{
  if (i != j) kept[j] = kept[i];
}

void FixBuryGran::set_arrays(int i)
{
  kept[i].clear();
}

int FixBuryGran::pack_exchange(int i, double *buf)
{
  buf[0] = static_cast<double>(kept[i].size());
  std::copy(kept[i].begin(), kept[i].end(), buf + 1);
  return 1 + static_cast<int>(kept[i].size());
}

int FixBuryGran::unpack_exchange(int nlocal, double *buf)
{
  const int n = static_cast<int>(buf[0]);
  kept[nlocal].assign(buf + 1, buf + 1 + n);
  return 1 + n;
}

/* ----------------------------------------------------------------------
   restart: per atom the count of values (this one included), the values per contact, the kept
   contacts
------------------------------------------------------------------------- */

int FixBuryGran::pack_restart(int i, double *buf)
{
  const int n = static_cast<int>(kept[i].size());
  buf[0] = 2 + n;
  buf[1] = dnum;
  std::copy(kept[i].begin(), kept[i].end(), buf + 2);
  return 2 + n;
}

void FixBuryGran::unpack_restart(int nlocal, int nth)
{
  double **extra = atom->extra;
  int m = 0;
  for (int k = 0; k < nth; k++) m += static_cast<int>(extra[nlocal][m]);
  const int n = static_cast<int>(extra[nlocal][m]) - 2;
  const int d = static_cast<int>(extra[nlocal][m + 1]);
  kept[nlocal].assign(&extra[nlocal][m + 2], &extra[nlocal][m + 2] + n);
  if (n > 0) {
    if (restart_dnum >= 0 && restart_dnum != d)
      error->one(FLERR, "Fix {}: kept contact histories of different sizes in the restart", style);
    restart_dnum = d;
  }
}

int FixBuryGran::size_restart(int nlocal)
{
  return 2 + static_cast<int>(kept[nlocal].size());
}

int FixBuryGran::maxsize_restart()
{
  size_t most = 0;
  for (int i = 0; i < atom->nlocal; i++) most = std::max(most, kept[i].size());
  return 2 + static_cast<int>(most);
}
