/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

/* ----------------------------------------------------------------------
   compute coord/dist: coordination number of granular contacts.
   Z_i = number of contacts of atom i (partners of any group, any height,
   across periodic boundaries); f(Z) and <Z> over the atoms of the group
   whose centres lie in [zlo, zhi]. Contacts are either geometric
   (r_ij <= r_i + r_j + tolerance, as compute contact/atom with a tolerance)
   or "active": the contacts the granular pair style holds at its last force
   evaluation, read from its contact-history flags (a JKR contact in tension
   beyond touching is active but not geometric).
------------------------------------------------------------------------- */

#include "compute_coord_dist.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "fix_neigh_history.h"
#include "force.h"
#include "memory.h"
#include "modify.h"
#include "neigh_list.h"
#include "neighbor.h"
#include "pair.h"
#include "slab_geometry.h"
#include "update.h"

#include <cmath>
#include <cstring>
#include <vector>

using namespace LAMMPS_NS;

/* ---------------------------------------------------------------------- */

ComputeCoordDist::ComputeCoordDist(LAMMPS *lmp, int narg, char **arg) :
    Compute(lmp, narg, arg), coord(nullptr), tally(nullptr), list(nullptr), fix_history(nullptr)
{
  if (!atom->radius_flag)
    error->all(FLERR, "Compute coord/dist requires atom style sphere (per-atom radius)");

  max_coord = 20;
  zlo_null = zhi_null = 1;
  zlo = zhi = 0.0;
  active = 0;
  tolerance = 0.0;
  tolerance_set = 0;

  int iarg = 3;
  while (iarg < narg) {
    if (strcmp(arg[iarg], "z") == 0) {
      if (iarg + 3 > narg) utils::missing_cmd_args(FLERR, "compute coord/dist z", error);
      parse_slab_bounds(lmp, arg, iarg + 1, "Compute coord/dist z:", zlo, zhi, zlo_null, zhi_null);
      iarg += 3;
    } else if (strcmp(arg[iarg], "contact") == 0) {
      if (iarg + 2 > narg) utils::missing_cmd_args(FLERR, "compute coord/dist contact", error);
      if (strcmp(arg[iarg + 1], "geometric") == 0)
        active = 0;
      else if (strcmp(arg[iarg + 1], "active") == 0)
        active = 1;
      else
        error->all(FLERR, iarg + 1,
                   "Compute coord/dist contact must be 'geometric' or 'active', got '{}'",
                   arg[iarg + 1]);
      iarg += 2;
    } else if (strcmp(arg[iarg], "tolerance") == 0) {
      if (iarg + 2 > narg) utils::missing_cmd_args(FLERR, "compute coord/dist tolerance", error);
      tolerance = utils::numeric(FLERR, arg[iarg + 1], false, lmp);
      if (tolerance < 0.0)
        error->all(FLERR, iarg + 1, "Compute coord/dist tolerance must be >= 0, got {}", tolerance);
      tolerance_set = 1;
      iarg += 2;
    } else if (strcmp(arg[iarg], "zmax") == 0) {
      if (iarg + 2 > narg) utils::missing_cmd_args(FLERR, "compute coord/dist zmax", error);
      max_coord = utils::inumeric(FLERR, arg[iarg + 1], false, lmp);
      if (max_coord < 1 || max_coord > 10000)
        error->all(FLERR, iarg + 1, "Compute coord/dist zmax must be in [1, 10000], got {}", max_coord);
      iarg += 2;
    } else
      error->all(FLERR, iarg, "Unknown compute coord/dist keyword: {}", arg[iarg]);
  }
  if (active && tolerance_set)
    error->all(FLERR, "Compute coord/dist tolerance applies to contact geometric only");

  scalar_flag = 1;
  extscalar = 0;
  array_flag = 1;
  size_array_rows = max_coord + 1;
  size_array_cols = 3;
  extarray = 0;
  peratom_flag = 1;
  size_peratom_cols = 0;
  comm_reverse = 1;

  nmax = 0;
  tally_step = -1;
  memory->create(tally, max_coord + 3, "coord/dist:tally");
  memory->create(array, max_coord + 1, 3, "coord/dist:array");
  for (int z = 0; z <= max_coord; z++) array[z][0] = array[z][1] = array[z][2] = 0.0;
  for (int z = 0; z <= max_coord; z++) array[z][0] = z;
}

