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
// kept by atom ID, start the next induction solve.

#ifndef LMP_COUL_FMM_POLARIZABLE_H
#define LMP_COUL_FMM_POLARIZABLE_H

#include "coul_fmm_comm.h"
#include "pointers.h"

#include <memory>
#include <string>
#include <vector>

namespace gcfmm {
class PolarizableSolver;
struct Options;
}    // namespace gcfmm

namespace LAMMPS_NS {

class CoulFMMPolarizable : protected Pointers {
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
  CoulFMMPolarizable(class LAMMPS *, const Settings &, int groupbit);
  ~CoulFMMPolarizable() override;

  // checks against the atoms and the box, and a solver for the options (set_geometry applied)
  void init(const gcfmm::Options &opts);
  // field[i][0..3] = Ex, Ey, Ez (applied field included) and the potential of the charges;
  // field[i][4..6] = the dipole (charge x distance; polarize only); force[i][0..2] = q E + (p . grad) E, all in
  // LAMMPS units, zero outside the group; returns this rank's part of the energy
  // predict: start from the dipoles extrapolated from the last two steps when they were the
  // two steps before this one (false: from the last solution; e.g. in a minimization)
  double evaluate(double **field, double **force, bool predict = true);

  // the solver's error estimate, order, M2L and P2P counts of the last evaluation
  double estimated_error() const;
  int order() const;
  double m2l() const;
  double p2p() const;
  int iterations() const { return last_iterations; }
  double residual() const { return last_residual; }
  const Settings &settings() const { return s; }
  double memory_usage() const;

 private:
  Settings s;
  int groupbit;
  std::unique_ptr<gcfmm::PolarizableSolver> solver;
  bool periodic = false;
  // all atoms of the group, sorted by ID (radius as the extra value), their polarizabilities
  // (bare units) and dipoles
  std::unique_ptr<CoulFMMComm> mpi;
  GatheredCharges gathered;
  std::vector<double> galpha, gp;
  // the last two solutions, by atom ID (sorted), and their steps: the warm start is the last
  // one, or 2 p_n - p_{n-1} after two consecutive steps (a linear prediction)
  std::vector<tagint> last_tag, prev_tag;
  std::vector<double> last_p, prev_p;
  bigint last_step = -1, prev_step = -1;
  int last_iterations = 0;
  double last_residual = 0.0;

  void gather();
};

}    // namespace LAMMPS_NS

#endif
