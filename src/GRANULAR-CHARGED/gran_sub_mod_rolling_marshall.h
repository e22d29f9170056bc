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
GranSubModStyle(marshall/particle,GranSubModRollingMarshallParticle,ROLLING);
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

    double get_theta_crit() const { return theta_crit; }                    //!< theta_crit
    double get_pair_radius_factor() const { return pair_radius_factor; }    //!< 1, or 2

   protected:
    GranSubModNormalJKRMarshall *jkr;    // normal model, for k_R
    double theta_crit;                   // critical rolling angle
    double pair_radius_factor;           // slip at theta_crit x this x R_eff for a pair
  };

  // The same spring, but the contact rolls once |xi| exceeds theta_crit times the particle
  // radius instead of the effective radius: 2 R_eff for a pair (r_p for like spheres, the
  // harmonic mean of unlike ones), R_eff = r_p at a wall. A convention option: the paper's
  // eq. 4 writes R without saying which.
  class GranSubModRollingMarshallParticle : public GranSubModRollingMarshall {
   public:
    GranSubModRollingMarshallParticle(class GranularModel *, class LAMMPS *);
  };

}    // namespace Granular_NS
}    // namespace LAMMPS_NS

#endif
#endif
