/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#ifdef GRAN_SUB_MOD_CLASS
// clang-format off
GranSubModStyle(marshall/jkr,GranSubModTwistingMarshallJKR,TWISTING);
// clang-format on
#else

#ifndef GRAN_SUB_MOD_TWISTING_MARSHALL_JKR_H
#define GRAN_SUB_MOD_TWISTING_MARSHALL_JKR_H

#include "gran_sub_mod_twisting.h"

// LAMMPS 4Jul2026 returns the twisting moment from calculate_forces(); 4Feb2025 stores it in
// GranularModel::magtortwist. GC_TWISTING_RETURNS_MOMENT comes from cmake/LammpsSource.cmake.
#ifndef GC_TWISTING_RETURNS_MOMENT
#error "GC_TWISTING_RETURNS_MOMENT is set by the GRANULAR-CHARGED CMake build"
#elif GC_TWISTING_RETURNS_MOMENT
#define GC_TWISTING_RESULT double
#else
#define GC_TWISTING_RESULT void
#endif

namespace LAMMPS_NS {
namespace Granular_NS {

  // Twisting resistance as in the paper (eq. 4) and Marshall (2009): stiffness k_T a^2 / 2 with
  // k_T = 8 G* a, damping eta_T a^2 / 2, limit M_crit = 3 pi a F_crit / 16.
  class GranSubModTwistingMarshallJKR : public GranSubModTwisting {
   public:
    GranSubModTwistingMarshallJKR(class GranularModel *, class LAMMPS *);
    void init() override;
    GC_TWISTING_RESULT calculate_forces() override;

   protected:
    double k_tang;     // 8 G*: tangential stiffness per unit contact radius
    double mu_tang;    // sliding friction coefficient
  };

}    // namespace Granular_NS
}    // namespace LAMMPS_NS

#endif
#endif
