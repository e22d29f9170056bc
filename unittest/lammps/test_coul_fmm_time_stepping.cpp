// Unit tests of fix coul/fmm's multiple time stepping (coul_fmm_time_stepping.h) alone, without
// a LAMMPS instance: the schedule and its adaptation (doc/theory.md, eq. (5.4)), the linear
// extrapolation of the far part (eq. (5.2)) on fields with a closed-form time dependence, the
// near-pair change (eq. (5.3)) against K(r) = r / |r|^3 evaluated directly, the error measure,
// the continuity rules and the restart list.

#include "coul_fmm_time_stepping.h"

#include "gtest/gtest.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

using LAMMPS_NS::CoulFMMTimeStepping;
using MTS = CoulFMMTimeStepping;

namespace {

MTS::Settings settings(int every, double tolerance = 0.0, bool extrapolate = true, double near = 0.0)
{
  MTS::Settings s;
  s.every = every;
  s.tolerance = tolerance;
  s.extrapolate = extrapolate;
  s.near_cutoff = near;
  return s;
}

std::string error_of(const MTS::Settings &s)
{
  try {
    MTS m(s);
  } catch (std::invalid_argument &e) {
    return e.what();
  }
  return "";
}

// one evaluation of a single atom at `step` whose exact field is `exact` (4 values), as the fix
// does it: plan, begin, write the field, end, finish; returns the prediction it measured
std::vector<double> evaluate(MTS &m, std::vector<double> &row, int64_t step, const double exact[4],
                             MTS::Continuity c)
{
  const MTS::Plan p = m.plan(c, true, step);
  const double xu[3] = {0.0, 0.0, 0.0};
  std::vector<double> predicted(4);
  m.begin_evaluation(p, row.data(), xu, 1.0, false, nullptr, nullptr, predicted.data());
  m.evaluated.step = step;
  for (int k = 0; k < 4; k++) row[MTS::FIELD + k] = exact[k];
  double sums[2] = {0.0, 0.0};
  m.end_evaluation(p, row.data(), predicted.data(), sums);
  m.finish_evaluation(p, MTS::relative_rms(sums));
  return predicted;
}

void kernel(const double r[3], double g[4])
{
  const double d = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
  for (int k = 0; k < 3; k++) g[k] = r[k] / (d * d * d);
  g[3] = 1.0 / d;
}

}    // namespace

TEST(CoulFMMTimeStepping, SettingsAreValidatedOnce)
{
  EXPECT_EQ(error_of(settings(0)), "every must be >= 1, got 0");
  EXPECT_EQ(error_of(settings(8, -1e-4)), "tolerance must be in [0, 1), got -0.0001");
  EXPECT_EQ(error_of(settings(8, 1.0)), "tolerance must be in [0, 1), got 1");
  EXPECT_EQ(error_of(settings(1, 1e-4)),
            "tolerance 0.0001 needs every > 1 (the largest evaluation interval)");
  EXPECT_EQ(error_of(settings(8, 0.0, true, -1.0)), "near cutoff must be >= 0, got -1");
  MTS::Settings s = settings(8);
  s.check_every = -1;
  EXPECT_EQ(error_of(s), "check must be >= 0, got -1");
  EXPECT_EQ(error_of(settings(8, 1e-4, true, 2.0)), "");
  // with a tolerance the largest interval is the power of two at or below every
  EXPECT_EQ(MTS(settings(12, 1e-4)).settings().every, 8);
  EXPECT_EQ(MTS(settings(12)).settings().every, 12);
  EXPECT_EQ(MTS(settings(12, 1e-4)).stride(), 1);
  EXPECT_EQ(MTS(settings(12)).stride(), 12);
}

TEST(CoulFMMTimeStepping, ScheduleOnMultiplesOfTheInterval)
{
  MTS m(settings(4));
  EXPECT_TRUE(m.scheduled(3));    // no evaluation yet
  m.evaluated.step = 3;
  EXPECT_FALSE(m.scheduled(3));
  EXPECT_TRUE(m.scheduled(4));
  EXPECT_FALSE(m.scheduled(5));
  EXPECT_TRUE(m.scheduled(8));
  m.restart_schedule();
  EXPECT_TRUE(m.scheduled(5));
}

