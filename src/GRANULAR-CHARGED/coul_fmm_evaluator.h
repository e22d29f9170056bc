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
#include "coul_fmm_time_stepping.h"
#include "pointers.h"

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace gcfmm {
class DistributedSolver;
class Solver;
struct Options;
struct Stats;
}    // namespace gcfmm

namespace LAMMPS_NS {
class CoulFMMSleepers;
class Fix;

class CoulFMMEvaluator : protected Pointers {
 public:
  CoulFMMEvaluator(class LAMMPS *, const std::string &fix_id, int groupbit);
  ~CoulFMMEvaluator() override;

  // opts.boundary from the box (free space or periodic in x and y only), and errors for the
  // solver options this box rules out
  void set_geometry(gcfmm::Options &opts, bool bed_given);
  // warnings or errors for other styles that compute the same Coulomb interactions: a kspace
  // style, a pair style with a coul part, another fix coul/fmm sharing charged atoms
  void check_counted_once(class Fix *self);
  // a solver for these options (the one of the last run if its boundary is the same), the
  // sleepers of `sleep` as a static source if given (errors for what cannot use them)
  // distribute: gcfmm::DistributedSolver (each rank keeps its charges), else gcfmm::Solver on
  // the charges of all ranks gathered on every rank
  void init(const gcfmm::Options &opts, Fix *sleep, bool virial, bool distribute);

  // what the stored evaluation (state rows: CoulFMMTimeStepping::Column) belongs to: record()
  // it before an evaluation, continuity() relates it to the atoms now
  void record(CoulFMMTimeStepping &scheme, double **state);
  CoulFMMTimeStepping::Continuity continuity(const CoulFMMTimeStepping &scheme, double **state);
  // at the start of a run: the stored field belongs to the same atoms, charges and box, and no
  // atom was moved since the field was last applied (displace_atoms, set)
  bool continues(const CoulFMMTimeStepping &scheme, double **state);
  // keyword check: the applied field against a fresh evaluation at the same positions (with
  // static sleepers a full one: the error of the split and of the time stepping together)
  void measure_error(CoulFMMTimeStepping &scheme, double **applied);

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
  // the solver's side of the last evaluation (the same on every rank)
  struct Diagnostics {
    double estimated_error = 0.0, theta = 0.0;
    int order = 0, leaf = 0;
    double m2l = 0.0, p2p = 0.0;      // interactions of all ranks together
    double bytes_received = 0.0;      // largest over the ranks, all collectives of the evaluation
    double solver_memory = 0.0;       // largest over the ranks
    double charges = 0.0;             // charged atoms evaluated
  };
  const Diagnostics &diagnostics_of_last() const { return diagnostics; }
  double memory_usage() const;

 private:
  std::string fix_id;
  int groupbit;
  std::unique_ptr<gcfmm::Options> opts;
  std::unique_ptr<gcfmm::Solver> solver;
  std::unique_ptr<gcfmm::DistributedSolver> distributed_solver;
  bool distributed;
  int solver_boundary;
  CoulFMMComm mpi;
  GatheredCharges gathered;    // replicated: the charges of all ranks
  GatheredCharges local;       // distributed: this rank's
  std::vector<int64_t> ids;
  Diagnostics diagnostics;
  std::vector<double> result, values, mine;
  double **fresh;    // the fresh evaluation of measure_error()
  int nmax_fresh;
  Fix *sleep_fix;
  std::unique_ptr<CoulFMMSleepers> sleepers;
  double pair_energy;    // C/2 sum_awake q pot^sleepers at the last evaluation
  bool logged;

  bool evaluate_replicated(const std::function<bool(int)> &charged, double **out, int col,
                           bool split);
  bool evaluate_distributed(const std::function<bool(int)> &charged, double **out, int col,
                            bool split);
  double add_sleepers_field(const GatheredCharges &targets, size_t first, size_t last, double *pot,
                            double *ex, double *ey, double *ez);
  void sum_pair_energy(double qpot);
  std::string guarded(const std::function<void()> &run,
                      const std::function<tagint(size_t)> &tag_of);
  void record_diagnostics();
  void log_parameters();
};

}    // namespace LAMMPS_NS

#endif
