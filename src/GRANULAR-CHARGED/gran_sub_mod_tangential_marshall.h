/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#ifdef GRAN_SUB_MOD_CLASS
// clang-format off
GranSubModStyle(marshall,GranSubModTangentialMarshall,TANGENTIAL);
// clang-format on
#else

#ifndef GRAN_SUB_MOD_TANGENTIAL_MARSHALL_H
#define GRAN_SUB_MOD_TANGENTIAL_MARSHALL_H

#include "gran_sub_mod_tangential.h"

namespace LAMMPS_NS {
namespace Granular_NS {

  // Sliding spring-dashpot-slider of Marshall (2009): k_T = 8 G* a, eta_T = eta_N,
  // slip at mu |F_ne + 2 F_C| (marshall_kernels.h: tangential_force, the operations of the
  // built-in mindlin with the history of the tangential displacement), with G* taken from the
  // normal model's materials (correct for unlike types) and the damping ratio fixed to 1.
  // Derived from mindlin for its getters and, in LAMMPS 4Jul2026, its synchronized_verlet path.
  class GranSubModTangentialMarshall : public GranSubModTangentialMindlin {
   public:
    GranSubModTangentialMarshall(class GranularModel *, class LAMMPS *);
    void coeffs_to_local() override;
    void mix_coeffs(double *, double *) override;
    void init() override;
    void calculate_forces() override;
  };

}    // namespace Granular_NS
}    // namespace LAMMPS_NS

#endif
#endif
