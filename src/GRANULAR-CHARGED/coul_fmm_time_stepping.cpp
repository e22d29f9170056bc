/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "coul_fmm_time_stepping.h"

#include "gcfmm/charge_pair_change.hpp"
#include "gcfmm/dipole_kernels.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

using namespace LAMMPS_NS;

namespace {
std::string num(double v)
{
  char buf[64];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}
double dot(const double *a, const double *b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
}    // namespace

void CoulFMMTimeStepping::Settings::validate() const
{
  if (every < 1) throw std::invalid_argument("every must be >= 1, got " + std::to_string(every));
  if (!(tolerance >= 0.0 && tolerance < 1.0))
    throw std::invalid_argument("tolerance must be in [0, 1), got " + num(tolerance));
  if (tolerance > 0.0 && every < 2)
    throw std::invalid_argument("tolerance " + num(tolerance) +
                                " needs every > 1 (the largest evaluation interval)");
  if (!(near_cutoff >= 0.0))
    throw std::invalid_argument("near cutoff must be >= 0, got " + num(near_cutoff));
  if (check_every < 0)
    throw std::invalid_argument("check must be >= 0, got " + std::to_string(check_every));
}

CoulFMMTimeStepping::CoulFMMTimeStepping(const Settings &settings) :
    set(settings), interval(1), estimate(-1.0), slope_steps(0.0), last_check(0.0),
    max_check(0.0), check_sums{0.0, 0.0}, absorbing(false), absorb_tau(0.0), scale(0.0)
{
  set.validate();
  if (set.tolerance > 0.0) set.every = 1 << (int) std::floor(std::log2((double) set.every));
  interval = set.tolerance > 0.0 ? 1 : set.every;
}

void CoulFMMTimeStepping::restart_schedule()
{
  evaluated.step = -1;
  if (set.tolerance > 0.0) interval = 1;
}

// doc/theory.md, eq. (5.4): the error grows as interval^2 with extrapolation, as interval without
void CoulFMMTimeStepping::adapt(double error)
{
  estimate = error;
  if (set.tolerance <= 0.0) return;
  const double growth = set.extrapolate ? 4.0 : 2.0;    // error factor per doubling
  while (error > set.tolerance && interval > 1) {
    interval /= 2;
    error /= growth;
  }
  if (estimate * growth < 0.5 * set.tolerance && 2 * interval <= set.every) interval *= 2;
}

/* ----------------------------------------------------------------------
   The slope of the far part comes from the last two evaluations, S = (E(t_e) - E(t_p) - D) /
   (t_e - t_p), D the near-pair difference over t_p -> t_e (same pairs at both ends), and only
   over a whole interval: two evaluations also differ by the solver's own error (which changes
   when the tree does), and that difference divided by a short interval would be extrapolated
   over a long one. Otherwise the slope is kept (after a shortened interval, or for the atoms
   that were there before an insertion: a particle inserted far above the others changes their
   field by a nearly constant amount) or zeroed (nothing to continue; a minimizer step).
------------------------------------------------------------------------- */

CoulFMMTimeStepping::Plan CoulFMMTimeStepping::plan(Continuity continuity, bool with_slope,
                                                    int64_t step) const
{
  const int64_t last = evaluated.step;
  const Continuity c = (with_slope && set.every > 1) ? continuity : Continuity::NONE;
  Plan p;
  p.same = c == Continuity::SAME;
  p.keep_slope = c != Continuity::NONE && set.extrapolate;
  p.steps = p.same ? (double) (step - last) : 0.0;
  p.new_slope = p.same && set.extrapolate && step - last >= interval;
  p.near = p.same && set.near_cutoff > 0.0;
  p.ends_interval = p.same;
  return p;
}

double CoulFMMTimeStepping::trend_factor(double steps) const
{
  return set.extrapolate && slope_steps > 0.0 ? steps / slope_steps : 0.0;
}

void CoulFMMTimeStepping::predict(const double *state, double steps, const double *near,
                                  double out[4]) const
{
  for (int k = 0; k < 4; k++)
    out[k] = state[FIELD + k] + (set.extrapolate ? steps * state[SLOPE + k] : 0.0) +
        (near ? near[k] : 0.0);
}

void CoulFMMTimeStepping::begin_evaluation(const Plan &p, double *st, const double xu[3], double q,
                                           bool asleep, const double *near_now,
                                           const double *near_then, double predicted[4]) const
{
  predict(st, p.keep_slope ? p.steps : 0.0, p.near ? near_now : nullptr, predicted);
  for (int k = 0; k < 4; k++) {
    if (p.new_slope)
      st[SLOPE + k] = st[FIELD + k] + (p.near ? near_then[k] : 0.0);
    else if (!p.keep_slope)
      st[SLOPE + k] = 0.0;
  }
  if (p.new_slope) {
    // the slope is taken over t_e -> now: remember both ends for the near refresh
    for (int k = 0; k < 3; k++) {
      st[SLOPE_A + k] = st[X + k];
      st[SLOPE_B + k] = xu[k];
    }
  }
  if (!p.keep_slope) st[IN_SLOPE] = 0.0;
  for (int k = 0; k < 3; k++) st[X + k] = xu[k];
  st[Q] = q;
  if (p.new_slope) st[IN_SLOPE] = q != 0.0 ? 1.0 : 0.0;
  // a static source gets no field, so no slope; awake again it starts as an added atom
  st[ASLEEP] = asleep ? 1.0 : 0.0;
  if (asleep) {
    for (int k = 0; k < 4; k++) st[SLOPE + k] = 0.0;
    st[IN_SLOPE] = 0.0;
  }
}

void CoulFMMTimeStepping::end_evaluation(const Plan &p, double *st, const double predicted[4],
                                         double sums[2]) const
{
  // static sources have no field to predict
  const double q2 = st[ASLEEP] != 0.0 ? 0.0 : st[Q] * st[Q];
  add_error_sums(q2, predicted, &st[FIELD], sums);
  // S = (E(t) - E(t_e) - D) / (t - t_e); begin_evaluation put E(t_e) + D into the slope
  if (p.new_slope)
    for (int k = 0; k < 4; k++) st[SLOPE + k] = slope(st[FIELD + k], st[SLOPE + k], p.steps);
}

void CoulFMMTimeStepping::finish_evaluation(const Plan &p, double error)
{
  if (p.new_slope) slope_steps = p.steps;
  if (p.ends_interval) adapt(error);
}

/* ----------------------------------------------------------------------
   E_i(t) = E_i(t_e) + (t - t_e) S_i + C sum_{j: |r_ij(t)| < rc} q_j [K(r_ij(t)) - K(r_ij(t_e))]
   with r_ij(t_e) = r_ij(t) - (d_i - d_j), d = displacement since the evaluation at t_e (the
   same for every image of an atom, so periodic images need no special case)
------------------------------------------------------------------------- */

bool CoulFMMTimeStepping::near_pair_change(const double now[3], const double *di, const double *dj,
                                           double trend, double dg[4]) const
{
  double then[3], change[4], rn2, rt2;
  separation_then(now, di, dj, then);
  gcfmm::charge_pair_change(1, {&now[0], &now[1], &now[2]}, {&then[0], &then[1], &then[2]},
                            {&change[0], &change[1], &change[2], &change[3], &rn2, &rt2});
  if (!near_pair_finish(now, rn2, rt2, di, dj, trend, change)) return false;
  for (int k = 0; k < 4; k++) dg[k] = change[k];
  return true;
}

void CoulFMMTimeStepping::slope_pair_change(const double now[3], const double *di,
                                            const double *dj, double change[4]) const
{
  for (int k = 0; k < 4; k++) change[k] = 0.0;
  if (di[DELTA_IN_SLOPE] == 0.0 || dj[DELTA_IN_SLOPE] == 0.0) return;
  double rb[3], ra[3];
  for (int k = 0; k < 3; k++) {
    rb[k] = now[k] - (di[DELTA_B + k] - dj[DELTA_B + k]);
    ra[k] = now[k] - (di[DELTA_A + k] - dj[DELTA_A + k]);
  }
  const double rb2 = dot(rb, rb), ra2 = dot(ra, ra);
  if (rb2 < set.near_cutoff * set.near_cutoff || ra2 == 0.0) return;
  gcfmm::FieldTerms<double> b, a;
  gcfmm::charge_terms<false>(1.0, rb[0], rb[1], rb[2], 1.0 / std::sqrt(rb2), b);
  gcfmm::charge_terms<false>(1.0, ra[0], ra[1], ra[2], 1.0 / std::sqrt(ra2), a);
  change[0] = b.ex - a.ex;
  change[1] = b.ey - a.ey;
  change[2] = b.ez - a.ez;
  change[3] = b.pot - a.pot;
}

void CoulFMMTimeStepping::displacements(const double xu[3], const double *state, double *delta)
{
  for (int k = 0; k < 3; k++) {
    delta[DELTA_E + k] = xu[k] - state[X + k];
    delta[DELTA_A + k] = xu[k] - state[SLOPE_A + k];
    delta[DELTA_B + k] = xu[k] - state[SLOPE_B + k];
  }
  delta[DELTA_IN_SLOPE] = state[IN_SLOPE];
  delta[DELTA_Q] = state[Q];
  delta[DELTA_STATIC] = state[ASLEEP];
}

/* ----------------------------------------------------------------------
   doc/theory.md, eq. (5.6): a change dq at distance r >= rc makes a field C |dq| / r^2 <=
   C |dq| / rc^2 at any atom (the pairs closer than rc are refreshed exactly); with x and y
   periodic the images of the changes add, far from them, the sheet field of their net change
------------------------------------------------------------------------- */

double CoulFMMTimeStepping::absorbed_far_bound(double qqrd2e, double sum_abs_dq, double net_dq,
                                               double rc, double area)
{
  double bound = std::fabs(qqrd2e) * sum_abs_dq / (rc * rc);
  if (area > 0.0) bound += 2.0 * M_PI * std::fabs(qqrd2e) * std::fabs(net_dq) / area;
  return bound;
}

void CoulFMMTimeStepping::set_field_scale(const double sums[2])
{
  scale = sums[1] > 0.0 ? std::sqrt(sums[0] / sums[1]) : 0.0;
}

void CoulFMMTimeStepping::add_error_sums(double q2, const double *applied, const double *reference,
                                         double sums[2])
{
  for (int k = 0; k < 3; k++) {
    sums[0] += q2 * (applied[k] - reference[k]) * (applied[k] - reference[k]);
    sums[1] += q2 * reference[k] * reference[k];
  }
}

double CoulFMMTimeStepping::relative_rms(const double sums[2])
{
  return sums[1] > 0.0 ? std::sqrt(sums[0] / sums[1]) : 0.0;
}

void CoulFMMTimeStepping::record_check(const double sums[2])
{
  last_check = relative_rms(sums);
  if (last_check > max_check) max_check = last_check;
  check_sums[0] += sums[0];
  check_sums[1] += sums[1];
}

// weighted by the field, unlike the largest, which a check at a nearly vanishing field can
// dominate
double CoulFMMTimeStepping::check_overall() const
{
  return relative_rms(check_sums);
}

bool CoulFMMTimeStepping::same_setting(int boundary, double qqrd2e, const double box[4],
                                       bool periodic) const
{
  if (evaluated.step < 0 || boundary != evaluated.boundary || qqrd2e != evaluated.qqrd2e)
    return false;
  if (periodic)
    for (int k = 0; k < 4; k++)
      if (box[k] != evaluated.box[k]) return false;
  return true;
}

CoulFMMTimeStepping::Continuity CoulFMMTimeStepping::continuity(const uint64_t sums[4]) const
{
  if (sums[0] != evaluated.charges || sums[2] != 0) return Continuity::NONE;
  return sums[1] == 0 && sums[3] == 0 ? Continuity::SAME : Continuity::ADDED;
}

namespace {
// the restart list starts with this marker (older files start with the step of the last
// evaluation, >= -1, and hold no charge checksum; files marked -2 hold no field scale)
constexpr double kRestartFormat = -3.0, kRestartFormatNoScale = -2.0;
enum : int {
  R_FORMAT,
  R_LAST,
  R_BOX,
  R_EVERY = R_BOX + 4,
  R_TOLERANCE,
  R_STRIDE,
  R_SLOPE,
  R_SUM_HI,
  R_SUM_LO,
  R_QQRD2E,
  R_BOUNDARY,
  R_SCALE,
  R_SIZE
};
static_assert(R_SIZE == CoulFMMTimeStepping::RESTART_SIZE, "restart list size");
}    // namespace

void CoulFMMTimeStepping::write_restart(double list[RESTART_SIZE]) const
{
  list[R_FORMAT] = kRestartFormat;
  list[R_LAST] = (double) evaluated.step;
  for (int k = 0; k < 4; k++) list[R_BOX + k] = evaluated.box[k];
  list[R_EVERY] = set.every;
  list[R_TOLERANCE] = set.tolerance;
  list[R_STRIDE] = interval;
  list[R_SLOPE] = slope_steps;
  // the 64-bit checksum as two 32-bit halves (exact in doubles)
  list[R_SUM_HI] = (double) (evaluated.charges >> 32);
  list[R_SUM_LO] = (double) (evaluated.charges & 0xffffffffULL);
  list[R_QQRD2E] = evaluated.qqrd2e;
  list[R_BOUNDARY] = evaluated.boundary;
  list[R_SCALE] = scale;
}

bool CoulFMMTimeStepping::read_restart(const double *list)
{
  // a different every or tolerance gives a different schedule
  if (list[R_FORMAT] != kRestartFormat && list[R_FORMAT] != kRestartFormatNoScale) return false;
  if ((int) list[R_EVERY] != set.every || list[R_TOLERANCE] != set.tolerance) return false;
  interval = (int) list[R_STRIDE];
  slope_steps = list[R_SLOPE];
  evaluated.step = (int64_t) list[R_LAST];
  for (int k = 0; k < 4; k++) evaluated.box[k] = list[R_BOX + k];
  evaluated.charges = ((uint64_t) list[R_SUM_HI] << 32) | (uint64_t) list[R_SUM_LO];
  evaluated.qqrd2e = list[R_QQRD2E];
  evaluated.boundary = (int) list[R_BOUNDARY];
  // without it the first absorbed change forces an evaluation
  scale = list[R_FORMAT] == kRestartFormat ? list[R_SCALE] : 0.0;
  return true;
}
