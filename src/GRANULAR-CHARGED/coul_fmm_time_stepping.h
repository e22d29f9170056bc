/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

// The multiple time stepping of fix coul/fmm (doc/theory.md, eqs. (5.1)-(5.4)): between two
// evaluations of the FMM the far part of each atom's field is extrapolated with its slope and
// the pairs closer than a cutoff are summed afresh; the evaluation interval adapts to a
// tolerance. No LAMMPS headers: the fix owns the per-atom arrays and the communication, this
// class the numerics on one atom's row (or one pair) at a time, so it is tested alone
// (unittest/lammps/test_coul_fmm_time_stepping.cpp).

#ifndef LMP_COUL_FMM_TIME_STEPPING_H
#define LMP_COUL_FMM_TIME_STEPPING_H

#include <cstdint>
#include <cstring>

namespace LAMMPS_NS {

class CoulFMMTimeStepping {
 public:
  // one atom's state of the last evaluation (a row of the fix's per-atom array)
  enum Column : int {
    X = 0,           // unwrapped position at the evaluation (3)
    Q = 3,           // charge at the evaluation (0 outside the group)
    FIELD = 4,       // evaluated Ex, Ey, Ez, phi (4)
    SLOPE = 8,       // change of the far part per step, from the last two evaluations (4)
    LAST_X = 12,     // unwrapped position when a field was last applied (3)
    SLOPE_A = 15,    // unwrapped positions at the two evaluations the slope was taken over
    SLOPE_B = 18,    // (3 each): the trend of a pair inside the slope, for the near refresh
    IN_SLOPE = 21,   // 1 if the slope covers this atom's pairs (it existed at both evaluations)
    ASLEEP = 22,     // 1 if the atom was a static source (fix sleep/gran) at the evaluation
    LAST_Q = 23,     // charge when a field was last applied (0 outside the group)
    COLS = 24
  };
  // rows of restart files written before ASLEEP existed
  static constexpr int COLS_V1 = 22;

  // one atom's displacements for the near refresh (local atoms and ghosts): since the
  // evaluation, since the two evaluations of the slope, whether the slope covers it, its
  // charge at the evaluation (the change of an absorbed charge, eq. (5.5)) and whether it was a
  // static source then (ASLEEP)
  enum Delta : int {
    DELTA_E = 0,
    DELTA_A = 3,
    DELTA_B = 6,
    DELTA_IN_SLOPE = 9,
    DELTA_Q = 10,
    DELTA_STATIC = 11,
    DELTA_COLS = 12
  };

  // the keywords of the scheme, checked once by validate()
  struct Settings {
    int every = 1;             // fixed: evaluate on multiples of every; adaptive: largest interval
    double tolerance = 0.0;    // adaptive: error allowed per interval (0: fixed interval)
    bool extrapolate = true;   // extrapolate the far part linearly between evaluations
    double near_cutoff = 0.0;  // pairs closer than this are summed afresh every step (0: off)
    int check_every = 0;       // measure the scheme's error every this many steps (0: never)
    // throws std::invalid_argument "<keyword> must be ..., got <value>"
    void validate() const;
  };

  // how the stored evaluation relates to the atoms now (the fix measures it)
  enum class Continuity { NONE, SAME, ADDED };

  // what a new evaluation does with the stored state
  struct Plan {
    bool same = false;        // the same charges as at the last evaluation
    bool keep_slope = false;  // the stored slope stays valid (same charges, or only added ones)
    bool new_slope = false;   // a whole interval passed: take a new slope over it
    bool near = false;        // the near refresh is part of the prediction
    double steps = 0.0;       // steps since the last evaluation (same charges only)
    // the measured error is that of the interval, which adapts to it: not of an evaluation
    // brought forward (a near pair leaving the lists), whose shorter span would understate it
    bool ends_interval = false;
  };

  // validates the settings; with a tolerance, every becomes the power of two at or below it
  // (the evaluation steps of a shorter interval then include those of a longer one)
  explicit CoulFMMTimeStepping(const Settings &settings);

