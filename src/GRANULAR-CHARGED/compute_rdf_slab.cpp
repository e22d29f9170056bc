/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

/* ----------------------------------------------------------------------
   compute rdf/slab: g(r) of the bed between zlo and zhi in a box periodic in
   x and y. Reference atoms and partners are the group atoms with centres in
   the slab. The ideal-gas count of bin k for reference atom i is
     (N - 1) / V_slab * [V(r_k+1, z_i) - V(r_k, z_i)],
   V(r, z) = 4/3 pi r^3 - cap(r, z - zlo) - cap(r, zhi - z) the part of the
   ball of radius r around height z inside the slab, cap(r, d) = pi (r - d)^2
   (2 r + d) / 3 for d < r (the two caps lie on opposite sides of the slab and
   never overlap), so g(r) -> 1 for an ideal gas at every r, also for atoms
   near the faces. Column 3 is the measured mean number of group atoms
   (inside the slab or not) within r of a reference atom.
------------------------------------------------------------------------- */

#include "compute_rdf_slab.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "force.h"
#include "group.h"
#include "math_const.h"
#include "memory.h"
#include "neigh_list.h"
#include "neigh_request.h"
#include "neighbor.h"
#include "pair.h"
#include "slab_geometry.h"
#include "update.h"

#include <cmath>
#include <cstring>

using namespace LAMMPS_NS;
using MathConst::MY_PI;

/* ---------------------------------------------------------------------- */

ComputeRDFSlab::ComputeRDFSlab(LAMMPS *lmp, int narg, char **arg) :
    Compute(lmp, narg, arg), buf(nullptr), bufall(nullptr), list(nullptr), warned_outside(false)
{
  if (narg < 5) utils::missing_cmd_args(FLERR, "compute rdf/slab", error);
  if (!atom->radius_flag)
    error->all(FLERR, "Compute rdf/slab requires atom style sphere (per-atom radius)");

  nbin = utils::inumeric(FLERR, arg[3], false, lmp);
  if (nbin < 1 || nbin > 1000000)
    error->all(FLERR, 3, "Compute rdf/slab number of bins must be in [1, 1000000], got {}", nbin);
  rmax_user = utils::numeric(FLERR, arg[4], false, lmp);
  if (rmax_user <= 0.0)
    error->all(FLERR, 4, "Compute rdf/slab rmax must be > 0, got {}", rmax_user);

  diameter_units = 0;
  zlo_null = zhi_null = 1;
  zlo = zhi = 0.0;

  int iarg = 5;
  while (iarg < narg) {
    if (strcmp(arg[iarg], "z") == 0) {
      if (iarg + 3 > narg) utils::missing_cmd_args(FLERR, "compute rdf/slab z", error);
      parse_slab_bounds(lmp, arg, iarg + 1, "Compute rdf/slab z:", zlo, zhi, zlo_null, zhi_null);
      iarg += 3;
    } else if (strcmp(arg[iarg], "units") == 0) {
      if (iarg + 2 > narg) utils::missing_cmd_args(FLERR, "compute rdf/slab units", error);
      if (strcmp(arg[iarg + 1], "box") == 0)
        diameter_units = 0;
      else if (strcmp(arg[iarg + 1], "diameter") == 0)
        diameter_units = 1;
      else
        error->all(FLERR, iarg + 1, "Compute rdf/slab units must be 'box' or 'diameter', got '{}'",
                   arg[iarg + 1]);
      iarg += 2;
    } else
      error->all(FLERR, iarg, "Unknown compute rdf/slab keyword: {}", arg[iarg]);
  }
  check_slab_box(lmp, "Compute rdf/slab");

  array_flag = 1;
  size_array_rows = nbin;
  size_array_cols = 3;
  extarray = 0;

  dunit = 1.0;
  rmax = rmax_user;
  delr = rmax / nbin;
  memory->create(array, nbin, 3, "rdf/slab:array");
  memory->create(buf, 3 * nbin + 2, "rdf/slab:buf");
  memory->create(bufall, 3 * nbin + 2, "rdf/slab:bufall");
  for (int k = 0; k < nbin; k++) {
    array[k][0] = (k + 0.5) * rmax_user / nbin;
    array[k][1] = array[k][2] = 0.0;
  }
}

/* ---------------------------------------------------------------------- */

