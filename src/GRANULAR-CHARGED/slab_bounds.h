/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#ifndef LMP_GC_SLAB_BOUNDS_H
#define LMP_GC_SLAB_BOUNDS_H

#include <string>

namespace LAMMPS_NS {
class LAMMPS;

// Parse the "zlo zhi" bounds of an analysis slab from arg[ilo], arg[ilo + 1] ("NULL" leaves a
// bound open: each compute says what an open bound means). Both given: zlo < zhi, or an error
// "<what> zlo .. must be < zhi ..". An open bound is stored as 0 with its null flag set.
void parse_slab_bounds(LAMMPS *lmp, char **arg, int ilo, const std::string &what, double &zlo,
                       double &zhi, int &zlo_null, int &zhi_null);

}    // namespace LAMMPS_NS

#endif