// eq. (5.4): the error grows by 4 per doubling with extrapolation (2 without)
TEST(CoulFMMTimeStepping, AdaptHalvesAndDoubles)
{
  MTS m(settings(16, 1e-3));
  EXPECT_EQ(m.stride(), 1);
  m.adapt(1e-4);    // 4e-4 < 5e-4: double
  EXPECT_EQ(m.stride(), 2);
  m.adapt(1.3e-4);    // 5.2e-4 >= 5e-4: stay
  EXPECT_EQ(m.stride(), 2);
  m.adapt(1e-5);
  m.adapt(1e-5);
  m.adapt(1e-5);
  EXPECT_EQ(m.stride(), 16);
  m.adapt(1e-5);    // never beyond every
  EXPECT_EQ(m.stride(), 16);
  m.adapt(2e-2);    // 2e-2 -> /4 5e-3 -> /4 1.25e-3 -> /4 3.1e-4 <= 1e-3: three halvings
  EXPECT_EQ(m.stride(), 2);
  EXPECT_DOUBLE_EQ(m.last_estimate(), 2e-2);
  MTS linear(settings(16, 1e-3, false));
  linear.adapt(2e-4);    // growth 2: 4e-4 < 5e-4
  EXPECT_EQ(linear.stride(), 2);
  linear.adapt(2e-3);    // 2e-3 -> /2 1e-3 <= 1e-3: one halving
  EXPECT_EQ(linear.stride(), 1);
}

// a field linear in time is extrapolated exactly once a slope exists; a quadratic one
// E = c t^2 evaluated at 0, s and 2s is predicted at 2s as E(s) + s (E(s) - E(0)) / s = 2 c s^2
// against 4 c s^2: relative error 1/2
TEST(CoulFMMTimeStepping, ExtrapolationOfClosedFormFields)
{
  const int s = 8;
  MTS m(settings(s));
  std::vector<double> row(MTS::COLS, 0.0);
  auto linear = [](double t, double e[4]) {
    for (int k = 0; k < 4; k++) e[k] = (k + 1.0) + (0.5 - k) * t;
  };
  double e[4];
  linear(0, e);
  evaluate(m, row, 0, e, MTS::Continuity::NONE);
  linear(s, e);
  evaluate(m, row, s, e, MTS::Continuity::SAME);
  EXPECT_DOUBLE_EQ(m.slope_interval(), s);
  double pred[4];
  for (int t = s + 1; t < 2 * s; t++) {
    m.predict(row.data(), t - s, nullptr, pred);
    linear(t, e);
    for (int k = 0; k < 4; k++) EXPECT_NEAR(pred[k], e[k], 1e-14 * (1 + std::fabs(e[k])));
  }
  linear(2 * s, e);
  evaluate(m, row, 2 * s, e, MTS::Continuity::SAME);
  EXPECT_LT(m.last_estimate(), 1e-15);

  MTS q(settings(s));
  std::vector<double> qrow(MTS::COLS, 0.0);
  auto quadratic = [](double t, double e4[4]) {
    for (int k = 0; k < 4; k++) e4[k] = 0.01 * (k + 1.0) * t * t;
  };
  for (int t = 0; t <= 2 * s; t += s) {
    quadratic(t, e);
    const auto p = evaluate(q, qrow, t, e, t == 0 ? MTS::Continuity::NONE : MTS::Continuity::SAME);
    if (t == 2 * s)
      for (int k = 0; k < 4; k++) EXPECT_NEAR(p[k], 0.5 * e[k], 1e-12 * e[k]);
  }
  EXPECT_NEAR(q.last_estimate(), 0.5, 1e-12);
  // without extrapolation the field is held: the error at 2s is 1 - 1/4
  MTS held(settings(s, 0.0, false));
  std::vector<double> hrow(MTS::COLS, 0.0);
  for (int t = 0; t <= 2 * s; t += s) {
    quadratic(t, e);
    evaluate(held, hrow, t, e, t == 0 ? MTS::Continuity::NONE : MTS::Continuity::SAME);
  }
  EXPECT_NEAR(held.last_estimate(), 0.75, 1e-12);
}

