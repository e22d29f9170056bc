/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

// One FMM evaluation of fix coul/fmm: the field of the group's charges at the local atoms, from
// the atoms to the fix's backend (coul_fmm_backend.h: the solver, its cell, units and errors)
// and back, and the sleepers of fix sleep/gran as a static source (coul_fmm_sleepers.h).

#ifndef LMP_COUL_FMM_EVALUATOR_H
#define LMP_COUL_FMM_EVALUATOR_H

#include "coul_fmm_comm.h"
#include "coul_fmm_scheme.h"
#include "coul_fmm_time_stepping.h"
#include "pointers.h"

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace gcfmm {
struct Options;
}    // namespace gcfmm

namespace LAMMPS_NS {
class CoulFMMBackend;
class CoulFMMSleepers;
class CoulFMMState;
class Fix;

class CoulFMMEvaluator : protected Pointers {
 public:
  CoulFMMEvaluator(class LAMMPS *, const std::string &fix_id, int groupbit, CoulFMMBackend &);
  ~CoulFMMEvaluator() override;

  // a solver for these options (the one of the last run if its boundary is the same), the
  // sleepers of `sleep` as a static source if given (errors for what cannot use them)
  // distribute: the distributed backend (each rank keeps its charges), else the replicated one
  // on the charges of all ranks gathered on every rank
  void init(const gcfmm::Options &opts, Fix *sleep, bool virial, bool distribute);

  // keyword check: the applied field against a fresh evaluation at the same positions (with
  // static sleepers a full one: the error of the split and of the time stepping together)
  void measure_error(CoulFMMTimeStepping &scheme, CoulFMMState &state);
  int boundary() const;

  // the sleepers' flags of this step (call before asleep())
  void update_sleepers();
  bool split_active() const { return sleepers != nullptr; }
  bool asleep(int i) const;

  // out(i)[0 .. 3] = Ex, Ey, Ez, phi (LAMMPS units) at the local atoms, zero outside the
  // group, for uncharged atoms and for static sources; split false: all charges in the solver
  using Rows = std::function<double *(int)>;
  void evaluate(const Rows &out, bool split);

  // the static sleepers' energy (LAMMPS units): with the awake charges at the last evaluation,
  // and among themselves (computed when first asked after a change of the set)
  double sleeper_pair_energy() const { return pair_energy; }
  double sleeper_source_energy();
  using Diagnostics = CoulFMMScheme::Diagnostics;
  const Diagnostics &diagnostics_of_last() const { return diagnostics; }
  double memory_usage() const;

 private:
  std::string fix_id;
  int groupbit;
  std::unique_ptr<gcfmm::Options> opts;
  CoulFMMBackend &backend;
  CoulFMMComm &mpi;
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

  GatheredCharges &collect(const std::function<bool(int)> &charged);
  void hand_back(const std::function<bool(int)> &charged, const GatheredCharges &in,
                 const Rows &out);
  double add_sleepers_field(const GatheredCharges &targets, size_t first, size_t last, double *pot,
                            double *ex, double *ey, double *ez);
  void sum_pair_energy(double qpot);
  void record_diagnostics();
  void log_parameters();
};

}    // namespace LAMMPS_NS

#endif
