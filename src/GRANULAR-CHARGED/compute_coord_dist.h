/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#ifdef COMPUTE_CLASS
// clang-format off
ComputeStyle(coord/dist,ComputeCoordDist);
// clang-format on
#else

#ifndef LMP_COMPUTE_COORD_DIST_H
#define LMP_COMPUTE_COORD_DIST_H

#include "compute.h"

namespace LAMMPS_NS {

// Coordination number of granular contacts: per-atom Z, global distribution f(Z) and mean <Z>
// of the atoms whose centres lie in a slab zlo <= z <= zhi.
class ComputeCoordDist : public Compute {
 public:
  ComputeCoordDist(class LAMMPS *, int, char **);
  ~ComputeCoordDist() override;
  void init() override;
  void init_list(int, class NeighList *) override;
  double compute_scalar() override;
  void compute_array() override;
  void compute_peratom() override;
  int pack_reverse_comm(int, int, double *) override;
  void unpack_reverse_comm(int, int *, double *) override;
  double memory_usage() override;

 private:
  int max_coord;    // largest coordination number with its own row of f(Z) (keyword zmax);
                    // the last row counts every Z >= max_coord
  double zlo, zhi;           // slab of atom centres that enter f(Z) and <Z>
  int zlo_null, zhi_null;    // 1 if that bound is NULL (unbounded: the bed's own extent)
  int active;                // 1: contacts held by the granular pair style, 0: geometric
  double tolerance;          // geometric contact if r_ij <= r_i + r_j + tolerance
  int tolerance_set;         // 1 if the tolerance keyword was given

  int nmax;                              // allocated length of coord
  double *coord;                         // per-atom Z
  double *tally;                         // global f(Z) counts, sum Z, number of atoms
  bigint tally_step;                     // timestep of the last tally (-1: none)
  class NeighList *list;                 // own occasional list (geometric contacts)
  class FixNeighHistory *fix_history;    // contact flags of the pair style (active contacts)

  void tally_global();
};

}    // namespace LAMMPS_NS

#endif
#endif
