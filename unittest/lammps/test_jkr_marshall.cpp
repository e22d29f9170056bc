/* GRANULAR-CHARGED: jkr/marshall and companions (pair_style granular, fix wall/gran),
   tested against the closed forms of doc/theory.md, eqs. (1.2)-(1.9) (JKR relations written again,
   independently, in gc_testing.h). Units si: r_p = 1 um, E = 2e8 Pa, nu = 0.33,
   gamma = 0.01 J/m^2, rho = 2500 kg/m^3 (the paper's Table 1). */
#include "gc_testing.h"
#include "jkr_scaled.h"

#include "exceptions.h"
#include "gtest/gtest.h"

#include <cmath>
#include <regex>
#include <string>
#include <vector>

using gctest::JKR;
using gctest::Lmp;
using gctest::error_of;

namespace {

constexpr double RP = 1.0e-6, EMOD = 2.0e8, NU = 0.33, GAMMA = 0.01, RHO = 2500.0, MU = 0.3;
const double ESTAR_PAIR = EMOD / (2.0 * (1.0 - NU * NU));     // E* of two like spheres
const double GSTAR_PAIR = EMOD / (4.0 * (2.0 - NU) * (1.0 + NU));
const double MASS = 4.0 / 3.0 * M_PI * RP * RP * RP * RHO;

std::string contact_model(double e, double gamma = GAMMA, const std::string &extra = "",
                          const std::string &damping = "marshall")
{
  return fmt::format("jkr/marshall {} {} {} {} damping {} tangential marshall {} {}", EMOD, e, NU,
                     gamma, damping, MU, extra);
}

// two spheres on the x axis: atom 1 at the origin, atom 2 at x = gap + 2 r_p
void two_spheres(Lmp &l, double e, const std::string &extra = "", double gamma = GAMMA,
                 const std::string &newton = "off", const std::string &damping = "marshall")
{
  l.cmds({"units si", "atom_style sphere", "atom_modify map array", "boundary f f f",
          "newton " + newton, "comm_modify vel yes",
          "region box block -1e-5 1e-5 -1e-5 1e-5 -1e-5 1e-5", "create_box 1 box",
          "create_atoms 1 single 0 0 0", fmt::format("create_atoms 1 single {} 0 0", 2 * RP),
          fmt::format("set type 1 diameter {}", 2 * RP), fmt::format("set type 1 density {}", RHO),
          "pair_style granular", "pair_coeff * * " + contact_model(e, gamma, extra, damping),
          "neighbor 2e-7 bin", "timestep 1e-10"});
}

// place atom 2 at overlap delta and evaluate forces without moving anything
double force_at(Lmp &l, double delta)
{
  l.cmd(fmt::format("set atom 2 x {:.17g}", 2 * RP - delta));
  l.cmd("run 0 post no");
  return -l.var("fx[1]");    // > 0 repulsive: force on atom 1 points to -x
}

}    // namespace

// 1. quasi-static loading/unloading; contact hysteresis; the three check points
TEST(JKRMarshall, QuasiStaticCheckPoints)
{
  Lmp l;
  two_spheres(l, 1.0);
  const JKR jkr{RP / 2, ESTAR_PAIR, GAMMA};
  const double FC = jkr.FC(), dC = jkr.deltaC();

  // the test-side closed forms themselves hit the check points of doc/theory.md, eq. (1.4)
  EXPECT_NEAR(JKR::delta_of_ahat(1.0), 1.21141, 5e-6);
  EXPECT_NEAR(JKR::delta_of_ahat(std::pow(2.0, -2.0 / 3.0)), -0.48075, 5e-6);
  EXPECT_NEAR(JKR::delta_of_ahat(std::pow(6.0, -2.0 / 3.0)), -1.0, 1e-12);
  EXPECT_NEAR(JKR::force_of_ahat(std::pow(6.0, -2.0 / 3.0)), -5.0 / 9.0, 1e-12);

  // approach: no contact for delta < 0
  for (double dd : {-0.9, -0.5, -0.1, -1e-3}) EXPECT_EQ(force_at(l, dd * dC), 0.0) << dd;
  // contact forms at delta = 0 (JKR snap-in: a = (2/3)^(2/3) a_0, F < 0)
  EXPECT_NEAR(force_at(l, 1e-9 * dC) / FC, JKR::force_of_ahat(std::pow(2.0 / 3.0, 2.0 / 3.0)), 1e-6);
  // loading then unloading through the check points: 1e-6 relative to F_C is what the closed
  // form of the contact radius (double precision, cube and square roots) delivers away from the
  // double root at separation.
  for (double dd : {0.5, 2.0, 3.0}) EXPECT_NEAR(force_at(l, dd * dC) / FC, jkr.force(dd * dC) / FC, 1e-6);
  const double zero_load = JKR::delta_of_ahat(1.0);
  const double pull_off = JKR::delta_of_ahat(std::pow(2.0, -2.0 / 3.0));
  EXPECT_NEAR(force_at(l, zero_load * dC) / FC, 0.0, 1e-6);
  EXPECT_NEAR(force_at(l, pull_off * dC) / FC, -1.0, 1e-6);
  EXPECT_NEAR(force_at(l, -0.9 * dC) / FC, jkr.force(-0.9 * dC) / FC, 1e-6);
  // just before separation: F -> -5/9 F_C; near the double root a - a_min ~ sqrt(1 - |delta|/delta_C),
  // so at 1 - 1e-10 the force is within ~1e-4 F_C of -5/9
  EXPECT_NEAR(force_at(l, -(1.0 - 1e-10) * dC) / FC, -5.0 / 9.0, 1e-4);
  // beyond delta_C the contact is gone, and does not re-form in tension
  EXPECT_EQ(force_at(l, -1.001 * dC), 0.0);
  EXPECT_EQ(force_at(l, -0.5 * dC), 0.0);
  EXPECT_NE(force_at(l, 0.1 * dC), 0.0);
}

