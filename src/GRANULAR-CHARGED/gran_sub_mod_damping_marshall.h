/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#ifdef GRAN_SUB_MOD_CLASS
// clang-format off
GranSubModStyle(marshall,GranSubModDampingMarshall,DAMPING);
GranSubModStyle(marshall/printed,GranSubModDampingMarshallPrinted,DAMPING);
// clang-format on
#else

#ifndef GRAN_SUB_MOD_DAMPING_MARSHALL_H
#define GRAN_SUB_MOD_DAMPING_MARSHALL_H

#include "gran_sub_mod_damping.h"

namespace LAMMPS_NS {
namespace Granular_NS {

  class GranSubModNormalJKRMarshall;

  // Normal dashpot of Marshall (2009) for JKR contacts:
  // eta_N = alpha(e) sqrt(2 m* k_N), k_N = 4/3 E* a, alpha from the restitution coefficient
  // (the factor 2 makes a Hertz collision rebound with e; doc/theory.md, damping).
  class GranSubModDampingMarshall : public GranSubModDamping {
   public:
    GranSubModDampingMarshall(class GranularModel *, class LAMMPS *);
    void init() override;
    double calculate_forces() override;

    double get_alpha() const { return alpha; }                //!< alpha(e)
    double get_mass_factor() const { return mass_factor; }    //!< 2, or 1 for marshall/printed

   protected:
    GranSubModNormalJKRMarshall *jkr;    // normal model, for E*
    double alpha;                        // alpha(e)
    double mass_factor;                  // 2: eta_N = alpha sqrt(2 m* k_N); 1: as printed
  };

  // The same dashpot as printed in the paper (eq. 2) and Marshall (2009): eta_N = alpha(e)
  // sqrt(m* k_N), which rebounds with more than e (0.778 for e = 0.7 without adhesion).
  // A convention option for comparisons with the paper, not a correction.
  class GranSubModDampingMarshallPrinted : public GranSubModDampingMarshall {
   public:
    GranSubModDampingMarshallPrinted(class GranularModel *, class LAMMPS *);
  };

}    // namespace Granular_NS
}    // namespace LAMMPS_NS

#endif
#endif