// the slope is kept for added charges (only the new ones start without), zeroed when nothing
// continues, and a static source carries none
TEST(CoulFMMTimeStepping, SlopeKeptZeroedOrDropped)
{
  MTS m(settings(4));
  std::vector<double> row(MTS::COLS, 0.0);
  double e[4] = {1, 2, 3, 4};
  evaluate(m, row, 0, e, MTS::Continuity::NONE);
  double e2[4] = {2, 4, 6, 8};
  evaluate(m, row, 4, e2, MTS::Continuity::SAME);
  EXPECT_DOUBLE_EQ(row[MTS::SLOPE + 0], 0.25);
  EXPECT_EQ(row[MTS::IN_SLOPE], 1.0);
  // an insertion after 2 steps: a shortened interval keeps the slope (no new one)
  evaluate(m, row, 6, e2, MTS::Continuity::ADDED);
  EXPECT_DOUBLE_EQ(row[MTS::SLOPE + 0], 0.25);
  evaluate(m, row, 7, e2, MTS::Continuity::NONE);
  EXPECT_EQ(row[MTS::SLOPE + 0], 0.0);
  EXPECT_EQ(row[MTS::IN_SLOPE], 0.0);
  row[MTS::SLOPE + 1] = 3.0;
  const MTS::Plan p = m.plan(MTS::Continuity::ADDED, true, 8);
  const double xu[3] = {1, 2, 3};
  double pred[4];
  m.begin_evaluation(p, row.data(), xu, 1.0, true, nullptr, nullptr, pred);
  EXPECT_EQ(row[MTS::SLOPE + 1], 0.0);
  EXPECT_EQ(row[MTS::ASLEEP], 1.0);
  EXPECT_EQ(row[MTS::X + 2], 3.0);
  // a minimizer step continues nothing
  EXPECT_FALSE(m.plan(MTS::Continuity::SAME, false, 9).same);
}

// eq. (5.3) against the kernel evaluated at both ends
TEST(CoulFMMTimeStepping, NearPairChangeIsTheKernelDifference)
{
  MTS m(settings(8, 0.0, true, 2.0));
  std::vector<double> di(MTS::DELTA_COLS, 0.0), dj(MTS::DELTA_COLS, 0.0);
  const double now[3] = {0.9, -0.4, 0.3};
  // i moved by (0.2, 0.1, -0.1), j by (-0.1, 0, 0.05) since the evaluation
  const double mi[3] = {0.2, 0.1, -0.1}, mj[3] = {-0.1, 0.0, 0.05};
  for (int k = 0; k < 3; k++) {
    di[MTS::DELTA_E + k] = mi[k];
    dj[MTS::DELTA_E + k] = mj[k];
  }
  double then[3], gn[4], gt[4], dg[4];
  for (int k = 0; k < 3; k++) then[k] = now[k] - (mi[k] - mj[k]);
  kernel(now, gn);
  kernel(then, gt);
  ASSERT_TRUE(m.near_pair_change(now, di.data(), dj.data(), 0.0, dg));
  for (int k = 0; k < 4; k++) EXPECT_NEAR(dg[k], gn[k] - gt[k], 1e-14);
  // beyond the cutoff now and then: not refreshed; closer only then: refreshed between
  // evaluations (trend >= 0) but not in the D of a slope (trend < 0)
  const double far[3] = {2.5, 0.0, 0.0};
  EXPECT_FALSE(m.near_pair_change(far, di.data(), dj.data(), 0.0, dg));
  std::vector<double> dmove(MTS::DELTA_COLS, 0.0);
  dmove[MTS::DELTA_E] = 1.0;    // then at distance 1.5
  EXPECT_TRUE(m.near_pair_change(far, dmove.data(), dj.data(), 0.0, dg));
  EXPECT_FALSE(m.near_pair_change(far, dmove.data(), dj.data(), -1.0, dg));
  // trend: a pair beyond the cutoff at the slope's later end has its trend in the slope, which
  // is taken out times the trend factor
  for (int k = 0; k < 3; k++) {
    di[MTS::DELTA_B + k] = k == 0 ? -2.0 : 0.0;    // r_B = now - (-2, 0, 0): beyond 2
    di[MTS::DELTA_A + k] = k == 0 ? -2.5 : 0.0;
  }
  di[MTS::DELTA_IN_SLOPE] = dj[MTS::DELTA_IN_SLOPE] = 1.0;
  double rb[3] = {now[0] + 2.0, now[1], now[2]}, ra[3] = {now[0] + 2.5, now[1], now[2]};
  double gb[4], ga[4];
  kernel(rb, gb);
  kernel(ra, ga);
  ASSERT_TRUE(m.near_pair_change(now, di.data(), dj.data(), 0.5, dg));
  for (int k = 0; k < 4; k++) EXPECT_NEAR(dg[k], gn[k] - gt[k] - 0.5 * (gb[k] - ga[k]), 1e-14);
}

