/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#ifdef COMPUTE_CLASS
// clang-format off
ComputeStyle(packing/slab,ComputePackingSlab);
// clang-format on
#else

#ifndef LMP_COMPUTE_PACKING_SLAB_H
#define LMP_COMPUTE_PACKING_SLAB_H

#include "compute.h"

namespace LAMMPS_NS {

// Solid volume fraction of the slab zlo <= z <= zhi of a box periodic in x and y, from the exact
// volumes of the sphere-slab intersections.
class ComputePackingSlab : public Compute {
 public:
  ComputePackingSlab(class LAMMPS *, int, char **);
  void init() override;
  double compute_scalar() override;
  void compute_vector() override;
  double memory_usage() override;

 private:
  double zlo, zhi;           // slab
  int zlo_null, zhi_null;    // 1 if that bound is NULL (lowest sphere bottom / highest sphere top)
  double result[3];          // phi, # of atoms whose sphere intersects the slab, slab volume
  bigint result_step;        // timestep of result (-1: none)

  void tally();
};

}    // namespace LAMMPS_NS

#endif
#endif
