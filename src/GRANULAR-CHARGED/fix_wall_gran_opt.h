/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#ifdef FIX_CLASS
// clang-format off
FixStyle(wall/gran/opt,FixWallGranOpt);
// clang-format on
#else

#ifndef LMP_FIX_WALL_GRAN_OPT_H
#define LMP_FIX_WALL_GRAN_OPT_H

#include "fix_wall_gran.h"
#include "marshall_fused_set.h"
#include "marshall_kernels.h"

#include <vector>

namespace LAMMPS_NS {

// fix wall/gran with a fused loop for a flat wall (xplane, yplane, zplane) of the Marshall
// sub-model set (marshall_fused_set.h): the touching atoms found in one pass over the local
// atoms, their contacts evaluated several at a time by the contact assembly of pair_style
// granular/opt (marshall_lanes.h), no virtual calls. Every other wall (wiggle, shear, other
// models, heat, rigid bodies, the contacts output) runs FixWallGran::post_force(). Same
// arguments, history layout, restart data and results as wall/gran (doc/fix_wall_gran_opt.rst).
class FixWallGranOpt : public FixWallGran {
 public:
  FixWallGranOpt(class LAMMPS *, int, char **);
  void post_constructor() override;
  void init() override;
  void post_force(int) override;

  // for tests and the log: does post_force() run the fused loop (valid after init())?
  bool is_fused() const { return fused; }

 protected:
  bool fused;                          // the fused loop applies to this wall
  bool reported;                       // the log line of init() was written
  MarshallFusedSet::Coeffs coeffs;     // the wall model's coefficients
  MarshallFusedSet::Coeffs wall_coeffs;    // the same with the rolling limit of a wall contact
  // JKR scales of the last particle radius seen (a flat wall's R_eff is the particle radius)
  double scales_radius;
  MarshallKernels::JKRScales scales;

  // one touching atom of this step: its index and x_i - x_wall along the wall's axis
  struct WallContact {
    int i;
    double dist;
  };
  std::vector<WallContact> contacts;
  std::vector<double> jkr_overlap, jkr_root;    // their scaled overlaps and JKR roots
  std::vector<double> lane_in, lane_out;        // lanes blocks of one chunk (marshall_lanes.h)

  void post_force_fused();
  void gather_contacts();
  void pack_contact(const WallContact &c, double root, double *in, int stride);
  void unpack_contact(const WallContact &c, const double *out, int stride);
  const MarshallKernels::JKRScales &scales_of(double reff);
};

}    // namespace LAMMPS_NS

#endif
#endif
