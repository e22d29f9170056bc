/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

// One FMM evaluation of fix coul/fmm: the field of the group's charges at the local atoms, from
// the atoms to the solver (src/fmm) and back, with the solver's failures turned into LAMMPS
// errors naming atom IDs, and the sleepers of fix sleep/gran as a static source
// (coul_fmm_sleepers.h). Owns the solver, which is kept across runs.

#ifndef LMP_COUL_FMM_EVALUATOR_H
#define LMP_COUL_FMM_EVALUATOR_H

#include "coul_fmm_comm.h"
#include "pointers.h"

#include <memory>
#include <string>
#include <vector>

namespace gcfmm {
class Solver;
struct Options;
struct Stats;
}    // namespace gcfmm

namespace LAMMPS_NS {
class CoulFMMSleepers;
class FixSleepGran;

class CoulFMMEvaluator : protected Pointers {
 public:
  CoulFMMEvaluator(class LAMMPS *, const std::string &fix_id, int groupbit);
  ~CoulFMMEvaluator() override;

  // a solver for these options (the one of the last run if its boundary is the same), the
  // sleepers of `sleep` as a static source if given
  void init(const gcfmm::Options &opts, FixSleepGran *sleep);

  // the sleepers' flags of this step (call before asleep())
  void update_sleepers();
  bool split_active() const { return sleepers != nullptr; }
  bool asleep(int i) const;

  // out[i][col .. col+3] = Ex, Ey, Ez, phi (LAMMPS units) at the local atoms, zero outside the
  // group, for uncharged atoms and for static sources; split false: all charges in the solver
  void evaluate(double **out, int col, bool split);

  // the static sleepers' energy (LAMMPS units): with the awake charges at the last evaluation,
  // and among themselves (computed when first asked after a change of the set)
  double sleeper_pair_energy() const { return pair_energy; }
  double sleeper_source_energy();
  const gcfmm::Stats *stats() const;
  double memory_usage() const;

 private:
  std::string fix_id;
  int groupbit;
  std::unique_ptr<gcfmm::Options> opts;
  std::unique_ptr<gcfmm::Solver> solver;
  int solver_boundary;
  CoulFMMComm mpi;
  GatheredCharges gathered;
  std::vector<double> result, values, mine;
  FixSleepGran *sleep_fix;
  std::unique_ptr<CoulFMMSleepers> sleepers;
  double pair_energy;    // C/2 sum_awake q pot^sleepers at the last evaluation
  bool logged;

  std::string solve(bool split);
  void log_parameters();
};

}    // namespace LAMMPS_NS

#endif