// 1b. the scaled root that jkr/marshall solves for its contact radius (jkr_scaled.h): table
// plus Newton steps against bisection, over the table (u = sqrt(Delta + 1) < 16) and beyond.
// Away from separation both are exact to ~1 ulp (tolerance 4e-15 relative). Near Delta = -1,
// s - 1 ~ sqrt((Delta + 1) / 2) and the residual s^4 - 4 s - 3 Delta can only be evaluated to
// ~1e-15 absolute, so any double-precision root is uncertain by ~1e-15 / (12 (s - 1)).
TEST(JKRMarshall, ScaledRootAgreesWithBisection)
{
  using LAMMPS_NS::JKRScaled::root;
  using LAMMPS_NS::JKRScaled::root_by_bisection;
  EXPECT_EQ(root(-1.0), 1.0);
  EXPECT_EQ(root(-2.0), 1.0);    // clamped: the branch ends at separation
  for (int k = 0; k <= 20000; ++k) {
    const double Delta = -1.0 + std::pow(10.0, -12.0 + 17.0 * k / 20000.0);    // up to 1e5
    const double s = root(Delta), sb = root_by_bisection(Delta);
    const double tol = 4e-15 * sb + 2e-15 / (12.0 * (sb - 1.0));
    ASSERT_NEAR(s, sb, tol) << "Delta = " << Delta;
    // and the law itself: s solves s^4 - 4 s = 3 Delta to rounding of its terms
    ASSERT_NEAR(s * s * s * s - 4.0 * s, 3.0 * Delta, 1e-14 * (std::fabs(3.0 * Delta) + 4.0 * s));
  }
  // F / F_C at separation (s = 1), zero load and pull-off (s^3 = 3): the check points of
  // doc/theory.md, eq. (1.4)
  EXPECT_NEAR(LAMMPS_NS::JKRScaled::force_over_fc(1.0), -5.0 / 9.0, 1e-15);
  EXPECT_NEAR(LAMMPS_NS::JKRScaled::force_over_fc(std::cbrt(3.0)), -1.0, 1e-15);
  EXPECT_NEAR(LAMMPS_NS::JKRScaled::force_over_fc(std::cbrt(6.0)), 0.0, 1e-15);
}

// 1b'. the batched root (JKRScaled::roots, the pair style's call) on each SIMD path (0 generic,
// 1 AVX2, 2 AVX-512; one this CPU lacks runs the generic path) gives root()'s double bit for bit:
// the pair style's forces, and the runs, must not depend on the path. Covered: the 1b range,
// separation and below (-1, -2, NaN: s = 1), both sides of the table's end (Delta = 255) and the
// asymptote, and every count 0-19 at every start offset 0-3 (vector remainders, unaligned data).
TEST(JKRMarshall, BatchedRootsAreTheScalarRoot)
{
  using LAMMPS_NS::JKRScaled::root;
  using LAMMPS_NS::JKRScaled::roots;
  std::vector<double> Delta{-2.0, -1.0, std::nan(""), -1.0 + 1e-300, 0.0, 1.0, 253.9, 254.0,
                            254.99999999999997, 255.0, 255.00000000000003, 256.0, 1e5};
  for (int k = 0; k <= 20000; ++k) Delta.push_back(-1.0 + std::pow(10.0, -12.0 + 17.0 * k / 20000.0));
  std::vector<double> expect(Delta.size());
  for (std::size_t k = 0; k < Delta.size(); ++k) expect[k] = root(Delta[k]);
  for (int path = 0; path <= 2; ++path) {
    std::vector<double> s(Delta.size(), -7.0);
    roots(Delta.size(), Delta.data(), s.data(), static_cast<gcsimd::SimdPath>(path));
    for (std::size_t k = 0; k < Delta.size(); ++k)
      ASSERT_EQ(s[k], expect[k]) << "path " << path << ", Delta = " << Delta[k];
    for (std::size_t start = 0; start < 4; ++start)
      for (std::size_t n = 0; n < 20; ++n) {
        std::vector<double> part(n + 1, -7.0);
        roots(n, &Delta[start], part.data(), static_cast<gcsimd::SimdPath>(path));
        for (std::size_t k = 0; k < n; ++k) ASSERT_EQ(part[k], expect[start + k]);
        ASSERT_EQ(part[n], -7.0);    // nothing written past n
      }
  }
}