  const Settings &settings() const { return set; }
  bool refreshes_near() const { return set.near_cutoff > 0.0 && set.every > 1; }

  // ---- schedule (eq. (5.4)) ----
  // an evaluation is due on the multiples of the interval (a schedule that does not depend on
  // where a run starts) and when none was made yet
  bool scheduled(int64_t step) const
  {
    return evaluated.step < 0 || (step % interval == 0 && step != evaluated.step);
  }
  int stride() const { return interval; }
  // the stored field cannot be continued: no evaluation to continue, an adaptive schedule
  // starts again from 1
  void restart_schedule();
  // halve the interval while the measured error exceeds the tolerance, double it when even
  // the doubled interval would stay below half of it
  void adapt(double error);
  // the error measured at the last evaluation that continued a field (-1: none yet)
  double last_estimate() const { return estimate; }
  // steps between the two evaluations of the last slope
  double slope_interval() const { return slope_steps; }

  // ---- one evaluation (eqs. (5.2)-(5.3)) ----
  // with_slope false: a field of its own, nothing continued (a minimizer step)
  Plan plan(Continuity continuity, bool with_slope, int64_t step) const;
  // the share of a pair's trend that the extrapolation has added `steps` after the evaluation
  double trend_factor(double steps) const;
  // eq. (5.2): the field applied `steps` after the evaluation, near = the near refresh or null
  void predict(const double *state, double steps, const double *near, double out[4]) const;
  // before the new evaluation overwrites the row: the field the scheme would have applied now
  // (`predicted`), the first half of a new slope (E(t_e) + D), the evaluation's position xu,
  // charge q (0 outside the group) and whether it is a static source now
  void begin_evaluation(const Plan &plan, double *state, const double xu[3], double q, bool asleep,
                        const double *near_now, const double *near_then, double predicted[4]) const;
  // after the evaluation wrote FIELD: the new slope S = (E(t) - E(t_e) - D) / (t - t_e) and the
  // sums of squares of the prediction error (add_error_sums)
  void end_evaluation(const Plan &plan, double *state, const double predicted[4],
                      double sums[2]) const;
  // the whole set: the interval of a new slope, and the adapted schedule from the error of the
  // prediction (relative_rms of the summed sums)
  void finish_evaluation(const Plan &plan, double error);

  // eq. (5.3): the change of (K, 1/r) of one pair since the evaluation, K(r) = r / |r|^3,
  // r = now the separation, di, dj the two atoms' Delta rows. trend < 0: the D of a new slope
  // (pairs closer than the cutoff now); trend >= 0: the refresh between evaluations (pairs
  // closer now or at the evaluation), minus trend times the change over the slope's interval
  // of the pairs the slope carries. False (dg untouched) if the pair is not refreshed.
  bool near_pair_change(const double now[3], const double *di, const double *dj, double trend,
                        double dg[4]) const;
  // the same in two halves, for many pairs at once (the near refresh): the separation at the
  // evaluation, then (after gcfmm::charge_pair_change gave dg = (K, 1/r)(now) - (K, 1/r)(then)
  // and the squared separations rn2, rt2) whether the pair is refreshed and its trend taken out
  // (inline: the near refresh calls them for every pair at every step)
  static void separation_then(const double now[3], const double *di, const double *dj,
                              double then[3])
  {
    for (int k = 0; k < 3; k++) then[k] = now[k] - (di[DELTA_E + k] - dj[DELTA_E + k]);
  }
  bool near_pair_finish(const double now[3], double rn2, double rt2, const double *di,
                        const double *dj, double trend, double dg[4]) const;
  // whether a pair at squared separations rn2 now and rt2 at the evaluation is refreshed
  // (between: between evaluations, trend >= 0); the rule of near_pair_finish
  bool near_pair_refreshed(double rn2, double rt2, bool between) const
  {
    const double cutsq = set.near_cutoff * set.near_cutoff;
    if (rn2 >= cutsq && (!between || rt2 >= cutsq)) return false;
    return rn2 != 0.0 && rt2 != 0.0;    // coincident atoms are caught at evaluations
  }
  // the change of (K, 1/r) over the slope's interval that the slope carries for this pair, per
  // unit trend: (K, 1/r)(r_B) - (K, 1/r)(r_A) if the slope covers both atoms and the pair was
  // beyond the cutoff at the slope's later end, else 0. Between evaluations it depends on the
  // positions at the evaluations only (now - (di - dj) is fixed while the atoms do not wrap),
  // so the near refresh takes it once per neighbor list and evaluation.
  void slope_pair_change(const double now[3], const double *di, const double *dj,
                         double change[4]) const;
  // an atom's Delta row from its unwrapped position now and its state
  static void displacements(const double xu[3], const double *state, double *delta);

