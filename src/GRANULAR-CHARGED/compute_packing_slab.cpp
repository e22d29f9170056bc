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
   for d <= -R). With z periodic, every image z + n Lz is included: a slab thicker than Lz
   holds k whole periods (every sphere k times, whole) plus a remainder slab thinner than Lz
   between the bounds wrapped into the box, so the cost per atom stays O(1) for any slab.
------------------------------------------------------------------------- */

#include "compute_packing_slab.h"

#include "atom.h"
#include "domain.h"
#include "error.h"
#include "math_const.h"
#include "slab_geometry.h"
#include "update.h"

#include <cmath>
#include <cstring>

using namespace LAMMPS_NS;
using MathConst::MY_PI;

/* ---------------------------------------------------------------------- */

ComputePackingSlab::ComputePackingSlab(LAMMPS *lmp, int narg, char **arg) : Compute(lmp, narg, arg)
{
  if (narg < 5) utils::missing_cmd_args(FLERR, "compute packing/slab", error);
  if (!atom->radius_flag)
    error->all(FLERR, "Compute packing/slab requires atom style sphere (per-atom radius)");
  if (narg > 5) error->all(FLERR, 5, "Unknown compute packing/slab keyword: {}", arg[5]);

  parse_slab_bounds(lmp, arg, 3, "Compute packing/slab", zlo, zhi, zlo_null, zhi_null);
  check_slab_box(lmp, "Compute packing/slab");

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

void ComputePackingSlab::init()
{
  check_slab_box(lmp, "Compute packing/slab");
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
    double bottom = HUGE_VAL, top = -HUGE_VAL;
    for (int i = 0; i < nlocal; i++)
      if (mask[i] & groupbit) {
        bottom = MIN(bottom, x[i][2] - radius[i]);
        top = MAX(top, x[i][2] + radius[i]);
      }
    reduce_z_range(world, bottom, top, bottom, top);
    if (zlo_null) lo = bottom;
    if (zhi_null) hi = top;
  }

  // periodic z: k whole periods, each holding every sphere once, and the remainder slab
  // [rlo, rlo + rest] (rest < Lz) in the images z + n Lz that can reach it

  const int zper = domain->zperiodic;
  const double lz = domain->zprd;
  double whole = 0.0, rlo = lo, rhi = hi;    // whole: share of the slab in whole periods
  if (zper && hi > lo) {
    if (!std::isfinite(hi - lo))
      error->all(FLERR, Error::NOLASTLINE, "Compute packing/slab {}: slab {} .. {} is not finite",
                 id, lo, hi);
    // each bound wrapped into the box on its own (fmod is exact): the remainder slab is then
    // shorter than Lz however far outside the box the bounds lie, so the images below are a
    // few per atom (a remainder taken as (hi - lo) - periods Lz carries the round-off of
    // hi - lo, which for bounds far outside the box is many periods); a slab of whole periods
    // (the box itself, or [zlo - k Lz, zhi + m Lz]) has no remainder and gives phi of the box
    const auto wrap = [&](double z) {
      double w = domain->boxlo[2] + fmod(z - domain->boxlo[2], lz);
      if (w < domain->boxlo[2]) w += lz;
      return w < domain->boxhi[2] ? w : domain->boxlo[2];
    };
    rlo = wrap(lo);
    double rest = wrap(hi) - rlo;
    if (rest < 0.0) rest += lz;
    // k Lz / (hi - lo), not k itself: k overflows for bounds like +-1e300 in a thin box
    whole = MAX(0.0, 1.0 - rest / (hi - lo));
    rhi = rlo + rest;
  }

  // [0] sphere volume in the remainder slab, [1] spheres in the slab, [2] whole sphere volumes
  double loc[3] = {0.0, 0.0, 0.0}, all[3];
  if (hi > lo) {
    for (int i = 0; i < nlocal; i++) {
      if (!(mask[i] & groupbit)) continue;
      const double r = radius[i];
      if (r <= 0.0) continue;
      const double full = 4.0 * MY_PI / 3.0 * r * r * r;
      double nlo = 0.0, nhi = 0.0;
      if (zper) {
        nlo = floor((rlo - r - x[i][2]) / lz);
        nhi = ceil((rhi + r - x[i][2]) / lz);
      }
      double v = 0.0;
      for (double n = nlo; n <= nhi; n += 1.0) {
        const double z = x[i][2] + n * lz;
        if (z + r <= rlo || z - r >= rhi) continue;
        v += MAX(0.0, full - sphere_cap_volume(r, z - rlo) - sphere_cap_volume(r, rhi - z));
      }
      loc[0] += v;
      loc[2] += full;
      if (v > 0.0 || whole > 0.0) loc[1] += 1.0;
    }
  }
  MPI_Allreduce(loc, all, 3, MPI_DOUBLE, MPI_SUM, world);

  // phi = (k sum V + V_rest) / (A (hi - lo)) = whole sum V / (A Lz) + V_rest / (A (hi - lo))
  const double area = domain->xprd * domain->yprd;
  const double vslab = (hi > lo) ? area * (hi - lo) : 0.0;
  result[0] = (vslab > 0.0) ? all[0] / vslab + (whole > 0.0 ? whole * all[2] / (area * lz) : 0.0)
                            : 0.0;
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