// 1c. the pair force along the stable branch, from separation to ~150 delta_C (an overlap of
// 0.6 r_p here; the root's asymptotic branch beyond Delta = 255 is covered by 1b), against the
// test's own closed forms in a-hat. The overlap is set through positions: 2 r_p - delta is rounded to ~4e-22 m, i.e.
// ~1.3e-13 delta_C, which moves F by up to ~1e-13 F_C / sqrt(Delta + 1) (dF/ds = -4/3 F_C and
// ds/dDelta = 1 / (2 sqrt(2 (Delta + 1))) at separation): the tolerance is twice that plus
// 1e-10 (1 + |F| / F_C) for the rounding of F.
TEST(JKRMarshall, ForceAlongTheStableBranch)
{
  Lmp l;
  two_spheres(l, 1.0);
  const JKR jkr{RP / 2, ESTAR_PAIR, GAMMA};
  const double FC = jkr.FC(), dC = jkr.deltaC();
  force_at(l, 2.0 * dC);    // the contact forms in compression, then lives in tension
  const double ah_sep = std::pow(6.0, -2.0 / 3.0);
  for (int k = 0; k <= 400; ++k) {
    const double ah = ah_sep * (1.0 + std::pow(10.0, -6.0 + 7.3 * k / 400.0));
    const double dd = JKR::delta_of_ahat(ah);
    const double expect = JKR::force_of_ahat(ah);
    const double tol = 2e-13 / std::sqrt(dd + 1.0) + 1e-10 * (1.0 + std::fabs(expect));
    ASSERT_NEAR(force_at(l, dd * dC) / FC, expect, tol)
        << "a-hat " << ah << ", delta/delta_C " << dd;
  }
}

// 2. pull-off: the largest tensile force on unloading is F_C = 3 pi gamma R
TEST(JKRMarshall, PullOffForce)
{
  Lmp l;
  two_spheres(l, 1.0);
  const JKR jkr{RP / 2, ESTAR_PAIR, GAMMA};
  force_at(l, 2.0 * jkr.deltaC());
  double fmin = 0.0;
  // fine sweep around the minimum; F is quadratic there, so a step of 1e-3 delta_C resolves
  // the minimum to ~1e-6 F_C
  for (double dd = 0.0; dd >= -0.99; dd -= 1e-3) fmin = std::min(fmin, force_at(l, dd * jkr.deltaC()));
  EXPECT_NEAR(fmin / (3.0 * M_PI * GAMMA * RP / 2), -1.0, 1e-5);
}

// 5. the wall: same law with R = r_p; pull-off 3 pi gamma r_p
// The same law against every wall form: the zplane wall of fix wall/gran and flat and curved
// walls of fix wall/gran/region. A flat wall is a sphere's partner of R = r_p; a region wall of
// curvature radius R_w (LAMMPS: negative inside a sphere region) gives R = r_p R_w / (r_p + R_w).
// The region wall asks the normal model for its search radius with pulloff_distance(r_p, 0),
// which used to give delta_C = 0: the contact let go at zero overlap (F = 0 for delta <= 0).
struct WallForm {
  const char *name;
  std::vector<std::string> commands;    // after create_box; the sphere sits at z_of(delta)
  double reff;                          // R of the contact
  double z_contact;                     // z of the sphere centre at delta = 0
  double z_sign;                        // +1: delta grows as z falls
};

class WallForceLaw : public ::testing::TestWithParam<int> {};

