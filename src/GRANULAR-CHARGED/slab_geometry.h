/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

// The analysis slab zlo <= z <= zhi shared by the packing computes (coord/dist, rdf/slab,
// packing/slab): parsing of its bounds, the box it needs, and the sphere-slab geometry.

#ifndef LMP_GC_SLAB_GEOMETRY_H
#define LMP_GC_SLAB_GEOMETRY_H

#include "math_const.h"

#include <mpi.h>
#include <string>

namespace LAMMPS_NS {
class LAMMPS;

// Parse the "zlo zhi" bounds of an analysis slab from arg[ilo], arg[ilo + 1] ("NULL" leaves a
// bound open: each compute says what an open bound means). Both given: zlo < zhi, or an error
// "<what> zlo .. must be < zhi ..". An open bound is stored as 0 with its null flag set.
void parse_slab_bounds(LAMMPS *lmp, char **arg, int ilo, const std::string &what, double &zlo,
                       double &zhi, int &zlo_null, int &zhi_null);

// Error unless the box is 3d and periodic in x and y (the slab's cross-section is the cell).
void check_slab_box(LAMMPS *lmp, const std::string &style);

// Smallest low and largest high value over all ranks (open slab bounds from the atoms).
// Ranks without atoms pass the defaults; with no atoms at all, lo = +HUGE_VAL, hi = -HUGE_VAL.
void reduce_z_range(MPI_Comm world, double lo_local, double hi_local, double &lo, double &hi);

// Volume of the part of a ball of radius r beyond a plane at signed distance d from its
// centre: pi (r - d)^2 (2 r + d) / 3 for |d| < r, 0 for d >= r, the whole ball for d <= -r.
inline double sphere_cap_volume(double r, double d)
{
  if (d >= r) return 0.0;
  if (d <= -r) return 4.0 * MathConst::MY_PI / 3.0 * r * r * r;
  const double h = r - d;
  return MathConst::MY_PI * h * h * (2.0 * r + d) / 3.0;
}

}    // namespace LAMMPS_NS

#endif
