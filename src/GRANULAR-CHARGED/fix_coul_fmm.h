/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#ifdef FIX_CLASS
// clang-format off
FixStyle(coul/fmm,FixCoulFMM);
// clang-format on
#else

#ifndef LMP_FIX_COUL_FMM_H
#define LMP_FIX_COUL_FMM_H

#include "fix.h"

#include "coul_fmm_time_stepping.h"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace gcfmm {
struct Options;
}    // namespace gcfmm

namespace LAMMPS_NS {
class CoulFMMComm;
class CoulFMMEvaluator;
class CoulFMMPolarizable;

// Coulomb forces between the charged atoms of a group by the FMM core library (src/fmm):
// free space (boundary f f f) or periodic in x and y and open in z (boundary p p f). The fix is
// the LAMMPS adapter (keywords, checks, per-atom arrays, restart); the time stepping is
// CoulFMMTimeStepping, one evaluation CoulFMMEvaluator, the communication CoulFMMComm.
class FixCoulFMM : public Fix {
 public:
  FixCoulFMM(class LAMMPS *, int, char **);
  ~FixCoulFMM() override;
  int setmask() override;
  void init() override;
  void init_list(int, class NeighList *) override;
  void setup(int) override;
  void min_setup(int) override;
  void post_force(int) override;
  void post_force_respa(int, int, int) override;
  void min_post_force(int) override;
  double compute_scalar() override;
  double compute_vector(int) override;
  double memory_usage() override;

  void grow_arrays(int) override;
  void copy_arrays(int, int, int) override;
  void set_arrays(int) override;
  int pack_exchange(int, double *) override;
  int unpack_exchange(int, double *) override;
  int pack_forward_comm(int, int *, double *, int, int *) override;
  void unpack_forward_comm(int, int, double *) override;
  void write_restart(FILE *) override;
  void restart(char *) override;
  int pack_restart(int, double *) override;
  void unpack_restart(int, int) override;
  int size_restart(int) override;
  int maxsize_restart() override;

 private:
  std::unique_ptr<gcfmm::Options> opts;           // solver options from the keywords
  std::unique_ptr<CoulFMMTimeStepping> stepping;  // the schedule and extrapolation
  std::unique_ptr<CoulFMMEvaluator> evaluator;    // atoms -> solver -> field
  std::unique_ptr<CoulFMMComm> mpi;
  std::unique_ptr<class CoulFMMNearRefresh> near;    // the near refresh's list and buffers
  // keywords efield, polarize, electrode: gcfmm::PolarizableSolver on the schedule's steps, continued
  // in between (null if none)
  std::unique_ptr<CoulFMMPolarizable> polarizable;
  int field_cols;                  // per-atom columns: 4, or 7 with the dipole
  double **polar_force;            // per atom: q E + (p . grad) E of the last evaluation
  bool bed_given;                  // bed zlo/zhi given by the user (farfield average)
  std::string periodic_keyword;    // last of images/farfield given (ignored in free space)
  bool sleepers_static;            // keyword sleepers: static (true) or full
  bool distributed;                // keyword solver: distributed (true) or replicated

  bigint nevaluations;             // evaluations so far (diagnostic)

  double energy_local, energy_all;
  bool energy_summed;
  int ilevel_respa;    // rRESPA level at which the Coulomb force is applied (outermost)

  // per atom: Ex, Ey, Ez, potential (force/charge, energy/charge), the field applied
  double **field;
  // per atom: the state of the last evaluation (CoulFMMTimeStepping::Column)
  double **eval_state;

  void parse_keywords(int narg, char **arg);
  int one_of(int iarg, const std::vector<std::string> &words, char **arg);
  void check_boundary_and_options();
  void compute_field(bool with_slope);
  void advance_field();
  void apply_field();
  void remember_positions();
  void post_force_polarizable(bool predict);
  void add_force(int i, const double *fi, bool in_plane);
};

}    // namespace LAMMPS_NS

#endif
#endif