  // ---- error measure ----
  // sums[0] += q2 |applied - reference|^2, sums[1] += q2 |reference|^2 (the field, 3 components)
  static void add_error_sums(double q2, const double *applied, const double *reference,
                             double sums[2]);
  // sqrt(sums[0] / sums[1]), 0 without a reference field
  static double relative_rms(const double sums[2]);
  // the change per step of a value that went from `then` to `now` over `steps` steps
  static double slope(double now, double then, double steps) { return (now - then) / steps; }

  // keyword check: one measurement (global sums of add_error_sums)
  void record_check(const double sums[2]);
  double check_last() const { return last_check; }
  double check_max() const { return max_check; }
  double check_overall() const;    // all checks together (their sums of squares)

  // ---- what the stored evaluation belongs to ----
  struct Evaluated {
    int64_t step = -1;          // step of the last evaluation (-1: none yet)
    double box[4] = {0, 0, 0, 0};    // xlo, ylo, Lx, Ly then
    uint64_t charges = 0;       // sum of coul_fmm_charge_hash over the charged atoms then
    double qqrd2e = 0.0;        // Coulomb constant (units, dielectric) then
    int boundary = -1;          // the solver's boundary then (-1: none)
  };
  Evaluated evaluated;
  // the same boundary, Coulomb constant and (periodic) cell as at the last evaluation
  bool same_setting(int boundary, double qqrd2e, const double box[4], bool periodic) const;
  // from the global sums over the atoms: [0] coul_fmm_charge_hash of the evaluation's charges
  // still present, [1] atoms whose charge differs from the evaluation's (a created atom had 0),
  // [2] those of them charged at the evaluation (changed, not added), [3] charged atoms that
  // were static sources then and are awake now (no stored field, like added ones)
  Continuity continuity(const uint64_t sums[4]) const;

