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

#include "coul_fmm_scheme.h"
#include "coul_fmm_time_stepping.h"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace LAMMPS_NS {

// Coulomb forces between the charged atoms of a group by the FMM core library (src/fmm):
// free space (boundary f f f) or periodic in x and y and open in z (boundary p p f). The fix is
// the LAMMPS adapter (keywords, checks, per-atom callbacks, restart) over one solver backend
// (CoulFMMBackend: box, units, errors), one scheme that computes the forces of a step
// (CoulFMMChargeScheme, or CoulFMMPolarizable with efield, polarize or electrode) and one
// owner of the per-atom state (CoulFMMState).
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
  void post_run() override;
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
  std::unique_ptr<gcfmm::Options> opts;              // solver options from the keywords
  std::unique_ptr<CoulFMMTimeStepping> stepping;     // the schedule and extrapolation
  std::unique_ptr<CoulFMMBackend> backend;           // the solver
  std::unique_ptr<CoulFMMNearRefresh> near;          // the near refresh's list and buffers
  std::unique_ptr<CoulFMMState> state;               // per-atom fields, forces, evaluation rows
  std::unique_ptr<CoulFMMScheme> scheme;             // the forces of one step
  int field_cols;                  // per-atom columns: 4, or 7 with the dipole
  bool bed_given;                  // bed zlo/zhi given by the user (farfield average)
  std::string periodic_keyword;    // last of images/farfield given (ignored in free space)
  bool sleepers_static;            // keyword sleepers: static (true) or full
  bool distributed;                // keyword solver: distributed (true) or replicated
  CoulFMMScheme::QChange qchange;  // keyword qchange

  double energy_local, energy_all;
  bool energy_summed;
  int ilevel_respa;    // rRESPA level at which the Coulomb force is applied (outermost)

  void parse_keywords(int narg, char **arg);
  void create_parts(const CoulFMMTimeStepping::Settings &mts);
  CoulFMMScheme::Parts parts();
  int one_of(int iarg, const std::vector<std::string> &words, char **arg);
  void check_boundary_and_options();
  void check_accuracy_reachable();
  void apply(int vflag, bool predict);
};

}    // namespace LAMMPS_NS

#endif
#endif