WallForm wall_form(int k)
{
  const std::string model = contact_model(1.0);
  const double rs = 4.0 * RP;    // sphere region: the sphere rests inside it, below its centre
  switch (k) {
    case 0:
      return {"zplane", {"fix floor all wall/gran granular " + model + " zplane 0.0 NULL"}, RP, RP, 1.0};
    case 1:
      return {"region plane",
              {"region floor plane 0 0 0 0 0 1 side in",
               "fix floor all wall/gran/region granular " + model + " region floor"},
              RP, RP, 1.0};
    case 2:
      return {"region block",
              {"region floor block INF INF INF INF 0 INF side in",
               "fix floor all wall/gran/region granular " + model + " region floor"},
              RP, RP, 1.0};
    default:
      return {"region sphere (inside, R_w = 4 r_p)",
              {"region bowl sphere 5e-6 5e-6 5e-6 4e-6 side in",
               "fix floor all wall/gran/region granular " + model + " region bowl"},
              RP * rs / (rs - RP), 5e-6 - (rs - RP), 1.0};
  }
}

TEST_P(WallForceLaw, AgreesWithTheClosedForm)
{
  const WallForm w = wall_form(GetParam());
  SCOPED_TRACE(w.name);
  Lmp l;
  l.cmds({"units si", "atom_style sphere", "atom_modify map array", "boundary p p f",
          "comm_modify vel yes", "region box block 0 1e-5 0 1e-5 0 1e-5", "create_box 1 box",
          fmt::format("create_atoms 1 single 5e-6 5e-6 {}", w.z_contact),
          fmt::format("set type 1 diameter {}", 2 * RP), fmt::format("set type 1 density {}", RHO),
          "pair_style granular", "pair_coeff * * " + contact_model(1.0), "neighbor 2e-7 bin",
          "timestep 1e-10"});
  l.cmds(w.commands);
  const JKR wall{w.reff, EMOD / (2.0 * (1.0 - NU * NU)), GAMMA};    // E* of like materials
  auto fz_at = [&](double delta) {
    l.cmd(fmt::format("set atom 1 z {:.17g}", w.z_contact - w.z_sign * delta));
    l.cmd("run 0 post no");
    return l.var("fz[1]");
  };
  EXPECT_EQ(fz_at(-0.5 * wall.deltaC()), 0.0);
  double fmin = 0.0;
  // 1e-6: the scaled root is good to a few ulps; the region's distance to its surface carries
  // the rounding of positions ~5e-6 m, 1e-16 relative, far below 1e-6 of delta_C ~ 4e-9 m
  for (double dd : {1.5, 1.0, 0.3, 0.0})
    EXPECT_NEAR(fz_at(dd * wall.deltaC()) / wall.FC(), wall.force(dd * wall.deltaC()) / wall.FC(), 1e-6);
  for (double dd = 0.0; dd >= -0.99; dd -= 1e-3) fmin = std::min(fmin, fz_at(dd * wall.deltaC()));
  EXPECT_NEAR(fmin / wall.FC(), -1.0, 1e-5);
  EXPECT_NEAR(fz_at(-(1.0 - 1e-10) * wall.deltaC()) / wall.FC(), -5.0 / 9.0, 1e-4);
  EXPECT_EQ(fz_at(-1.001 * wall.deltaC()), 0.0);
}

INSTANTIATE_TEST_SUITE_P(JKRMarshall, WallForceLaw, ::testing::Values(0, 1, 2, 3));

// ---- collisions ---------------------------------------------------------------------------

namespace {
struct Collision {
  double e_apparent;    // |v_rel after| / |v_rel before|
  double ke_before, ke_after;
  bool stuck;
};

Collision collide(double e, double v, double gamma = GAMMA, double dt = 2e-10,
                  const std::string &newton = "off", const std::string &damping = "marshall")
{
  Lmp l;
  two_spheres(l, e, "", gamma, newton, damping);
  l.cmd(fmt::format("set atom 2 x {:.17g}", 2 * RP + 1e-8));
  l.cmd(fmt::format("velocity all set NULL 0 0 units box"));
  l.cmd(fmt::format("set atom 1 vx {}", 0.5 * v));
  l.cmd(fmt::format("set atom 2 vx {}", -0.5 * v));
  l.cmds({"fix integrate all nve/sphere", fmt::format("timestep {}", dt),
          "compute ke all ke", "thermo_style custom step c_ke", "thermo 0", "run 0 post no"});
  Collision c{};
  c.ke_before = l.var("c_ke");
  // run until the spheres separate beyond the break distance, or long enough to call it stuck
  const double dC = JKR{RP / 2, ESTAR_PAIR, gamma}.deltaC();
  c.stuck = true;
  for (int chunk = 0; chunk < 400; ++chunk) {
    l.cmd("run 200 post no");
    if (l.var("x[2]-x[1]") > 2 * RP + 1.5 * dC + 1e-9 && l.var("vx[2]-vx[1]") > 0) {
      c.stuck = false;
      break;
    }
  }
  c.e_apparent = l.var("vx[2]-vx[1]") / v;
  c.ke_after = l.var("c_ke");
  return c;
}

// energy needed to pull a JKR contact from delta = 0 to -delta_C: -int F d(delta)
double separation_work(const JKR &jkr)
{
  const double amin = std::pow(6.0, -2.0 / 3.0), a0 = JKR::ahat_of_delta(0.0);
  double w = 0.0;
  const int n = 20000;
  for (int k = 0; k < n; ++k) {    // midpoint rule in a-hat: d(delta) = delta'(a) da
    const double a = amin + (k + 0.5) * (a0 - amin) / n;
    const double ddel = std::cbrt(6.0) * (4.0 * a - 2.0 / 3.0 / std::sqrt(a));
    w -= JKR::force_of_ahat(a) * ddel * (a0 - amin) / n;
  }
  return w * jkr.FC() * jkr.deltaC();
}
}    // namespace