ComputeRDFSlab::~ComputeRDFSlab()
{
  memory->destroy(array);
  memory->destroy(buf);
  memory->destroy(bufall);
}

/* ---------------------------------------------------------------------- */

void ComputeRDFSlab::init()
{
  check_slab_box(lmp, "Compute rdf/slab");

  // length unit: the mean diameter of the group's atoms at the start of the run

  dunit = 1.0;
  if (diameter_units) {
    double loc[2] = {0.0, 0.0}, all[2];
    for (int i = 0; i < atom->nlocal; i++)
      if (atom->mask[i] & groupbit) {
        loc[0] += 2.0 * atom->radius[i];
        loc[1] += 1.0;
      }
    MPI_Allreduce(loc, all, 2, MPI_DOUBLE, MPI_SUM, world);
    if (all[1] == 0.0 || all[0] <= 0.0)
      error->all(FLERR,
                 "Compute rdf/slab units diameter needs atoms of non-zero size in group {} "
                 "at the start of a run",
                 group->names[igroup]);
    dunit = all[0] / all[1];
  }
  rmax = rmax_user * dunit;
  delr = rmax / nbin;
  for (int k = 0; k < nbin; k++) array[k][0] = (k + 0.5) * rmax_user / nbin;

  // occasional half list out to rmax + skin, kept until the next reneighboring as
  // compute rdf does; atoms beyond rmax + skin - (pair cutoff) need ghost atoms of their own

  // (4Feb2025 also has MULTI_OLD, 4Jul2026 does not: test for what is supported)
  if (neighbor->style != Neighbor::BIN && neighbor->style != Neighbor::NSQ)
    error->all(FLERR, "Compute rdf/slab requires neighbor style 'bin' or 'nsq'");
  const double skin = neighbor->skin;
  const double mycutneigh = rmax + skin;
  double cutghost;
  if (force->pair)
    cutghost = MAX(force->pair->cutforce + skin, comm->cutghostuser);
  else
    cutghost = comm->cutghostuser;
  if (mycutneigh > cutghost)
    error->all(FLERR,
               "Compute rdf/slab rmax plus skin {} exceeds the ghost atom range {}: use "
               "comm_modify cutoff {} or larger",
               mycutneigh, cutghost, mycutneigh);

  auto req = neighbor->add_request(this, NeighConst::REQ_OCCASIONAL);
  req->set_cutoff(mycutneigh);
}

/* ---------------------------------------------------------------------- */

void ComputeRDFSlab::init_list(int /*id*/, NeighList *ptr)
{
  list = ptr;
}

/* ---------------------------------------------------------------------- */