/* ---------------------------------------------------------------------- */

ComputeCoordDist::~ComputeCoordDist()
{
  memory->destroy(coord);
  memory->destroy(tally);
  memory->destroy(array);
}

/* ---------------------------------------------------------------------- */

void ComputeCoordDist::init()
{
  if (force->pair == nullptr) error->all(FLERR, "Compute coord/dist requires a pair style");
  tally_step = -1;
  fix_history = nullptr;

  if (active) {
    // the granular pair style's contact state: the flags its FixNeighHistory keeps per
    // neighbor pair of the pair style's own list (firstflag[i][jj] pairs with
    // pair->list->firstneigh[i][jj]); without history the pair style's contact test is
    // plain overlap r_ij < r_i + r_j
    if (!force->pair_match("^granular", 0) && !force->pair_match("^gran/", 0))
      error->all(FLERR,
                 "Compute coord/dist contact active requires a granular pair style "
                 "(pair_style granular or gran/*), not {}",
                 force->pair_style);
    auto fixes = modify->get_fix_by_style("^NEIGH_HISTORY");
    std::vector<FixNeighHistory *> hist;
    for (auto &f : fixes) {
      auto fh = dynamic_cast<FixNeighHistory *>(f);
      if (fh && fh->pair) hist.push_back(fh);
    }
    if (hist.size() > 1)
      error->all(FLERR,
                 "Compute coord/dist contact active supports one granular pair style "
                 "with contact history, found {}",
                 hist.size());
    if (hist.size() == 1) fix_history = hist[0];
  }

  // own occasional list of granular size (r_i + r_j + skin), as compute contact/atom
  if (!fix_history) {
    if (tolerance > neighbor->skin)
      error->all(FLERR, "Compute coord/dist tolerance {} exceeds the neighbor skin {}", tolerance,
                 neighbor->skin);
    neighbor->add_request(this, NeighConst::REQ_SIZE | NeighConst::REQ_OCCASIONAL);
  }
}

/* ---------------------------------------------------------------------- */

void ComputeCoordDist::init_list(int /*id*/, NeighList *ptr)
{
  list = ptr;
}

/* ---------------------------------------------------------------------- */

void ComputeCoordDist::compute_peratom()
{
  invoked_peratom = update->ntimestep;

  if (atom->nmax > nmax) {
    memory->destroy(coord);
    nmax = atom->nmax;
    memory->create(coord, nmax, "coord/dist:coord");
    vector_atom = coord;
  }

  double **x = atom->x;
  double *radius = atom->radius;
  int *mask = atom->mask;
  const int nall = atom->nlocal + atom->nghost;
  for (int i = 0; i < nall; i++) coord[i] = 0.0;

  // half lists: each pair once per owner pair (newton on) or once per rank (newton off);
  // count it for both ends, ghost counts go home by reverse communication

  if (fix_history) {
    NeighList *plist = fix_history->pair->list;
    int **firstflag = fix_history->firstflag;
    // a rank without atoms may have no flag pages: test per rank, report from the one that fails
    if (!plist)
      error->all(FLERR, Error::NOLASTLINE,
                 "Compute coord/dist contact active needs a force evaluation first (e.g. run 0)");
    if (plist->inum > 0 && !firstflag)
      error->one(FLERR, Error::NOLASTLINE,
                 "Compute coord/dist contact active needs a force evaluation first (e.g. run 0)");
    const double *special_lj = force->special_lj;
    for (int ii = 0; ii < plist->inum; ii++) {
      const int i = plist->ilist[ii];
      const int *jlist = plist->firstneigh[i];
      const int jnum = plist->numneigh[i];
      const int *touch = firstflag[i];
      for (int jj = 0; jj < jnum; jj++) {
        if (!touch[jj]) continue;
        if (special_lj[sbmask(jlist[jj])] == 0.0) continue;    // the pair style skips these
        const int j = jlist[jj] & NEIGHMASK;
        if (mask[i] & groupbit) coord[i] += 1.0;
        if (mask[j] & groupbit) coord[j] += 1.0;
      }
    }
  } else {
    neighbor->build_one(list);
    // active without history: the pair style's contact is overlap, r_ij < r_i + r_j (strict)
    const double tol = tolerance;
    for (int ii = 0; ii < list->inum; ii++) {
      const int i = list->ilist[ii];
      const double xtmp = x[i][0], ytmp = x[i][1], ztmp = x[i][2], radi = radius[i];
      const int *jlist = list->firstneigh[i];
      const int jnum = list->numneigh[i];
      for (int jj = 0; jj < jnum; jj++) {
        const int j = jlist[jj] & NEIGHMASK;
        if (!(mask[i] & groupbit) && !(mask[j] & groupbit)) continue;
        const double delx = xtmp - x[j][0], dely = ytmp - x[j][1], delz = ztmp - x[j][2];
        const double rsq = delx * delx + dely * dely + delz * delz;
        const double rc = radi + radius[j] + tol;
        const bool contact = active ? (rsq < rc * rc) : (rsq <= rc * rc);
        if (!contact) continue;
        if (mask[i] & groupbit) coord[i] += 1.0;
        if (mask[j] & groupbit) coord[j] += 1.0;
      }
    }
  }

  if (force->newton_pair) comm->reverse_comm(this);
}