// 3. head-on collisions: restitution tends to e above the sticking speed; capture below it
TEST(JKRMarshall, RestitutionAndCapture)
{
  // Inertia-dominated limit: gamma = 1e-3 J/m^2 and v = 50 m/s (~700x the capture speed).
  // The adhesive term of the JKR force decays only like (delta/delta_C)^(-3/4) ~ v^(-0.6),
  // so at the paper's gamma = 0.01 the apparent e stays below e even far above capture
  // (measured: e = 0.3 -> 0.278, 0.7 -> 0.690, 0.9 -> 0.897 at 50 m/s; table in the doc);
  // the 3% allowance covers the remaining adhesive deficit here (< 2.3% at e = 0.3).
  for (double e : {0.3, 0.7, 0.9}) {
    auto c = collide(e, 50.0, 1e-3, 2e-11);
    EXPECT_FALSE(c.stuck);
    EXPECT_NEAR(c.e_apparent / e, 1.0, 0.03) << "e = " << e;
    std::printf("[ restitution ] e = %.2f  v = 50 m/s  gamma = 1e-3  apparent e = %.4f\n", e, c.e_apparent);
  }
  // without adhesion the damping model reproduces e itself: 0.2% covers the time step
  for (double e : {0.3, 0.7, 0.9}) EXPECT_NEAR(collide(e, 5.0, 0.0, 2e-11).e_apparent / e, 1.0, 2e-3);
  // the printed form sqrt(m* k_N) (damping marshall/printed) damps by 1/sqrt 2 less: the damped
  // Hertz oscillator then rebounds with 0.440 (e = 0.3) and 0.778 (e = 0.7), values integrated
  // independently (doc/pair_granular_jkr_marshall.rst); 0.3% covers the time step
  EXPECT_NEAR(collide(0.3, 5.0, 0.0, 2e-11, "off", "marshall/printed").e_apparent, 0.440, 0.003 * 0.440);
  EXPECT_NEAR(collide(0.7, 5.0, 0.0, 2e-11, "off", "marshall/printed").e_apparent, 0.778, 0.003 * 0.778);
  EXPECT_TRUE(collide(0.7, 0.05).stuck);

  // capture speed by bisection, vs the energy balance (1/2) m* (e v_c)^2 = W_sep
  double lo = 0.05, hi = 5.0;
  for (int it = 0; it < 12; ++it) {
    const double mid = std::sqrt(lo * hi);
    (collide(0.7, mid).stuck ? lo : hi) = mid;
  }
  const JKR jkr{RP / 2, ESTAR_PAIR, GAMMA};
  const double mstar = MASS / 2, W = separation_work(jkr);
  const double v_estimate = std::sqrt(2.0 * W / mstar) / 0.7;
  std::printf("[ capture ] e = 0.7: numerical v_c = %.4f m/s, energy balance %.4f m/s, W_sep = "
              "%.4g J = %.4f F_C delta_C\n",
              hi, v_estimate, W, W / (jkr.FC() * jkr.deltaC()));
  // the estimate ignores the extra dissipation of the snap-in and of damping in the tensile
  // branch, so it can only be an order-of-magnitude guide: require agreement within 2x
  EXPECT_GT(hi / v_estimate, 0.5);
  EXPECT_LT(hi / v_estimate, 2.0);
}