TEST(CoulFMMTimeStepping, ErrorMeasure)
{
  double sums[2] = {0.0, 0.0};
  const double applied[3] = {1.0, 2.0, 2.0}, reference[3] = {1.0, 2.0, 3.0};
  MTS::add_error_sums(4.0, applied, reference, sums);
  EXPECT_DOUBLE_EQ(sums[0], 4.0);
  EXPECT_DOUBLE_EQ(sums[1], 56.0);
  EXPECT_DOUBLE_EQ(MTS::relative_rms(sums), std::sqrt(4.0 / 56.0));
  const double none[2] = {1.0, 0.0};
  EXPECT_EQ(MTS::relative_rms(none), 0.0);
  MTS m(settings(4));
  const double a[2] = {1.0, 4.0}, b[2] = {1.0, 100.0};
  m.record_check(a);
  m.record_check(b);
  EXPECT_DOUBLE_EQ(m.check_last(), 0.1);
  EXPECT_DOUBLE_EQ(m.check_max(), 0.5);
  EXPECT_DOUBLE_EQ(m.check_overall(), std::sqrt(2.0 / 104.0));
}

TEST(CoulFMMTimeStepping, ContinuityRules)
{
  MTS m(settings(4));
  const double box[4] = {0, 0, 10, 10};
  EXPECT_FALSE(m.same_setting(1, 1.0, box, true));    // no evaluation yet
  m.evaluated = {5, {0, 0, 10, 10}, 77, 1.0, 1};
  EXPECT_TRUE(m.same_setting(1, 1.0, box, true));
  EXPECT_FALSE(m.same_setting(0, 1.0, box, true));
  EXPECT_FALSE(m.same_setting(1, 2.0, box, true));
  const double other[4] = {0, 0, 10, 11};
  EXPECT_FALSE(m.same_setting(1, 1.0, other, true));
  EXPECT_TRUE(m.same_setting(1, 1.0, other, false));    // free space: the box does not matter
  const uint64_t same[4] = {77, 0, 0, 0}, added[4] = {77, 3, 0, 0}, woken[4] = {77, 0, 0, 2},
                 changed[4] = {77, 1, 1, 0}, left[4] = {76, 0, 0, 0};
  EXPECT_EQ(m.continuity(same), MTS::Continuity::SAME);
  EXPECT_EQ(m.continuity(added), MTS::Continuity::ADDED);
  EXPECT_EQ(m.continuity(woken), MTS::Continuity::ADDED);
  EXPECT_EQ(m.continuity(changed), MTS::Continuity::NONE);
  EXPECT_EQ(m.continuity(left), MTS::Continuity::NONE);
  // the checksum does not depend on the order of the atoms, and sees a changed charge
  using LAMMPS_NS::coul_fmm_charge_hash;
  EXPECT_EQ(coul_fmm_charge_hash(1, 0.5) + coul_fmm_charge_hash(2, -1.0),
            coul_fmm_charge_hash(2, -1.0) + coul_fmm_charge_hash(1, 0.5));
  EXPECT_NE(coul_fmm_charge_hash(1, 0.5), coul_fmm_charge_hash(1, 0.5000000001));
  EXPECT_NE(coul_fmm_charge_hash(1, 0.5), coul_fmm_charge_hash(2, 0.5));
}

TEST(CoulFMMTimeStepping, RestartListRoundTrip)
{
  MTS m(settings(16, 1e-3));
  m.adapt(1e-5);
  m.adapt(1e-5);
  m.evaluated = {1234, {-1, -2, 10, 11}, 0xfedcba9876543210ULL, 332.06371, 1};
  double list[MTS::RESTART_SIZE];
  m.write_restart(list);
  MTS r(settings(16, 1e-3));
  ASSERT_TRUE(r.read_restart(list));
  EXPECT_EQ(r.stride(), 4);
  EXPECT_EQ(r.evaluated.step, 1234);
  EXPECT_EQ(r.evaluated.charges, 0xfedcba9876543210ULL);
  EXPECT_EQ(r.evaluated.qqrd2e, 332.06371);
  EXPECT_EQ(r.evaluated.box[3], 11.0);
  EXPECT_EQ(r.evaluated.boundary, 1);
  // other settings: a different schedule, nothing restored
  MTS other(settings(8, 1e-3));
  EXPECT_FALSE(other.read_restart(list));
  EXPECT_EQ(other.evaluated.step, -1);
  list[0] = 5.0;    // an older file starts with the step
  EXPECT_FALSE(r.read_restart(list));
}