/* ----------------------------------------------------------------------
   f(Z), sum of Z and number of atoms of the group with zlo <= z <= zhi,
   one Allreduce for all of them, once per timestep
------------------------------------------------------------------------- */

void ComputeCoordDist::tally_global()
{
  if (tally_step == update->ntimestep && invoked_peratom == update->ntimestep) return;
  if (invoked_peratom != update->ntimestep) compute_peratom();
  tally_step = update->ntimestep;

  double *local = new double[max_coord + 3];
  for (int k = 0; k < max_coord + 3; k++) local[k] = 0.0;
  double **x = atom->x;
  int *mask = atom->mask;
  const int nlocal = atom->nlocal;
  // heights in the box image (z periodic: an owned atom may have drifted out since reneighboring)
  const int zper = domain->zperiodic;
  const double lz = domain->zprd, zbox = domain->boxlo[2];
  for (int i = 0; i < nlocal; i++) {
    if (!(mask[i] & groupbit)) continue;
    const double zi = zper ? x[i][2] - lz * floor((x[i][2] - zbox) / lz) : x[i][2];
    if (!zlo_null && zi < zlo) continue;
    if (!zhi_null && zi > zhi) continue;
    const int nc = static_cast<int>(coord[i]);
    local[nc < max_coord ? nc : max_coord] += 1.0;
    local[max_coord + 1] += coord[i];
    local[max_coord + 2] += 1.0;
  }
  MPI_Allreduce(local, tally, max_coord + 3, MPI_DOUBLE, MPI_SUM, world);
  delete[] local;
}

/* ---------------------------------------------------------------------- */

double ComputeCoordDist::compute_scalar()
{
  invoked_scalar = update->ntimestep;
  tally_global();
  const double n = tally[max_coord + 2];
  scalar = (n > 0.0) ? tally[max_coord + 1] / n : 0.0;
  return scalar;
}

/* ---------------------------------------------------------------------- */

void ComputeCoordDist::compute_array()
{
  invoked_array = update->ntimestep;
  tally_global();
  const double n = tally[max_coord + 2];
  for (int z = 0; z <= max_coord; z++) {
    array[z][0] = z;
    array[z][1] = tally[z];
    array[z][2] = (n > 0.0) ? tally[z] / n : 0.0;
  }
}

/* ---------------------------------------------------------------------- */

int ComputeCoordDist::pack_reverse_comm(int n, int first, double *buf)
{
  int m = 0;
  for (int i = first; i < first + n; i++) buf[m++] = coord[i];
  return m;
}

/* ---------------------------------------------------------------------- */

void ComputeCoordDist::unpack_reverse_comm(int n, int *list, double *buf)
{
  for (int i = 0; i < n; i++) coord[list[i]] += buf[i];
}

/* ---------------------------------------------------------------------- */

double ComputeCoordDist::memory_usage()
{
  return (double) nmax * sizeof(double) + (double) (max_coord + 3) * sizeof(double) +
      (double) (max_coord + 1) * 3 * sizeof(double);
}