// 6. no damping: a collision conserves energy (gamma = 0), or loses exactly the separation
// work of the adhesive hysteresis (gamma > 0)
TEST(JKRMarshall, EnergyBalanceWithoutDamping)
{
  // dt = 2e-11 s ~ t_c/3000: velocity Verlet's error, dominated by the force jumps at contact
  // formation and break (~F_C v dt), is < 2e-4 of the kinetic energy
  auto hertz = collide(1.0, 2.0, 0.0, 2e-11);
  EXPECT_FALSE(hertz.stuck);
  EXPECT_NEAR(hertz.ke_after / hertz.ke_before, 1.0, 1e-3);
  auto jkrc = collide(1.0, 2.0, GAMMA, 2e-11);
  EXPECT_FALSE(jkrc.stuck);
  const double W = separation_work(JKR{RP / 2, ESTAR_PAIR, GAMMA});
  std::printf("[ energy ] KE before %.6g J, after %.6g J, W_sep %.6g J\n", jkrc.ke_before,
              jkrc.ke_after, W);
  EXPECT_NEAR((jkrc.ke_before - jkrc.ke_after) / jkrc.ke_before, W / jkrc.ke_before, 1e-3);
}

// 4. sliding, twisting, rolling under prescribed motion at a loaded contact (no damping)
namespace {
void loaded_pair(Lmp &l, double delta, const std::string &extra)
{
  two_spheres(l, 1.0, extra);
  l.cmd(fmt::format("set atom 2 x {:.17g}", 2 * RP - delta));
  l.cmds({"group one id 1", "group two id 2", "timestep 1e-9"});
}
double ahat_at(double dd) { return JKR::ahat_of_delta(dd); }
}    // namespace

TEST(JKRMarshall, SlidingSpringAndLimit)
{
  Lmp l;
  const JKR jkr{RP / 2, ESTAR_PAIR, GAMMA};
  loaded_pair(l, jkr.deltaC(), "");
  const double a = ahat_at(1.0) * jkr.a0();
  const double kT = 8.0 * GSTAR_PAIR * a;    // Marshall eq. 24
  const double Fne = jkr.force(jkr.deltaC());
  const double Fcrit = MU * std::fabs(Fne + 2.0 * jkr.FC());
  const double vt = 0.02;    // m/s; u grows 2e-11 m per step, slip after ~100 steps
  l.cmds({"fix hold one move linear 0 0 0", fmt::format("fix slide two move linear 0 {} 0", vt)});
  l.cmd("run 0 post no");
  for (int step = 1; step <= 300; ++step) {
    l.cmd("run 1 post no");
    const double u = l.var("y[2]-y[1]");
    // tangential part of the force on atom 1 (normal part removed with the current normal)
    const double dx = l.var("x[1]-x[2]"), dy = l.var("y[1]-y[2]");
    const double r = std::hypot(dx, dy), nx = dx / r, ny = dy / r;
    const double fx = l.var("fx[1]"), fy = l.var("fy[1]");
    const double fn = fx * nx + fy * ny;
    const double ft = std::hypot(fx - fn * nx, fy - fn * ny);
    const double expect = std::min(kT * u, Fcrit);
    // u is integrated by the model from v_t dt, the test reads it from positions: they agree
    // to the first order in the normal's rotation (u/r ~ 1e-3), hence 1e-3 relative to F_crit
    EXPECT_NEAR(ft / Fcrit, expect / Fcrit, 2e-3) << "step " << step;
  }
}

TEST(JKRMarshall, TwistingSpringAndLimit)
{
  Lmp l;
  const JKR jkr{RP / 2, ESTAR_PAIR, GAMMA};
  loaded_pair(l, jkr.deltaC(), "twisting marshall/jkr");
  const double a = ahat_at(1.0) * jkr.a0();
  const double ktw = 0.5 * 8.0 * GSTAR_PAIR * a * a * a;    // k_T a^2 / 2
  const double Fcrit = MU * std::fabs(jkr.force(jkr.deltaC()) + 2.0 * jkr.FC());
  const double Mcrit = 3.0 * M_PI * a * Fcrit / 16.0;    // paper eq. 4
  const double omega = 2.0 * Mcrit / ktw / 200e-9;          // twist to 2 M_crit in 200 steps
  l.cmds({"fix hold one move linear 0 0 0",
          fmt::format("fix twist two move rotate {:.17g} 0 0 1 0 0 {:.17g}", 2 * RP - jkr.deltaC(),
                      2.0 * M_PI / omega)});
  l.cmd("run 0 post no");
  for (int step = 1; step <= 300; ++step) {
    l.cmd("run 1 post no");
    const double phi = omega * step * 1e-9;
    const double M = std::fabs(l.torque(1, 0));
    EXPECT_NEAR(M / Mcrit, std::min(ktw * phi, Mcrit) / Mcrit, 1e-6) << "step " << step;
  }
}