// eq. (5.5): a refreshed pair whose charges changed sums q(now) (K, 1/r)(r_now) - q(then)
// (K, 1/r)(r_then) at both atoms: the near-pair change times the charges now plus the charge
// change at the separation then, against the kernel evaluated directly (1e-14: a few ulps of
// terms of order 1)
TEST(CoulFMMTimeStepping, ChangedChargesOfAPairAtTheSeparationThen)
{
  const double now[3] = {0.9, -0.4, 0.3}, then[3] = {0.6, -0.5, 0.45};
  const double qi_then = 0.7, qj_then = -1.1, qi = 0.75, qj = -1.3;
  double gn[4], gt[4];
  kernel(now, gn);
  kernel(then, gt);
  double at_i[4], at_j[4];
  for (int k = 0; k < 4; k++) {
    at_i[k] = qj * (gn[k] - gt[k]);
    at_j[k] = (k < 3 ? -1.0 : 1.0) * qi * (gn[k] - gt[k]);    // K(-r) = -K(r), 1/r even
  }
  MTS::add_charge_change(qi - qi_then, qj - qj_then, gt, at_i, at_j);
  for (int k = 0; k < 4; k++) {
    const double sign = k < 3 ? -1.0 : 1.0;
    EXPECT_NEAR(at_i[k], qj * gn[k] - qj_then * gt[k], 1e-14);
    EXPECT_NEAR(at_j[k], sign * (qi * gn[k] - qi_then * gt[k]), 1e-14);
  }
  // unchanged charges add nothing, bit for bit; a ghost j (at_j null) gets nothing
  double same[4] = {1.0, 2.0, 3.0, 4.0};
  MTS::add_charge_change(0.0, 0.0, gt, same, nullptr);
  EXPECT_EQ(same[0], 1.0);
  EXPECT_EQ(same[3], 4.0);
}

// eq. (5.6): the bound of the changes' field beyond the near cutoff, and the rule that forces
// an evaluation against tau times the field scale of the last evaluation
TEST(CoulFMMTimeStepping, AbsorbedFarBound)
{
  // C sum |dq| / rc^2, plus 2 pi C |sum dq| / (Lx Ly) with x and y periodic
  EXPECT_DOUBLE_EQ(MTS::absorbed_far_bound(2.0, 0.3, 0.1, 4.0, 0.0), 2.0 * 0.3 / 16.0);
  EXPECT_DOUBLE_EQ(MTS::absorbed_far_bound(2.0, 0.3, -0.1, 4.0, 50.0),
                   2.0 * 0.3 / 16.0 + 2.0 * M_PI * 2.0 * 0.1 / 50.0);
  MTS m(settings(8, 1e-3, true, 4.0));
  m.set_absorbing(true, 1e-3);
  EXPECT_TRUE(m.absorbs());
  // unknown scale (no evaluation yet): any change forces an evaluation
  EXPECT_TRUE(m.far_part_exceeds(1e-30));
  // two charges 2 and 1 with fields 3 and 4: sqrt((4*9 + 1*16) / 5)
  const double sums[2] = {4.0 * 9.0 + 16.0, 5.0};
  m.set_field_scale(sums);
  EXPECT_DOUBLE_EQ(m.field_scale(), std::sqrt(52.0 / 5.0));
  EXPECT_FALSE(m.far_part_exceeds(0.99e-3 * m.field_scale()));
  EXPECT_TRUE(m.far_part_exceeds(1.01e-3 * m.field_scale()));
  // the scale is part of the restart list; a file of the format before it restores none
  double list[MTS::RESTART_SIZE];
  m.write_restart(list);
  MTS r(settings(8, 1e-3, true, 4.0));
  ASSERT_TRUE(r.read_restart(list));
  EXPECT_EQ(r.field_scale(), m.field_scale());
  list[0] = -2.0;
  ASSERT_TRUE(r.read_restart(list));
  EXPECT_EQ(r.field_scale(), 0.0);
  // no charge: scale 0, not a division by zero
  const double none[2] = {0.0, 0.0};
  m.set_field_scale(none);
  EXPECT_EQ(m.field_scale(), 0.0);
  // counts of the fix's vector and of a run
  m.count_absorbed(3.0);
  m.count_forced();
  m.start_run_counts();
  m.count_absorbed(2.0);
  EXPECT_EQ(m.absorbed_total().changes, 5.0);
  EXPECT_EQ(m.absorbed_total().forced, 1.0);
  EXPECT_EQ(m.absorbed_this_run().changes, 2.0);
  EXPECT_EQ(m.absorbed_this_run().forced, 0.0);
}
