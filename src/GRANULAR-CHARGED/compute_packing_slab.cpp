/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

/* ----------------------------------------------------------------------
   compute packing/slab: phi = sum_i V(sphere_i inside slab) / (A (zhi - zlo)),
   A the xy cross-section of the box (periodic in x and y, so every sphere is
   counted whole by its owner), V = 4/3 pi R^3 - cap(R, z - zlo) - cap(R, zhi - z)
   with cap(R, d) = pi (R - d)^2 (2 R + d) / 3 the part of the ball beyond a
   plane at signed distance d from its centre (0 for d >= R, the whole ball
   for d <= -R). With z periodic, every image z + n Lz is included.
------------------------------------------------------------------------- */

#include "compute_packing_slab.h"

#include "atom.h"
#include "domain.h"
#include "error.h"
#include "math_const.h"
#include "slab_bounds.h"
#include "update.h"

#include <cmath>
#include <cstring>

using namespace LAMMPS_NS;
using MathConst::MY_PI;

static constexpr double BIG = 1.0e300;

// volume of the part of a ball of radius r beyond a plane at signed distance d from its centre
static inline double cap_volume(double r, double d)
{
  if (d >= r) return 0.0;
  if (d <= -r) return 4.0 * MY_PI / 3.0 * r * r * r;
  const double h = r - d;
  return MY_PI * h * h * (2.0 * r + d) / 3.0;
}

/* ---------------------------------------------------------------------- */

ComputePackingSlab::ComputePackingSlab(LAMMPS *lmp, int narg, char **arg) : Compute(lmp, narg, arg)
{
  if (narg < 5) utils::missing_cmd_args(FLERR, "compute packing/slab", error);
  if (!atom->radius_flag)
    error->all(FLERR, "Compute packing/slab requires atom style sphere (per-atom radius)");
  if (narg > 5) error->all(FLERR, 5, "Unknown compute packing/slab keyword: {}", arg[5]);

  parse_slab_bounds(lmp, arg, 3, "Compute packing/slab", zlo, zhi, zlo_null, zhi_null);
  check_box();

  scalar_flag = 1;
  extscalar = 0;
  vector_flag = 1;
  size_vector = 3;
  extvector = 0;
  vector = result;
  result[0] = result[1] = result[2] = 0.0;
  result_step = -1;
}

/* ---------------------------------------------------------------------- */

void ComputePackingSlab::check_box()
{
  if (!domain->xperiodic || !domain->yperiodic)
    error->all(FLERR,
               "Compute packing/slab requires a box periodic in x and y, boundary is {} {} {}",
               domain->xperiodic ? "p" : "non-periodic", domain->yperiodic ? "p" : "non-periodic",
               domain->zperiodic ? "p" : "non-periodic");
  if (domain->dimension != 3) error->all(FLERR, "Compute packing/slab requires a 3d system");
}

/* ---------------------------------------------------------------------- */

void ComputePackingSlab::init()
{
  check_box();
  result_step = -1;
}

/* ---------------------------------------------------------------------- */

void ComputePackingSlab::tally()
{
  if (result_step == update->ntimestep) return;
  result_step = update->ntimestep;

  double **x = atom->x;
  double *radius = atom->radius;
  int *mask = atom->mask;
  const int nlocal = atom->nlocal;

  // NULL bounds: the lowest sphere bottom / highest sphere top of the group

  double lo = zlo, hi = zhi;
  if (zlo_null || zhi_null) {
    double ext[2] = {-BIG, -BIG}, extall[2];
    for (int i = 0; i < nlocal; i++)
      if (mask[i] & groupbit) {
        ext[0] = MAX(ext[0], -(x[i][2] - radius[i]));
        ext[1] = MAX(ext[1], x[i][2] + radius[i]);
      }
    MPI_Allreduce(ext, extall, 2, MPI_DOUBLE, MPI_MAX, world);
    if (zlo_null) lo = -extall[0];
    if (zhi_null) hi = extall[1];
  }

  // images of a sphere in a periodic z: every z + n Lz that can reach the slab

  const int zper = domain->zperiodic;
  const double lz = domain->zprd;

  double loc[2] = {0.0, 0.0}, all[2];
  if (hi > lo) {
    for (int i = 0; i < nlocal; i++) {
      if (!(mask[i] & groupbit)) continue;
      const double r = radius[i];
      if (r <= 0.0) continue;
      const double full = 4.0 * MY_PI / 3.0 * r * r * r;
      int nlo = 0, nhi = 0;
      if (zper) {
        nlo = static_cast<int>(floor((lo - r - x[i][2]) / lz));
        nhi = static_cast<int>(ceil((hi + r - x[i][2]) / lz));
      }
      double v = 0.0;
      for (int n = nlo; n <= nhi; n++) {
        const double z = x[i][2] + n * lz;
        if (z + r <= lo || z - r >= hi) continue;
        v += MAX(0.0, full - cap_volume(r, z - lo) - cap_volume(r, hi - z));
      }
      if (v > 0.0) {
        loc[0] += v;
        loc[1] += 1.0;
      }
    }
  }
  MPI_Allreduce(loc, all, 2, MPI_DOUBLE, MPI_SUM, world);

  const double vslab = (hi > lo) ? domain->xprd * domain->yprd * (hi - lo) : 0.0;
  result[0] = (vslab > 0.0) ? all[0] / vslab : 0.0;
  result[1] = all[1];
  result[2] = vslab;
}

/* ---------------------------------------------------------------------- */

double ComputePackingSlab::compute_scalar()
{
  invoked_scalar = update->ntimestep;
  tally();
  scalar = result[0];
  return scalar;
}

/* ---------------------------------------------------------------------- */

void ComputePackingSlab::compute_vector()
{
  invoked_vector = update->ntimestep;
  tally();
}

/* ---------------------------------------------------------------------- */

double ComputePackingSlab::memory_usage()
{
  return 0.0;    // no per-atom or per-bin storage
}