  // ---- charge changes absorbed between evaluations (doc/theory.md, eq. (5.5)) ----
  // on: an atom charged at the evaluation whose charge changed since is no reason to evaluate;
  // the change is a point charge dq = q - q_then at the atom, exact for the refreshed pairs and
  // left out beyond them while absorbed_far_bound stays below tau times the field scale
  void set_absorbing(bool on, double tau)
  {
    absorbing = on;
    absorb_tau = tau;
  }
  bool absorbs() const { return absorbing; }
  // what the charge changes add to a refreshed pair ij: at i the field and potential of dq_j at
  // the separation of the evaluation, dq_j (K, 1/r)(r_then); at j (at_j non-null: a local atom)
  // those of dq_i, -dq_i K(r_then) and dq_i / |r_then|. So the pair's refreshed term is
  // q_j(now) (K, 1/r)(r_now) - q_j(then) (K, 1/r)(r_then) with the q_j(now) part of dg.
  static void add_charge_change(double dq_i, double dq_j, const double terms_then[4],
                                double at_i[4], double *at_j)
  {
    if (dq_j != 0.0)
      for (int k = 0; k < 4; k++) at_i[k] += dq_j * terms_then[k];
    if (at_j && dq_i != 0.0) {
      for (int k = 0; k < 3; k++) at_j[k] -= dq_i * terms_then[k];
      at_j[3] += dq_i * terms_then[3];
    }
  }
  // an upper bound of the field, at any atom, of the changes beyond the near cutoff rc (which
  // the refresh leaves out): C sum_i |dq_i| / rc^2 for the cell's copy of the changes, plus
  // with x and y periodic (area = Lx Ly > 0) the sheet field 2 pi C |sum_i dq_i| / area of
  // their net change
  static double absorbed_far_bound(double qqrd2e, double sum_abs_dq, double net_dq, double rc,
                                   double area);
  // the field scale of the last evaluation, sqrt(sum q^2 |E|^2 / sum q^2), from those two sums
  void set_field_scale(const double sums[2]);
  double field_scale() const { return scale; }
  // the far part of the absorbed changes is too large: evaluate (a zero field scale, e.g. after
  // a restart or with a single charge, always is)
  bool far_part_exceeds(double bound) const { return bound > absorb_tau * scale; }
  // counts: charge changes absorbed (atoms whose charge changed on a step continued without
  // evaluation) and evaluations forced by the bound, since the fix was defined and in this run
  struct AbsorbCounts {
    double changes = 0.0, forced = 0.0;
  };
  void count_absorbed(double changes)
  {
    total.changes += changes;
    this_run.changes += changes;
  }
  void count_forced()
  {
    total.forced += 1.0;
    this_run.forced += 1.0;
  }
  void start_run_counts() { this_run = AbsorbCounts(); }
  const AbsorbCounts &absorbed_total() const { return total; }
  const AbsorbCounts &absorbed_this_run() const { return this_run; }

  // ---- restart: the settings, schedule, Evaluated and the field scale ----
  static constexpr int RESTART_SIZE = 15;
  void write_restart(double list[RESTART_SIZE]) const;
  // false (nothing restored: evaluate afresh) for a file of an older format or of other settings
  bool read_restart(const double *list);

 private:
  Settings set;
  int interval;          // evaluations on the steps that are multiples of it
  double estimate;       // error measured at the last evaluation that continued a field
  double slope_steps;    // steps between the two evaluations of the slope
  double last_check, max_check, check_sums[2];
  bool absorbing;        // charge changes absorbed (set_absorbing)
  double absorb_tau;     // the far part's allowance relative to the field scale
  double scale;          // field scale of the last evaluation (0: unknown)
  AbsorbCounts total, this_run;
};

// hash of one charged atom (ID, charge bits) for the checksum of the charges: summed modulo
// 2^64 over the atoms, so the sum does not depend on their order or on the ranks holding them
// (splitmix64 finaliser: a changed charge or ID changes the sum except with odds ~2^-64)
inline uint64_t coul_fmm_mix64(uint64_t z)
{
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

inline uint64_t coul_fmm_charge_hash(int64_t tag, double q)
{
  uint64_t bits;
  std::memcpy(&bits, &q, sizeof(bits));
  return coul_fmm_mix64((uint64_t) tag ^ coul_fmm_mix64(bits));
}

// refreshed: the pairs now closer than the cutoff and, between evaluations (trend >= 0), also
// those that were at the last evaluation (their change is in no slope). The sets depend on
// positions only (not on when a neighbor list was built), so split runs agree.
inline bool CoulFMMTimeStepping::near_pair_finish(const double now[3], double rn2, double rt2,
                                                  const double *di, const double *dj,
                                                  double trend, double dg[4]) const
{
  if (!near_pair_refreshed(rn2, rt2, trend >= 0.0)) return false;
  // a pair that was beyond the cutoff at the later evaluation of the slope has its trend in
  // the slope: take it out, the pair is summed exactly (doc/theory.md, eq. (5.3))
  if (trend > 0.0) {
    double change[4];
    slope_pair_change(now, di, dj, change);
    for (int k = 0; k < 4; k++) dg[k] -= trend * change[k];
  }
  return true;
}

}    // namespace LAMMPS_NS

#endif
