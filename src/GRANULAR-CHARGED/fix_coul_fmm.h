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

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace gcfmm {
class Solver;
struct Options;
}    // namespace gcfmm

namespace LAMMPS_NS {
class CoulFMMSleepers;

// Coulomb forces between the charged atoms of a group by the FMM core library (src/fmm):
// free space (boundary f f f) or periodic in x and y and open in z (boundary p p f).
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
  std::unique_ptr<gcfmm::Options> opts;    // solver options from the keywords
  std::unique_ptr<gcfmm::Solver> solver;
  int solver_boundary;    // the gcfmm::Boundary the solver was made for
  int every;                 // fixed: evaluate on multiples of every; adaptive: largest stride
  double tolerance;          // adaptive schedule: MTS error allowed per interval (0: fixed)
  int stride;                // evaluations on the steps that are multiples of stride
  double mts_estimate;       // MTS error measured at the last scheduled evaluation (-1: none)
  bigint nevaluations;       // evaluations so far (diagnostic)
  bool extrapolate;          // between evaluations extrapolate the far part linearly
  double near_cutoff;        // pairs closer than this are refreshed every step (0: off)
  bigint last_computed;      // step of the last FMM evaluation (-1: none yet)
  double box_computed[4];    // xlo, ylo, xprd, yprd at that evaluation
  uint64_t charges_computed;    // sum of hash(ID, q) over the charged atoms at that evaluation
  double qqrd2e_computed;       // force->qqrd2e (units, dielectric) at that evaluation
  int boundary_computed;        // the gcfmm::Boundary of that evaluation (-1: none)
  bool bed_given;            // bed zlo/zhi given by the user (farfield average)
  std::string periodic_keyword;    // last of images/farfield given (ignored in free space)
  double energy_local, energy_all;
  bool energy_summed;
  double **field;    // per atom: Ex, Ey, Ez, potential (force/charge, energy/charge)
  double **eval_state;    // per atom at the last evaluation: position, charge, field, far part
                          // and its slope (EVAL_* columns in the .cpp)
  double **near_delta;    // per atom incl. ghosts: displacement since the last evaluation
  int nmax_ghost;         // allocated rows of near_delta
  class NeighList *list;
  int check_every;        // measure the MTS error every this many steps (0: never)
  double **fresh;         // a fresh evaluation for that measurement
  int nmax_check;
  double check_last, check_max;        // measured MTS errors
  double check_num, check_den;         // their sums of squares over all checks
  double **near_now;                   // near-pair difference of the field (refresh)
  double **near_then;                  // the same over the pairs closer now only (slope)
  int nmax_near;
  double slope_steps;                  // steps between the two evaluations of the slope
  bool logged;

  // gathered charged atoms of the group, sorted by atom ID (identical on every rank)
  std::vector<double> gx, gy, gz, gq, buf;
  std::vector<double> result;         // potential, Ex, Ey, Ez of the gathered atoms, n each
  std::vector<tagint> gtag;
  std::vector<size_t> order;          // sorted position -> position in the gather (rank blocks)
  std::vector<int> result_counts;     // 4 x atoms of each rank
  std::vector<double> owner_order;    // Ex, Ey, Ez, phi per atom in gather order
  std::vector<double> own_result;     // this rank's block of it

  int ilevel_respa;    // rRESPA level at which the Coulomb force is applied (outermost)

  // fix sleep/gran: the sleeping charges as a static source (keyword sleepers static)
  bool sleepers_static;                      // keyword sleepers: static (true) or full
  class FixSleepGran *sleep_fix;
  std::unique_ptr<CoulFMMSleepers> sleepers;
  double sleeper_pair_energy;                // C/2 sum_awake q pot^sleepers at the last evaluation
  bool split_now = true;                     // this evaluation splits (false: a full one)
  bool split_active() const { return sleepers && sleep_fix; }
  void init_sleepers(bool solver_new);
  void add_sleepers_field(size_t n, double *pot, double *ex, double *ey, double *ez);
  double sleeper_qpot_local = 0.0;           // this rank's sum q pot^sleepers of the last one

  void check_other_coul_fmm_fixes();
  bool stored_field_valid();
  enum class Continuity { NONE, SAME, ADDED };
  Continuity field_continuity();
  void compute_field(bool with_slope);
  void adapt_stride(double error);
  void near_pair_difference(double **out, double trend);
  void grow_near_buffers();
  double trend_factor(double steps) const;
  void advance_field();
  void remember_positions();
  void evaluate_into(double **out, int col, bool split = true);
  void measure_mts_error();
  void apply_field(int vflag);
  void gather_charges();
};

}    // namespace LAMMPS_NS

#endif
#endif
