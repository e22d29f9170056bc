/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#ifdef FIX_CLASS
// clang-format off
FixStyle(GC_CHARGE_CHECK,FixChargeCheck);
// clang-format on
#else

#ifndef LMP_FIX_CHARGE_CHECK_H
#define LMP_FIX_CHARGE_CHECK_H

#include "fix.h"

namespace LAMMPS_NS {

// The package's check that charges are not silently ignored: an internal fix (one per LAMMPS
// instance, added by ensure()) whose init() warns once, on the first run whose atoms carry
// non-zero charges while nothing computes their Coulomb interaction (no fix coul/fmm, no kspace
// style, no pair style with a coul part, no fix efield). A fix, because LAMMPS calls a fix's
// init() at the start of every run, after every pair, kspace and fix is defined: a granular
// sub-model has no such hook.
class FixChargeCheck : public Fix {
 public:
  FixChargeCheck(class LAMMPS *, int, char **);
  int setmask() override { return 0; }
  void init() override;

  // adds the fix unless it exists (pair_style granular's jkr/marshall model at pair_coeff or
  // read_restart, pair_style granular/opt at init); never from inside a fix's constructor
  static void ensure(class LAMMPS *);

 private:
  bool warned;
};

}    // namespace LAMMPS_NS

#endif
#endif