// rolling marshall slips at theta_crit R_eff; marshall/particle at theta_crit r_p (= 2 R_eff for
// like spheres), with the same spring
class RollingLimit : public ::testing::TestWithParam<const char *> {};
TEST_P(RollingLimit, SpringAndLimit)
{
  const std::string style = GetParam();
  Lmp l;
  const JKR jkr{RP / 2, ESTAR_PAIR, GAMMA};
  const double theta = 0.01;
  loaded_pair(l, jkr.deltaC(), fmt::format("rolling {} {}", style, theta));
  const double ah = ahat_at(1.0);
  const double kR = 4.0 * jkr.FC() * std::pow(ah, 1.5);    // paper eq. 3
  const double Reff = RP / 2;
  const double Rlimit = style == "marshall" ? Reff : RP;
  const double Mcrit = kR * theta * Rlimit;                 // paper eq. 4
  // opposite spins about z: pure rolling (R_i w_i + R_j w_j = 0, no sliding, no twist);
  // xi = R (w_1 - w_2) t = 2 R w t reaches 2 theta R in 200 steps
  const double omega = 2.0 * theta / (2.0 * 200e-9);
  l.cmds({fmt::format("fix spin1 one move rotate 0 0 0 0 0 1 {:.17g}", 2.0 * M_PI / omega),
          fmt::format("fix spin2 two move rotate {:.17g} 0 0 0 0 -1 {:.17g}", 2 * RP - jkr.deltaC(),
                      2.0 * M_PI / omega)});
  l.cmd("run 0 post no");
  for (int step = 1; step <= 300; ++step) {
    l.cmd("run 1 post no");
    const double xi = Reff * 2.0 * omega * step * 1e-9;
    const double M = std::hypot(l.torque(1, 0), l.torque(1, 1), l.torque(1, 2));
    const double ft = std::hypot(l.var("fy[1]"), l.var("fz[1]"));
    EXPECT_LT(ft, 1e-9 * jkr.FC()) << "no sliding force in pure rolling";
    EXPECT_NEAR(M / Mcrit, std::min(kR * xi, Mcrit) / Mcrit, 1e-6) << "step " << step;
  }
}
INSTANTIATE_TEST_SUITE_P(JKRMarshall, RollingLimit, ::testing::Values("marshall", "marshall/particle"));

// unlike types: E* and G* from both materials, gamma by geometric mean, R from both radii
TEST(JKRMarshall, MixingUnlikeTypes)
{
  const double E1 = 2e8, nu1 = 0.33, g1 = 0.01, r1 = 1e-6, E2 = 5e8, nu2 = 0.25, g2 = 0.04, r2 = 2e-6;
  Lmp l;
  l.cmds({"units si", "atom_style sphere", "atom_modify map array", "boundary f f f",
          "comm_modify vel yes", "region box block -1e-5 1e-5 -1e-5 1e-5 -1e-5 1e-5",
          "create_box 2 box", "create_atoms 1 single 0 0 0",
          fmt::format("create_atoms 2 single {} 0 0", r1 + r2), fmt::format("set type 1 diameter {}", 2 * r1),
          fmt::format("set type 2 diameter {}", 2 * r2), "set type * density 2500", "pair_style granular",
          fmt::format("pair_coeff 1 1 jkr/marshall {} 1.0 {} {} damping marshall tangential marshall 0.3", E1, nu1, g1),
          fmt::format("pair_coeff 2 2 jkr/marshall {} 1.0 {} {} damping marshall tangential marshall 0.3", E2, nu2, g2),
          "neighbor 2e-7 bin", "timestep 1e-9", "group one id 1", "group two id 2"});
  const double Es = 1.0 / ((1 - nu1 * nu1) / E1 + (1 - nu2 * nu2) / E2);
  const double Gs = 1.0 / (2 * (2 - nu1) * (1 + nu1) / E1 + 2 * (2 - nu2) * (1 + nu2) / E2);
  const JKR jkr{r1 * r2 / (r1 + r2), Es, std::sqrt(g1 * g2)};
  auto fx_at = [&](double delta) {
    l.cmd(fmt::format("set atom 2 x {:.17g}", r1 + r2 - delta));
    l.cmd("run 0 post no");
    return -l.var("fx[1]");
  };
  for (double dd : {0.0, 0.5, 2.0, 1.0, -0.3, -0.9})
    EXPECT_NEAR(fx_at(dd * jkr.deltaC() + 1e-20) / jkr.FC(), jkr.force(dd * jkr.deltaC()) / jkr.FC(), 1e-6) << dd;
  EXPECT_EQ(fx_at(-1.001 * jkr.deltaC()), 0.0) << "breaks at the mixed delta_C";
  // tangential stiffness 8 G* a from the mixed G*: slope of the first steps of a slide
  fx_at(jkr.deltaC());
  const double a = JKR::ahat_of_delta(1.0) * jkr.a0();
  l.cmds({"fix hold one move linear 0 0 0", "fix slide two move linear 0 0.001 0", "run 0 post no",
          "run 5 post no"});
  const double u = l.var("y[2]-y[1]");
  // 1e-3: the normal rotates by u/r ~ 1e-5, the spring is read through the y force
  EXPECT_NEAR(l.var("fy[1]") / (8.0 * Gs * a * u), 1.0, 1e-3);
}

