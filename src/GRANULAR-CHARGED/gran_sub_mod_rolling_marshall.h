/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#ifdef GRAN_SUB_MOD_CLASS
// clang-format off
GranSubModStyle(marshall,GranSubModRollingMarshall,ROLLING);
// clang-format on
#else

#ifndef GRAN_SUB_MOD_ROLLING_MARSHALL_H
#define GRAN_SUB_MOD_ROLLING_MARSHALL_H

#include "gran_sub_mod_rolling.h"

namespace LAMMPS_NS {
namespace Granular_NS {

  class GranSubModNormalJKRMarshall;

  // Rolling resistance of Marshall (2009) / the paper's eqs. 3-4: a spring on the rolling
  // displacement xi with stiffness k_R = 4 F_C (a/a_0)^(3/2); the contact rolls irreversibly
  // once |xi| exceeds theta_crit R.
  class GranSubModRollingMarshall : public GranSubModRolling {
   public:
    GranSubModRollingMarshall(class GranularModel *, class LAMMPS *);
    void coeffs_to_local() override;
    void mix_coeffs(double *, double *) override;
    void init() override;
    void calculate_forces() override;

   protected:
    GranSubModNormalJKRMarshall *jkr;    // normal model, for k_R
    double theta_crit;                   // critical rolling angle
  };

}    // namespace Granular_NS
}    // namespace LAMMPS_NS

#endif
#endif
