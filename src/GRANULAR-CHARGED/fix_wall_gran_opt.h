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

namespace LAMMPS_NS {

// fix wall/gran with a fused loop for a flat wall (xplane, yplane, zplane) of the Marshall
// sub-model set (marshall_fused_set.h): one pass over the local atoms through the inline
// equations of marshall_kernels.h, no virtual calls. Every other wall (wiggle, shear, other
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
  // JKR scales of the last particle radius seen (a flat wall's R_eff is the particle radius)
  double scales_radius;
  MarshallKernels::JKRScales scales;

  void post_force_fused();
  const MarshallKernels::JKRScales &scales_of(double reff);
};

}    // namespace LAMMPS_NS

#endif
#endif