// 8. bad input: each refused with a message naming the model and the value
// the same messages from pair_style granular and granular/opt (which parses through granular)
class BadInput : public ::testing::TestWithParam<const char *> {};

TEST_P(BadInput, NamesTheStyleAndTheValue)
{
  const std::vector<std::string> base = {
      "units si", "atom_style sphere", "region box block 0 1e-5 0 1e-5 0 1e-5",
      "create_box 1 box", std::string("pair_style ") + GetParam()};
  auto err = [&](const std::string &coeff) {
    auto c = base;
    c.push_back("pair_coeff * * " + coeff);
    return error_of(c);
  };
  auto expect_match = [](const std::string &msg, const std::string &re) {
    EXPECT_TRUE(std::regex_search(msg, std::regex(re))) << "message: " << msg << "\nexpected: " << re;
  };
  const std::string tail = " damping marshall tangential marshall 0.3";
  expect_match(err("jkr/marshall 2e8 0.7 0.33"), "Illegal|argument|Insufficient|Expected");
  expect_match(err("jkr/marshall 2e8 0.7 abc 0.01" + tail), "Expected floating point.*abc");
  expect_match(err("jkr/marshall 0 0.7 0.33 0.01" + tail), "jkr/marshall.*Young's modulus must be > 0, got 0");
  expect_match(err("jkr/marshall -2e8 0.7 0.33 0.01" + tail), "Young's modulus must be > 0");
  expect_match(err("jkr/marshall 2e8 0.7 0.6 0.01" + tail), "Poisson's ratio must be in \\(-1, 0.5\\], got 0.6");
  expect_match(err("jkr/marshall 2e8 0.7 -1 0.01" + tail), "Poisson's ratio");
  expect_match(err("jkr/marshall 2e8 0.7 0.33 -0.01" + tail), "surface energy must be >= 0, got -0.01");
  expect_match(err("jkr/marshall 2e8 1.5 0.33 0.01" + tail), "restitution coefficient must be in \\[0, 1\\], got 1.5");
  expect_match(err("jkr/marshall 2e8 -0.1 0.33 0.01" + tail), "restitution coefficient");
  expect_match(err("jkr/marshall 2e8 0.7 0.33 0.01 damping marshall tangential marshall -0.3"),
               "marshall tangential model, friction coefficient must be >= 0, got -0.3");
  expect_match(err("jkr/marshall 2e8 0.7 0.33 0.01" + tail + " rolling marshall 0"),
               "marshall rolling model, theta_crit must be > 0, got 0");
  expect_match(err("jkr 2e8 0.7 0.33 0.01 damping marshall tangential marshall 0.3"),
               "Damping marshall requires normal model jkr/marshall.*not jkr");
  // e is a restitution coefficient: any damping model but marshall would misread it
  for (const char *d : {"viscoelastic", "velocity", "mass_velocity"})    // LAMMPS refuses tsuji itself
    expect_match(err(fmt::format("jkr/marshall 2e8 0.7 0.33 0.01 damping {} tangential marshall 0.3", d)),
                 fmt::format("jkr/marshall requires damping marshall.*got damping {}", d));
  expect_match(err("jkr/marshall 2e8 0.7 0.33 0.01 tangential marshall 0.3"),
               "jkr/marshall requires damping marshall|Must specify damping");
  expect_match(err("hertz/material 2e8 0.7 0.33 damping viscoelastic tangential marshall 0.3 "
                   "rolling marshall 0.01"),
               "Rolling marshall requires normal model jkr/marshall");
  expect_match(err("jkr/marshall 2e8 0.7 0.33 0.01 damping marshall twisting marshall/jkr"),
               "Must specify tangential granular model");
  expect_match(err("jkr/marshall 2e8 0.7 0.33 0.01 damping marshall tangential linear_history "
                   "1e3 1.0 0.3 twisting marshall/jkr"),
               "Twisting marshall/jkr requires tangential model marshall or mindlin.*linear_history");
}

INSTANTIATE_TEST_SUITE_P(JKRMarshall, BadInput, ::testing::Values("granular", "granular/opt"));
