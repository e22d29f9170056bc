/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

// The keywords efield, polarize and electrode of fix coul/fmm: one evaluation of the group's
// charges, induced dipoles, applied field and grounded electrode by gcfmm::PolarizableSolver
// (src/fmm; doc/polarization.md), from the atoms to the solver and back. The atoms of all ranks
// are gathered on every rank (sorted by ID, so that every rank solves the same system); each
// FMM evaluation is split among the ranks by target and summed, so every rank holds the same
// fields and dipoles; each keeps its own atoms' results. The dipoles of the last evaluation,
// kept by atom ID, start the next induction solve. Between evaluations (fix coul/fmm every,
// tolerance, near) the last evaluation is continued: its fields and forces plus the change of
// the near pairs with the dipoles held (gcfmm::NearPairChange; doc/polarization.md, section 8).

#ifndef LMP_COUL_FMM_POLARIZABLE_H
#define LMP_COUL_FMM_POLARIZABLE_H

#include "coul_fmm_comm.h"
#include "coul_fmm_scheme.h"
#include "pointers.h"

#include "gcfmm/types.hpp"

#include <memory>
#include <string>
#include <vector>

namespace gcfmm {
class NearPairChange;
struct NearChange;
struct Options;
}    // namespace gcfmm

namespace LAMMPS_NS {

class CoulFMMPolarizable : public CoulFMMScheme, protected Pointers {
 public:
  // what the keywords ask for (LAMMPS units: the field as for fix efield, force = qe2f q E)
  struct Settings {
    bool efield = false;
    double field[3] = {0.0, 0.0, 0.0};
    bool polarize = false;
    double eps_particle = 0.0;
    double eps_medium = 0.0;    // 0: not given (the dielectric command's value)
    bool electrode = false;
    double electrode_z = 0.0;
    double tolerance = 0.0;    // induction residual; 0: 0.1 x accuracy
  };
  CoulFMMPolarizable(class LAMMPS *, const Settings &, const Parts &);
  ~CoulFMMPolarizable() override;

  // CoulFMMScheme: evaluations on the schedule's steps, continued in between (advance)
  // (doc/polarization.md, section 8)
  void init() override;
  bool continues() override { return false; }    // an evaluation at every setup
  bool acts_on(int i) const override;
  const Diagnostics &diagnostics() const override { return diag; }
  double evaluations() const override { return nevaluations; }
  double memory_usage() const override;

 protected:
  bool evaluation_due() override;
  bool continue_last(double &energy) override;
  double evaluate(Evaluation why) override;

 private:
  // field[i][0..3] = Ex, Ey, Ez (applied field included) and the potential of the charges;
  // field[i][4..6] = the dipole (charge x distance; polarize only); force[i][0..2] = q E + (p . grad) E, all in
  // LAMMPS units, zero outside the group; returns this rank's part of the energy
  // predict: start from the dipoles extrapolated from the last two steps when they were the
  // two steps before this one (false: from the last solution; e.g. in a minimization)
  // stride: the time stepping's interval now (a trend of the far part is taken only over at
  // least that many steps)
  double solve(double **field, double **force, bool predict, int stride);
  // the same outputs from the last evaluation continued to the atoms now (its values plus the
  // near pairs' change within `cutoff` since then, dipoles held; the far part held). False
  // (nothing written) when it cannot be continued: no evaluation yet, other atoms or charges,
  // or displacements too large for the periodic cell; the caller then evaluates.
  bool advance(double **field, double **force, double &energy);
  // the near cutoff of advance() (0: only the evaluation's values, held), whether solve()
  // measures the error of the continued forces (the multiple time stepping is on), and whether
  // the far part of the force follows its trend over the last interval (extrapolate)
  void set_time_stepping(double cutoff, bool measure, bool extrapolate);
  // relative RMS difference of the continued forces from those of the last solve() (over
  // the group's charged and polarizable atoms); -1 if that evaluation continued nothing
  double prediction_error() const { return last_prediction_error; }

  Settings s;
  Parts parts;
  int groupbit;
  Diagnostics diag;
  double nevaluations = 0.0;
  void check_combinations();
  // checks against the atoms and the box, and a solver for the options (set_geometry applied)
  void init_solver(const gcfmm::Options &opts);
  class CoulFMMBackend &backend;    // the fix's, holding a gcfmm::PolarizableBackend
  bool periodic = false;
  // all atoms of the group, sorted by ID (with their radii), their polarizabilities
  // (bare units) and dipoles
  CoulFMMComm &mpi;
  GatheredCharges gathered;
  std::vector<double> galpha, gp;
  // the last two solutions, by atom ID (sorted), and their steps: the warm start is the last
  // one, or 2 p_n - p_{n-1} after two consecutive steps (a linear prediction)
  std::vector<tagint> last_tag, prev_tag;
  std::vector<double> last_p, prev_p;
  bigint last_step = -1, prev_step = -1;

  // the last evaluation, in the gathered order (bare units; positions interleaved, 3 per atom)
  struct LastEvaluation {
    std::vector<tagint> tag;
    std::vector<double> x, q, p, field, force, energy;
    std::vector<double> slope;    // trend of the far part of the force per step (eq. (8.3))
    bigint step = -1;
  } eval;
  double near_cutoff = 0.0;
  double induction_tolerance = 0.0;
  bool measure = false, extrapolate = false;
  std::vector<size_t> all_k;      // 0 .. n - 1: every gathered atom as a target
  double last_prediction_error = -1.0;
  std::unique_ptr<gcfmm::NearPairChange> near;
  std::vector<size_t> local_k;    // this rank's group atoms: their index in the gathered order
  std::vector<int> local_i;       // and their local index
  std::vector<double> now, then;  // gathered positions now and at the evaluation (3 per atom)

  gcfmm::Vec3 applied;            // the applied field, bare units

  void gather();
  void map_local();
  bool near_change(gcfmm::NearChange &change, const std::vector<size_t> &targets);
  double store(double **field, double **force, const gcfmm::NearChange *change, double steps);
  std::string below_electrode() const;
};

}    // namespace LAMMPS_NS

#endif