void ComputeRDFSlab::compute_array()
{
  invoked_array = update->ntimestep;

  double **x = atom->x;
  int *mask = atom->mask;
  const int nlocal = atom->nlocal;

  // with z periodic, an atom's height is taken in the box image that holds the slab:
  // shift(z) = Lz floor((z - boxlo) / Lz); a reference atom's partners are judged in the
  // reference atom's own image (a ghost at z + Lz is no partner of a slab in the box)

  const int zper = domain->zperiodic;
  const double lz = domain->zprd, zbox = domain->boxlo[2];
  auto shift = [&](double z) {
    return zper ? lz * floor((z - zbox) / lz) : 0.0;
  };

  // slab: NULL bounds are the lowest / highest (wrapped) centre of the group

  double lo = zlo, hi = zhi;
  if (zlo_null || zhi_null) {
    double lowest = HUGE_VAL, highest = -HUGE_VAL;
    for (int i = 0; i < nlocal; i++)
      if (mask[i] & groupbit) {
        const double z = x[i][2] - shift(x[i][2]);
        lowest = MIN(lowest, z);
        highest = MAX(highest, z);
      }
    reduce_z_range(world, lowest, highest, lowest, highest);
    if (zlo_null) lo = lowest;
    if (zhi_null) hi = highest;
  }
  if (zper && (lo < domain->boxlo[2] || hi > domain->boxhi[2]))
    error->all(FLERR, Error::NOLASTLINE,
               "Compute rdf/slab slab [{}, {}] must lie inside the periodic z range [{}, {}]", lo,
               hi, domain->boxlo[2], domain->boxhi[2]);
  // no centre lies outside a non-periodic z range, yet the slab's volume would count that
  // empty part: the density would be too low and g(r) too high by (hi - lo) over the width of
  // the part inside the box
  if (!zper && !warned_outside && (lo < domain->boxlo[2] || hi > domain->boxhi[2])) {
    warned_outside = true;
    if (comm->me == 0)
      error->warning(FLERR,
                     "Compute rdf/slab {} slab [{}, {}] reaches outside the box's non-periodic z "
                     "range [{}, {}]: g(r) counts the empty part as slab volume and is too high; "
                     "choose zlo, zhi inside the box",
                     id, lo, hi, domain->boxlo[2], domain->boxhi[2]);
  }
  auto inslab = [&](double z) {
    return z >= lo && z <= hi;
  };

  double *hist = buf, *count = buf + nbin, *capsum = buf + 2 * nbin;
  double &nref = buf[3 * nbin + 1];
  for (int k = 0; k < 3 * nbin + 2; k++) buf[k] = 0.0;

  if (hi > lo) {
    neighbor->build_one(list);
    const double delrinv = 1.0 / delr;
    const int newton_pair = force->newton_pair;

    // ordered pairs (i, j) with r_ij < rmax: count if the reference atom is in the slab, hist if
    // its partner is too; a half list holds each pair once (per rank with newton off, where a
    // pair with a ghost atom is counted by each owner for its own atom)

    for (int ii = 0; ii < list->inum; ii++) {
      const int i = list->ilist[ii];
      if (!(mask[i] & groupbit)) continue;
      const double xtmp = x[i][0], ytmp = x[i][1], ztmp = x[i][2];
      const double si = shift(ztmp);
      const bool iref = inslab(ztmp - si);
      const int *jlist = list->firstneigh[i];
      const int jnum = list->numneigh[i];
      for (int jj = 0; jj < jnum; jj++) {
        const int j = jlist[jj] & NEIGHMASK;
        if (!(mask[j] & groupbit)) continue;
        const double delx = xtmp - x[j][0], dely = ytmp - x[j][1], delz = ztmp - x[j][2];
        const double r = sqrt(delx * delx + dely * dely + delz * delz);
        const int ibin = static_cast<int>(r * delrinv);
        if (ibin >= nbin) continue;
        if (iref) {
          count[ibin] += 1.0;
          if (inslab(x[j][2] - si)) hist[ibin] += 1.0;
        }
        if (newton_pair || j < nlocal) {
          const double sj = shift(x[j][2]);
          if (inslab(x[j][2] - sj)) {
            count[ibin] += 1.0;
            if (inslab(ztmp - sj)) hist[ibin] += 1.0;
          }
        }
      }
    }

    // reference atoms and the truncated shell volumes: only atoms within rmax of a face
    // have caps; capsum[k] = sum over reference atoms of the caps at edge r_k = k delr

    for (int i = 0; i < nlocal; i++) {
      if (!(mask[i] & groupbit)) continue;
      const double z = x[i][2] - shift(x[i][2]);
      if (!inslab(z)) continue;
      nref += 1.0;
      for (const double d : {z - lo, hi - z}) {
        if (d >= rmax) continue;
        for (int k = static_cast<int>(d * delrinv) + 1; k <= nbin; k++)
          capsum[k] += sphere_cap_volume(k * delr, d);
      }
    }
  }

  MPI_Allreduce(buf, bufall, 3 * nbin + 2, MPI_DOUBLE, MPI_SUM, world);

  const double *histall = bufall, *countall = bufall + nbin, *capall = bufall + 2 * nbin;
  const double nall = bufall[3 * nbin + 1];
  const double vslab = domain->xprd * domain->yprd * (hi - lo);
  const double rho = (nall > 1.0 && vslab > 0.0) ? (nall - 1.0) / vslab : 0.0;
  double coord = 0.0;
  for (int k = 0; k < nbin; k++) {
    const double rl = k * delr, ru = (k + 1) * delr;
    const double shell =
        nall * 4.0 * MY_PI / 3.0 * (ru * ru * ru - rl * rl * rl) - (capall[k + 1] - capall[k]);
    const double ideal = rho * shell;
    array[k][1] = (ideal > 0.0) ? histall[k] / ideal : 0.0;
    if (nall > 0.0) coord += countall[k] / nall;
    array[k][2] = coord;
  }
}

/* ---------------------------------------------------------------------- */

double ComputeRDFSlab::memory_usage()
{
  return (double) nbin * 3 * sizeof(double) + 2.0 * (3 * nbin + 2) * sizeof(double);
}
