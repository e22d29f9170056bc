/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

// fix coul/fmm for charges (doc/theory.md, section 5): full evaluations on the schedule of
// CoulFMMTimeStepping, the field continued in between (extrapolated far part, refreshed near
// pairs: CoulFMMNearRefresh), F_i = q_i E_i, and the sleepers of fix sleep/gran as a static
// source (CoulFMMEvaluator).

#ifndef LMP_COUL_FMM_CHARGE_SCHEME_H
#define LMP_COUL_FMM_CHARGE_SCHEME_H

#include "coul_fmm_scheme.h"
#include "pointers.h"

#include <string>
#include <memory>

namespace LAMMPS_NS {
class CoulFMMEvaluator;

class CoulFMMChargeScheme : public CoulFMMScheme, protected Pointers {
 public:
  CoulFMMChargeScheme(class LAMMPS *, const Parts &);
  ~CoulFMMChargeScheme() override;

  void init() override;
  bool continues() override;
  bool acts_on(int i) const override;
  double total_energy(double atoms) override;
  const Diagnostics &diagnostics() const override;
  double evaluations() const override { return nevaluations; }
  double memory_usage() const override;

 protected:
  bool evaluation_due() override;
  bool continue_last(double &energy) override;
  double evaluate(Evaluation why) override;

 private:
  Parts p;
  std::unique_ptr<CoulFMMEvaluator> eval;
  double nevaluations;
  bool forced;                // this step's evaluation is forced by absorbed changes' far part
  double pending_absorbed;    // charge changes of this step, absorbed if the field is continued
  std::string absorbing_said;    // the absorbing setting last said in the log
  void compute_field(bool with_slope, bool brought_forward = false);
  bool advance_field();
  void init_absorbing();
  double apply_field();
};

}    // namespace LAMMPS_NS

#endif
