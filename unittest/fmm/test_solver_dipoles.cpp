// Solver::evaluate_dipoles: charges and point dipoles as FMM sources, field gradients at the
// targets (doc/polarization.md, section 5), against direct sums of dipole_kernels.hpp (whose
// terms test_polarization checks against closed forms), the lattice kernel of the far field,
// and finite differences of the solver's own field. Bare units.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <random>
#include <thread>
#include <stdexcept>
#include <vector>

#include "gcfmm/dipole_kernels.hpp"
#include "gcfmm/far_field.hpp"
#include "gcfmm/lattice_sum.hpp"
#include "gcfmm/polarization.hpp"
#include "gcfmm/direct_polarizable.hpp"
#include "gcfmm/polarizable_solver.hpp"
#include "gcfmm/solver.hpp"

using namespace gcfmm;

namespace {

struct Sources {
  std::vector<double> x, y, z, q, px, py, pz;
  std::size_t size() const { return x.size(); }
  DipoleSources view() const { return {q.data(), px.data(), py.data(), pz.data()}; }
};

// n particles in [0, side)^2 x [0, height) with charges and dipoles of both signs, O(1)
Sources random_sources(std::size_t n, unsigned seed, double side, double height)
{
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Sources s;
  for (std::size_t i = 0; i < n; ++i) {
    s.x.push_back(side * u(g));
    s.y.push_back(side * u(g));
    s.z.push_back(height * u(g));
    s.q.push_back(u(g) - 0.5);
    s.px.push_back(u(g) - 0.5);
    s.py.push_back(u(g) - 0.5);
    s.pz.push_back(u(g) - 0.5);
  }
  return s;
}

struct Result {
  std::vector<double> pot, ex, ey, ez, g;
  explicit Result(std::size_t n) : pot(n), ex(n), ey(n), ez(n), g(6 * n) {}
  FieldOutputs outputs(bool gradient = true)
  {
    return {pot.data(), ex.data(), ey.data(), ez.data(), gradient ? g.data() : nullptr};
  }
};

// the direct sum over the shifts (i lx, j ly, 0), |i|, |j| <= images, of dipole_kernels.hpp
Result direct(const Sources &s, double lx, double ly, int images)
{
  Result r(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) {
    PointField f;
    for (int a = -images; a <= images; ++a)
      for (int b = -images; b <= images; ++b)
        for (std::size_t j = 0; j < s.size(); ++j) {
          if (j == i && a == 0 && b == 0) continue;
          const Vec3 d{s.x[i] - s.x[j] - a * lx, s.y[i] - s.y[j] - b * ly, s.z[i] - s.z[j]};
          add_charge(s.q[j], d, f);
          add_dipole({s.px[j], s.py[j], s.pz[j]}, d, f);
        }
    r.pot[i] = f.pot;
    r.ex[i] = f.e.x;
    r.ey[i] = f.e.y;
    r.ez[i] = f.e.z;
    const double g6[6] = {f.g.xx, f.g.xy, f.g.xz, f.g.yy, f.g.yz, f.g.zz};
    for (int c = 0; c < 6; ++c) r.g[6 * i + c] = g6[c];
  }
  return r;
}

// relative RMS differences of the potential, the field and the gradient
struct Errors {
  double pot = 0, field = 0, gradient = 0;
};
Errors errors(const Result &a, const Result &ref)
{
  double np = 0, dp = 0, ne = 0, de = 0, ng = 0, dg = 0;
  for (std::size_t i = 0; i < a.pot.size(); ++i) {
    np += std::pow(a.pot[i] - ref.pot[i], 2);
    dp += ref.pot[i] * ref.pot[i];
    ne += std::pow(a.ex[i] - ref.ex[i], 2) + std::pow(a.ey[i] - ref.ey[i], 2) + std::pow(a.ez[i] - ref.ez[i], 2);
    de += ref.ex[i] * ref.ex[i] + ref.ey[i] * ref.ey[i] + ref.ez[i] * ref.ez[i];
    for (int c = 0; c < 6; ++c) {
      const double w = (c == 1 || c == 2 || c == 4) ? 2.0 : 1.0;  // off-diagonal entries twice
      ng += w * std::pow(a.g[6 * i + c] - ref.g[6 * i + c], 2);
      dg += w * ref.g[6 * i + c] * ref.g[6 * i + c];
    }
  }
  return {std::sqrt(np / dp), std::sqrt(ne / de), std::sqrt(ng / dg)};
}

// the direct reference's view of the particles s with polarizabilities alpha
PolarizableSystem system_of(const Sources &s, const std::vector<double> &alpha)
{
  return particles_of(s.size(), s.x.data(), s.y.data(), s.z.data(), s.q.data(), alpha.data());
}

Options high_accuracy(Boundary b = Boundary::Free, FarField ff = FarField::None)
{
  Options o;
  o.accuracy = 1e-8;
  o.boundary = b;
  o.farfield = ff;
  o.images = 1;
  return o;
}

Result fmm(const Sources &s, const Options &o, double lx = 0.0, double ly = 0.0, bool gradient = true)
{
  Solver solver(o);
  if (o.boundary == Boundary::Periodic2D) solver.set_box(0.0, 0.0, lx, ly);
  solver.build(s.size(), s.x.data(), s.y.data(), s.z.data());
  Result r(s.size());
  solver.evaluate_dipoles(s.view(), r.outputs(gradient));
  return r;
}

}  // namespace

// Free space, N = 3000 at the accuracy 1e-8 of the charges' force. A dipole's multipole starts
// one order later (eq. (5.1)), so its far part converges one order slower; the gradient is
// dominated by the near field (summed exactly). Seen: pot 8e-10, field 6e-11, gradient 2e-12.
// The tolerance 1e-7 (10x the requested accuracy, 100x the worst seen) is far below what a
// wrong term gives (a sign or factor error is O(1e-2) or more).
TEST(SolverDipoles, FreeSpaceMatchesDirectSum)
{
  const Sources s = random_sources(3000, 7, 1.0, 1.0);
  Solver solver(high_accuracy());
  solver.build(s.size(), s.x.data(), s.y.data(), s.z.data());
  Result r(s.size());
  solver.evaluate_dipoles(s.view(), r.outputs());
  ASSERT_GT(solver.stats().m2l_count, 0u);  // the expansions are used, not only P2P
  const Errors e = errors(r, direct(s, 0, 0, 0));
  std::printf("free space: pot %.2e field %.2e gradient %.2e\n", e.pot, e.field, e.gradient);
  EXPECT_LT(e.pot, 1e-7);
  EXPECT_LT(e.field, 1e-7);
  EXPECT_LT(e.gradient, 1e-7);
}

// Without dipoles the result is that of evaluate() (other P2P kernel: round-off only), and a
// dipole-only evaluation is the difference.
TEST(SolverDipoles, ChargesOnlyEqualsEvaluate)
{
  Sources s = random_sources(500, 11, 2.0, 1.0);
  for (auto *v : {&s.px, &s.py, &s.pz}) v->assign(s.size(), 0.0);
  const Options o = high_accuracy();
  Solver solver(o);
  solver.build(s.size(), s.x.data(), s.y.data(), s.z.data());
  Result a(s.size()), b(s.size());
  solver.evaluate_dipoles({s.q.data(), nullptr, nullptr, nullptr}, a.outputs(false));
  solver.evaluate(s.q.data(), b.pot.data(), b.ex.data(), b.ey.data(), b.ez.data());
  for (std::size_t i = 0; i < s.size(); ++i) {
    EXPECT_NEAR(a.pot[i], b.pot[i], 1e-12 * std::abs(b.pot[i]) + 1e-12);
    EXPECT_NEAR(a.ez[i], b.ez[i], 1e-11 * (std::abs(b.ex[i]) + std::abs(b.ey[i]) + std::abs(b.ez[i])));
  }
}

// The near block of a periodic cell (FarField::None, 3 x 3 cells) against the direct sum over
// the same 9 shifts (seen: pot 3e-9, field 8e-10, gradient 1e-10; tolerances as above).
TEST(SolverDipoles, PeriodicNearBlockMatchesDirectImages)
{
  const Sources s = random_sources(300, 5, 4.0, 3.0);
  const Errors e = errors(fmm(s, high_accuracy(Boundary::Periodic2D), 4.0, 4.0), direct(s, 4.0, 4.0, 1));
  std::printf("periodic block: pot %.2e field %.2e gradient %.2e\n", e.pot, e.field, e.gradient);
  EXPECT_LT(e.pot, 1e-7);
  EXPECT_LT(e.field, 1e-6);
  EXPECT_LT(e.gradient, 1e-5);
}

// The exact far field of dipoles: (Exact - None) is the field of all cells beyond the block,
// sum_j [q_j R(d) - p_j . grad R(d)] with R the lattice kernel (far_kernel); its field
// -q grad R + H p needs the Hessian H of R, here by central differences of grad R (step 1e-4
// of the cell: error ~1e-8 of the smooth R). The far field's own accuracy is 1e-8 (requested);
// 1e-6 of the far part's RMS is the tolerance.
TEST(SolverDipoles, ExactFarFieldMatchesLatticeKernel)
{
  const double L = 4.0;
  const Sources s = random_sources(40, 3, L, 2.0);
  const Result exact = fmm(s, high_accuracy(Boundary::Periodic2D, FarField::Exact), L, L, false);
  const Result none = fmm(s, high_accuracy(Boundary::Periodic2D, FarField::None), L, L, false);
  const double h = 1e-4 * L;
  double num = 0, den = 0, nump = 0, denp = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    double pot = 0, e[3] = {0, 0, 0};
    for (std::size_t j = 0; j < s.size(); ++j) {
      const double d[3] = {s.x[i] - s.x[j], s.y[i] - s.y[j], s.z[i] - s.z[j]};
      const double p[3] = {s.px[j], s.py[j], s.pz[j]};
      double r, g[3];
      far_kernel(d[0], d[1], d[2], L, L, 1, &r, &g[0], &g[1], &g[2]);
      pot += s.q[j] * r - (p[0] * g[0] + p[1] * g[1] + p[2] * g[2]);
      for (int b = 0; b < 3; ++b) {
        double up[3] = {d[0], d[1], d[2]}, dn[3] = {d[0], d[1], d[2]}, gu[3], gd[3], ru, rd;
        up[b] += h;
        dn[b] -= h;
        far_kernel(up[0], up[1], up[2], L, L, 1, &ru, &gu[0], &gu[1], &gu[2]);
        far_kernel(dn[0], dn[1], dn[2], L, L, 1, &rd, &gd[0], &gd[1], &gd[2]);
        // E_a = -q d_a R + sum_b H_ab p_b; column b of H from the differences
        for (int a = 0; a < 3; ++a) e[a] += (gu[a] - gd[a]) / (2 * h) * p[b];
      }
      for (int a = 0; a < 3; ++a) e[a] -= s.q[j] * g[a];
    }
    const double far[3] = {exact.ex[i] - none.ex[i], exact.ey[i] - none.ey[i], exact.ez[i] - none.ez[i]};
    for (int a = 0; a < 3; ++a) {
      num += std::pow(far[a] - e[a], 2);
      den += e[a] * e[a];
    }
    nump += std::pow(exact.pot[i] - none.pot[i] - pot, 2);
    denp += pot * pot;
  }
  std::printf("far field: pot %.2e field %.2e\n", std::sqrt(nump / denp), std::sqrt(num / den));
  EXPECT_LT(std::sqrt(nump / denp), 1e-6);
  EXPECT_LT(std::sqrt(num / den), 1e-6);
}

// The far field's gradient is the derivative of its field: at a probe without charge or dipole,
// against central differences (step 1e-4 of the cell) of PeriodicFarField's own interpolated
// field, which is a polynomial in each box, so the differences err by ~(1e-4)^2 of its scale;
// tolerance 1e-6 of |G_far|. The far part is ~1e-3 of the whole gradient, so the solver-level
// test below cannot see it.
TEST(SolverDipoles, FarFieldGradientIsTheDerivativeOfItsField)
{
  const double L = 4.0;
  Sources s = random_sources(30, 29, L, 2.0);
  s.x.push_back(1.3);
  s.y.push_back(2.9);
  s.z.push_back(0.7);
  for (auto *v : {&s.q, &s.px, &s.py, &s.pz}) v->push_back(0.0);
  const std::size_t k = s.size() - 1, n = s.size();
  PeriodicFarField far;
  far.setup(0.0, 0.0, L, L, 0.0, 2.0, 1, 1e-8);
  auto eval = [&](const Sources &t, Result &r, bool gradient) {
    far.evaluate_dipoles(n, t.x.data(), t.y.data(), t.z.data(), t.q.data(), t.px.data(), t.py.data(), t.pz.data(),
                         0, n, r.pot.data(), r.ex.data(), r.ey.data(), r.ez.data(), gradient ? r.g.data() : nullptr);
  };
  Result r(n);
  eval(s, r, true);
  double gnorm = 0;
  for (int c = 0; c < 6; ++c) gnorm += r.g[6 * k + c] * r.g[6 * k + c];
  gnorm = std::sqrt(gnorm);
  ASSERT_GT(gnorm, 0.0);
  const int col[3][3] = {{0, 1, 2}, {1, 3, 4}, {2, 4, 5}};
  const double h = 1e-4 * L;
  for (int b = 0; b < 3; ++b) {
    Sources up = s, dn = s;
    (b == 0 ? up.x : (b == 1 ? up.y : up.z))[k] += h;
    (b == 0 ? dn.x : (b == 1 ? dn.y : dn.z))[k] -= h;
    Result ru(n), rd(n);
    eval(up, ru, false);
    eval(dn, rd, false);
    const double de[3] = {(ru.ex[k] - rd.ex[k]) / (2 * h), (ru.ey[k] - rd.ey[k]) / (2 * h),
                          (ru.ez[k] - rd.ez[k]) / (2 * h)};
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(r.g[6 * k + col[a][b]], de[a], 1e-6 * gnorm) << a << b;
  }
}

// G is the derivative of E and E minus that of the potential, at a probe without charge or
// dipole (so that moving it changes no source), in free space and with the exact far field:
// central differences of step h = 1e-3 have truncation ~(h / d)^2 ~ 1e-6 at the probe's
// distance d ~ 0.5 from its nearest source, and the FMM's error (1e-8 relative, different tree
// at each step) divided by h adds ~1e-5 of G; tolerance 1e-4 relative to |G|.
TEST(SolverDipoles, GradientIsTheDerivativeOfTheField)
{
  for (const bool periodic : {false, true}) {
    Sources s = random_sources(200, 13, 3.0, 2.0);
    const Vec3 probe{1.37, 1.61, 1.1};
    s.x.push_back(probe.x);
    s.y.push_back(probe.y);
    s.z.push_back(probe.z);
    for (auto *v : {&s.q, &s.px, &s.py, &s.pz}) v->push_back(0.0);
    const std::size_t k = s.size() - 1;
    const Options o = periodic ? high_accuracy(Boundary::Periodic2D, FarField::Exact) : high_accuracy();
    const Result r = fmm(s, o, 3.0, 3.0);
    const double h = 1e-3;
    double gnorm = 0;
    for (int c = 0; c < 6; ++c) gnorm += r.g[6 * k + c] * r.g[6 * k + c];
    gnorm = std::sqrt(gnorm);
    const int col[3][3] = {{0, 1, 2}, {1, 3, 4}, {2, 4, 5}};
    for (int b = 0; b < 3; ++b) {
      Sources up = s, dn = s;
      (b == 0 ? up.x : (b == 1 ? up.y : up.z))[k] += h;
      (b == 0 ? dn.x : (b == 1 ? dn.y : dn.z))[k] -= h;
      const Result ru = fmm(up, o, 3.0, 3.0, false), rd = fmm(dn, o, 3.0, 3.0, false);
      const double de[3] = {(ru.ex[k] - rd.ex[k]) / (2 * h), (ru.ey[k] - rd.ey[k]) / (2 * h),
                            (ru.ez[k] - rd.ez[k]) / (2 * h)};
      for (int a = 0; a < 3; ++a) EXPECT_NEAR(r.g[6 * k + col[a][b]], de[a], 1e-4 * gnorm) << periodic << a << b;
      const double e[3] = {r.ex[k], r.ey[k], r.ez[k]};
      EXPECT_NEAR(e[b], -(ru.pot[k] - rd.pot[k]) / (2 * h), 1e-4 * std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]));
    }
  }
}

// Induced dipoles with the FMM as the dipole-field operator T p (field of the dipoles only)
// against the direct solve of direct_polarizable.hpp: the same system to the FMM's accuracy.
TEST(SolverDipoles, InducedDipolesByFmmMatchDirectSolve)
{
  // spheres of radius 0.2 on a jittered lattice of spacing 0.5 (6 x 6 x 8, no overlaps: the
  // induction is definite), alpha = beta a^3 with beta = 0.5: pair coupling 2 alpha / d^3 ~ 0.1
  Sources s = random_sources(288, 17, 3.0, 4.0);
  std::mt19937_64 g(23);
  std::uniform_real_distribution<double> jitter(-0.04, 0.04);
  for (std::size_t i = 0; i < s.size(); ++i) {
    s.x[i] = 0.25 + 0.5 * (i % 6) + jitter(g);
    s.y[i] = 0.25 + 0.5 * ((i / 6) % 6) + jitter(g);
    s.z[i] = 0.25 + 0.5 * (i / 36) + jitter(g);
  }
  std::vector<double> alpha(s.size(), polarizability(0.5, 0.2));
  PolarizableSystem sys = system_of(s, alpha);
  sys.applied_field = {0.0, 0.0, 2.0};
  PolarizationSettings set;
  set.tolerance = 1e-10;
  const PolarizableResult ref = solve_polarizable_direct(sys, set);
  ASSERT_TRUE(ref.report.converged);

  const Options o = high_accuracy();
  Solver solver(o);
  solver.build(s.size(), s.x.data(), s.y.data(), s.z.data());
  const std::size_t n = s.size();
  Result f(n);
  solver.evaluate_dipoles({s.q.data(), nullptr, nullptr, nullptr}, f.outputs(false));
  std::vector<double> e0(3 * n), p(3 * n, 0.0), px(n), py(n), pz(n);
  for (std::size_t i = 0; i < n; ++i) {
    e0[3 * i] = f.ex[i] + sys.applied_field.x;
    e0[3 * i + 1] = f.ey[i] + sys.applied_field.y;
    e0[3 * i + 2] = f.ez[i] + sys.applied_field.z;
  }
  Result t(n);
  const DipoleFieldOperator field = [&](const double *d, double *out) {
    for (std::size_t i = 0; i < n; ++i) {
      px[i] = d[3 * i];
      py[i] = d[3 * i + 1];
      pz[i] = d[3 * i + 2];
    }
    solver.evaluate_dipoles({nullptr, px.data(), py.data(), pz.data()}, t.outputs(false));
    for (std::size_t i = 0; i < n; ++i) {
      out[3 * i] = t.ex[i];
      out[3 * i + 1] = t.ey[i];
      out[3 * i + 2] = t.ez[i];
    }
  };
  set.tolerance = 1e-8;
  const PolarizationReport rep = solve_induced_dipoles(n, alpha.data(), e0.data(), field, p.data(), set);
  EXPECT_TRUE(rep.converged);
  double num = 0, den = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 &q = ref.dipole[i];
    num += std::pow(p[3 * i] - q.x, 2) + std::pow(p[3 * i + 1] - q.y, 2) + std::pow(p[3 * i + 2] - q.z, 2);
    den += norm2(q);
  }
  std::printf("induced dipoles: %d iterations, residual %.2e, relative difference %.2e\n", rep.iterations,
              rep.residual, std::sqrt(num / den));
  EXPECT_LT(std::sqrt(num / den), 1e-6);
}

TEST(SolverDipoles, RefusesWhatItCannotDo)
{
  const Sources s = random_sources(50, 19, 2.0, 1.0);
  Result r(s.size());
  {
    Options o = high_accuracy(Boundary::Periodic2D, FarField::Average);
    Solver solver(o);
    solver.set_box(0, 0, 2, 2);
    solver.build(s.size(), s.x.data(), s.y.data(), s.z.data());
    EXPECT_THROW(solver.evaluate_dipoles(s.view(), r.outputs()), std::invalid_argument);
  }
  {
    Options o;
    o.order = 1;
    Solver solver(o);
    solver.build(s.size(), s.x.data(), s.y.data(), s.z.data());
    EXPECT_THROW(solver.evaluate_dipoles(s.view(), r.outputs()), std::invalid_argument);
    EXPECT_NO_THROW(solver.evaluate_dipoles(s.view(), r.outputs(false)));
  }
  {
    Sources c = s;  // particle 1 on particle 0, both carrying only a dipole
    c.x[1] = c.x[0];
    c.y[1] = c.y[0];
    c.z[1] = c.z[0];
    c.q[0] = c.q[1] = 0.0;
    Solver solver(high_accuracy());
    solver.build(c.size(), c.x.data(), c.y.data(), c.z.data());
    EXPECT_THROW(solver.evaluate_dipoles(c.view(), r.outputs()), CoincidentParticles);
  }
}

// ---- PolarizableSolver: applied field, induction and the electrode through the FMM ----------

namespace {

// 4 x 4 x layers spheres of radius 0.2 on a jittered lattice of spacing 0.5 above z = 0 (the
// electrode), charges of both signs
Sources lattice(int layers, unsigned seed)
{
  Sources s = random_sources(16 * layers, seed, 2.0, 1.0);
  std::mt19937_64 g(seed + 1);
  std::uniform_real_distribution<double> jitter(-0.04, 0.04);
  for (std::size_t i = 0; i < s.size(); ++i) {
    s.x[i] = 0.25 + 0.5 * (i % 4) + jitter(g);
    s.y[i] = 0.25 + 0.5 * ((i / 4) % 4) + jitter(g);
    s.z[i] = 0.3 + 0.5 * (i / 16) + jitter(g);
  }
  return s;
}

struct Polarized {
  std::vector<double> p;
  PolarizableOutputs out;
  PolarizationReport report;
  double energy = 0.0;
};

Polarized polarize(const Sources &s, const std::vector<double> &alpha, const Options &o, const PolarizableEnvironment &env,
                   double L)
{
  PolarizableSolver solver(o);
  if (o.boundary == Boundary::Periodic2D) solver.set_box(0.0, 0.0, L, L);
  solver.set_environment(env);
  Polarized r;
  r.p.assign(3 * s.size(), 0.0);
  solver.compute(s.size(), s.x.data(), s.y.data(), s.z.data(), s.q.data(), alpha.data(), r.p.data(), r.out);
  r.report = solver.report();
  r.energy = solver.energy();
  return r;
}

}  // namespace

// One charge at height h above the grounded plane: the image force q^2 / (4 h^2) towards it
// (q^2 / (16 pi eps0 h^2) in SI), energy -q^2 / (4 h), from the two-source tree (round-off).
TEST(PolarizableSolver, ChargeAboveGroundedPlane)
{
  const double q = 1.7, h = 0.8, x = 0.3, y = -0.2, z = 0.5 + h;
  PolarizableEnvironment env;
  env.electrode = true;
  env.electrode_z = 0.5;
  PolarizableSolver solver(high_accuracy());
  solver.set_environment(env);
  std::vector<double> p(3, 0.0);
  PolarizableOutputs out;
  solver.compute(1, &x, &y, &z, &q, nullptr, p.data(), out);
  EXPECT_NEAR(out.force[2], -q * q / (4 * h * h), 1e-12);
  EXPECT_NEAR(out.force[0], 0.0, 1e-12);
  EXPECT_NEAR(solver.energy(), -q * q / (4 * h), 1e-12);
  const double below = 0.5;
  EXPECT_THROW(solver.compute(1, &x, &y, &below, &q, nullptr, p.data(), out), std::invalid_argument);
}

// Everything on (applied field, induction, electrode) against the direct reference, in free
// space and in a periodic cell's near block: dipoles, forces and energy to 1e-7 relative at the
// accuracy 1e-8 (FMM error of the fields, induction residual 1e-9).
TEST(PolarizableSolver, MatchesDirectReference)
{
  for (const bool periodic : {false, true}) {
    const Sources s = lattice(4, 31);
    std::vector<double> alpha(s.size(), polarizability(0.6, 0.2));
    PolarizableEnvironment env;
    env.applied_field = {0.3, -0.2, 1.5};
    env.electrode = true;
    env.electrode_z = 0.0;
    const Options o = periodic ? high_accuracy(Boundary::Periodic2D) : high_accuracy();
    const Polarized f = polarize(s, alpha, o, env, 2.0);
    EXPECT_TRUE(f.report.converged);

    PolarizableSystem sys = system_of(s, alpha);
    sys.applied_field = env.applied_field;
    sys.electrode = true;
    sys.electrode_z = 0.0;
    if (periodic) {
      sys.lx = sys.ly = 2.0;
      sys.images = 1;
    }
    PolarizationSettings set;
    set.tolerance = 1e-12;
    const PolarizableResult ref = solve_polarizable_direct(sys, set);
    ASSERT_TRUE(ref.report.converged);
    double dp = 0, np = 0, df = 0, nf = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
      const Vec3 &pr = ref.dipole[i], &fr = ref.force[i];
      dp += std::pow(f.p[3 * i] - pr.x, 2) + std::pow(f.p[3 * i + 1] - pr.y, 2) + std::pow(f.p[3 * i + 2] - pr.z, 2);
      np += norm2(pr);
      df += std::pow(f.out.force[3 * i] - fr.x, 2) + std::pow(f.out.force[3 * i + 1] - fr.y, 2) +
            std::pow(f.out.force[3 * i + 2] - fr.z, 2);
      nf += norm2(fr);
    }
    std::printf("%s: %d iterations; dipoles %.2e forces %.2e energy %.10g (direct %.10g)\n",
                periodic ? "periodic" : "free", f.report.iterations, std::sqrt(dp / np), std::sqrt(df / nf),
                f.energy, ref.energy);
    EXPECT_LT(std::sqrt(dp / np), 1e-7);
    EXPECT_LT(std::sqrt(df / nf), 1e-7);
    EXPECT_NEAR(f.energy, ref.energy, 1e-7 * std::abs(ref.energy));
  }
}

// F = -dU/dx with the exact 2D-periodic far field, the electrode, the applied field and the
// induction: central differences of the energy (step 1e-3 of the spacing: truncation ~1e-6 of
// the force) at accuracy 1e-10 (the energy's FMM error over 48 particles divided by the step is
// ~1e-5 of a force); the induction residual enters the energy at second order. Tolerance 1e-4
// of the largest force component.
TEST(PolarizableSolver, ForceIsMinusEnergyGradientWithExactFarField)
{
  const Sources s = lattice(3, 37);
  std::vector<double> alpha(s.size(), polarizability(0.6, 0.2));
  PolarizableEnvironment env;
  env.applied_field = {0.2, 0.1, 1.0};
  env.electrode = true;
  env.electrode_z = 0.0;
  Options o = high_accuracy(Boundary::Periodic2D, FarField::Exact);
  o.accuracy = 1e-10;
  const Polarized f = polarize(s, alpha, o, env, 2.0);
  const double h = 5e-4;
  for (const std::size_t k : {std::size_t(5), std::size_t(21), std::size_t(40)}) {
    double fmax = 0;
    for (int a = 0; a < 3; ++a) fmax = std::max(fmax, std::abs(f.out.force[3 * k + a]));
    for (int a = 0; a < 3; ++a) {
      Sources up = s, dn = s;
      (a == 0 ? up.x : (a == 1 ? up.y : up.z))[k] += h;
      (a == 0 ? dn.x : (a == 1 ? dn.y : dn.z))[k] -= h;
      const double fd = -(polarize(up, alpha, o, env, 2.0).energy - polarize(dn, alpha, o, env, 2.0).energy) / (2 * h);
      EXPECT_NEAR(f.out.force[3 * k + a], fd, 1e-4 * fmax) << "particle " << k << " component " << a;
    }
  }
}

// FieldOutputs::targets: the first particles get the results of the full evaluation (the same
// lists and expansions, so to round-off), the others zero
TEST(SolverDipoles, TargetsSubset)
{
  const Sources s = random_sources(3000, 41, 1.0, 1.0);
  Solver solver(high_accuracy());
  solver.build(s.size(), s.x.data(), s.y.data(), s.z.data());
  Result all(s.size()), some(s.size());
  solver.evaluate_dipoles(s.view(), all.outputs());
  FieldOutputs o = some.outputs();
  o.targets = 1000;
  solver.evaluate_dipoles(s.view(), o);
  for (std::size_t i = 0; i < s.size(); ++i) {
    const bool target = i < 1000;
    EXPECT_EQ(some.ez[i], target ? all.ez[i] : 0.0) << i;
    EXPECT_EQ(some.pot[i], target ? all.pot[i] : 0.0) << i;
    EXPECT_EQ(some.g[6 * i + 2], target ? all.g[6 * i + 2] : 0.0) << i;
  }
}

// work partitions with FieldOutputs::targets: the parts split the targets' work, not the
// sources' (an electrode's images are sources only and lie apart, below the plane): two parts
// over 2000 targets above z = 0 and their 2000 mirror images each get about half the targets
// (within 35-65%: the estimate weighs P2P and M2L work, not the count). Weighing every source
// instead gives one part ~all the targets (seen: 2000 and 0), the other nothing to do.
TEST(SolverDipoles, PartitionsSplitTheTargets)
{
  Sources s = random_sources(2000, 53, 1.0, 1.0);
  for (auto *v : {&s.x, &s.y, &s.z, &s.q, &s.px, &s.py, &s.pz}) v->resize(4000);
  for (std::size_t i = 0; i < 2000; ++i) {
    s.z[i] += 0.05;
    s.x[2000 + i] = s.x[i];
    s.y[2000 + i] = s.y[i];
    s.z[2000 + i] = -s.z[i];
    s.q[2000 + i] = -s.q[i];
    s.px[2000 + i] = -s.px[i];
    s.py[2000 + i] = -s.py[i];
    s.pz[2000 + i] = s.pz[i];
  }
  Solver solver(Options{});
  solver.build(s.size(), s.x.data(), s.y.data(), s.z.data());
  std::size_t total = 0;
  for (int part = 0; part < 2; ++part) {
    Result r(s.size());
    FieldOutputs o = r.outputs();
    o.targets = 2000;
    solver.evaluate_dipoles(s.view(), o, part, 2);
    std::size_t mine = 0;
    for (std::size_t i = 0; i < 2000; ++i) mine += r.ez[i] != 0.0;
    std::printf("[ partition ] part %d: %zu of 2000 targets\n", part, mine);
    EXPECT_GT(mine, 700u) << "part " << part;
    EXPECT_LT(mine, 1300u) << "part " << part;
    total += mine;
  }
  EXPECT_EQ(total, 2000u);
  // and back to all particles as targets: the split covers them all again
  std::size_t all = 0;
  for (int part = 0; part < 2; ++part) {
    Result r(s.size());
    solver.evaluate_dipoles(s.view(), r.outputs(), part, 2);
    for (std::size_t i = 0; i < s.size(); ++i) all += r.ez[i] != 0.0;
  }
  EXPECT_EQ(all, s.size());
}

// set_partition: three parts run one after the other, their results summed as a communicator
// would, give the one-part solution bit for bit (dipoles, forces, energy)
TEST(PolarizableSolver, PartsSumToTheWhole)
{
  const Sources s = lattice(4, 43);
  std::vector<double> alpha(s.size(), polarizability(0.6, 0.2));
  PolarizableEnvironment env;
  env.applied_field = {0.0, 0.0, 1.5};
  env.electrode = true;
  const Options o = high_accuracy(Boundary::Periodic2D, FarField::Exact);
  const Polarized whole = polarize(s, alpha, o, env, 2.0);
  // the parts in lock-step: each evaluation of part k is completed by the others' at the same
  // call; a sequential emulation runs the three solvers on threads that meet at every sum
  const int nparts = 3;
  std::vector<std::vector<double>> p(nparts, std::vector<double>(3 * s.size(), 0.0));
  std::vector<PolarizableOutputs> out(nparts);
  std::vector<double> energy(nparts);
  std::mutex m;
  std::condition_variable cv;
  std::vector<double> acc;
  int arrived = 0, generation = 0;
  auto sum = [&](double *data, std::size_t count) {
    std::unique_lock<std::mutex> lock(m);
    const int gen = generation;
    if (arrived == 0) acc.assign(count, 0.0);
    for (std::size_t k = 0; k < count; ++k) acc[k] += data[k];
    if (++arrived == nparts) {
      arrived = 0;
      ++generation;
      cv.notify_all();
    } else {
      cv.wait(lock, [&] { return generation != gen; });
    }
    std::copy(acc.begin(), acc.begin() + count, data);
  };
  std::vector<std::thread> threads;
  for (int k = 0; k < nparts; ++k)
    threads.emplace_back([&, k] {
      PolarizableSolver solver(o);
      solver.set_box(0.0, 0.0, 2.0, 2.0);
      solver.set_environment(env);
      solver.set_partition(k, nparts, sum);
      solver.compute(s.size(), s.x.data(), s.y.data(), s.z.data(), s.q.data(), alpha.data(), p[k].data(), out[k]);
      energy[k] = solver.energy();
    });
  for (auto &t : threads) t.join();
  for (int k = 0; k < nparts; ++k) {
    EXPECT_EQ(p[k], whole.p) << "part " << k;
    EXPECT_EQ(out[k].force, whole.out.force) << "part " << k;
    EXPECT_EQ(energy[k], whole.energy) << "part " << k;
  }
}

// A start that already solves (3.3) twice in a row: the second time its evaluation carries the
// gradient and is the only one, with the forces of the full path bit for bit; a start that
// does not (the particles moved) falls back to the iterations and the forces' evaluation
TEST(PolarizableSolver, ConvergedStartIsTheOnlyEvaluation)
{
  Sources s = lattice(3, 47);
  std::vector<double> alpha(s.size(), polarizability(0.6, 0.2));
  PolarizableEnvironment env;
  env.applied_field = {0.0, 0.0, 1.5};
  env.electrode = true;
  PolarizableSolver solver(high_accuracy());
  solver.set_environment(env);
  std::vector<double> p(3 * s.size(), 0.0);
  PolarizableOutputs a, b, c, d;
  auto run = [&](PolarizableOutputs &o) {
    solver.compute(s.size(), s.x.data(), s.y.data(), s.z.data(), s.q.data(), alpha.data(), p.data(), o);
  };
  run(a);  // cold: start + iterations + forces
  EXPECT_GT(solver.evaluations(), 2);
  run(b);  // from the solution: the start converges, then the forces' evaluation
  EXPECT_EQ(solver.report().iterations, 1);
  EXPECT_EQ(solver.evaluations(), 2);
  run(c);  // the start carries the gradient and converges again: one evaluation
  EXPECT_EQ(solver.evaluations(), 1);
  EXPECT_EQ(c.force, b.force);
  for (std::size_t i = 0; i < s.size(); ++i) s.z[i] += 0.02;  // moved: the start is off
  run(d);
  EXPECT_GT(solver.evaluations(), 2);
  PolarizableSolver fresh(high_accuracy());
  fresh.set_environment(env);
  std::vector<double> p0(3 * s.size(), 0.0);
  PolarizableOutputs e;
  fresh.compute(s.size(), s.x.data(), s.y.data(), s.z.data(), s.q.data(), alpha.data(), p0.data(), e);
  double num = 0, den = 0;
  for (std::size_t k = 0; k < e.force.size(); ++k) {
    num += std::pow(d.force[k] - e.force[k], 2);
    den += e.force[k] * e.force[k];
  }
  EXPECT_LT(std::sqrt(num / den), 1e-7);
}

// The requested accuracy holds for the polarised forces in a deposition-like bed (charges of
// one sign on a jittered cubic lattice of spacing 2.2 radii, 10 layers of 9 x 9, a tenth of them
// lifted above, eps_p = 3.8, field along z, electrode, p p f with the exact far field): relative
// RMS force error against the solver at 1e-11 below the request. Without the tightened
// expansions for dipoles (dipole_accuracy_margin) it was ~5 x the request.
TEST(PolarizableSolver, PolarisedForcesMeetTheRequestedAccuracy)
{
  const int m = 9;
  const double a = 2.2, L = m * a;
  Sources s = random_sources(m * m * 10, 61, L, 1.0);
  std::mt19937_64 g(62);
  std::uniform_real_distribution<double> jitter(-0.025, 0.025), above(0.0, 60.0);
  for (std::size_t i = 0; i < s.size(); ++i) {
    s.x[i] = a * (0.5 + i % m) + jitter(g);
    s.y[i] = a * (0.5 + (i / m) % m) + jitter(g);
    s.z[i] = 1.2 + a * double(i / (m * m)) + jitter(g) + (i % 10 == 0 ? 25.0 + above(g) : 0.0);
    s.q[i] = 1.0;
  }
  const std::vector<double> alpha(s.size(), polarizability(clausius_mossotti(3.8, 1.0), 1.0));
  PolarizableEnvironment env;
  env.applied_field = {0.0, 0.0, 0.05};
  env.electrode = true;
  auto forces = [&](double accuracy) {
    Options o;
    o.accuracy = accuracy;
    o.boundary = Boundary::Periodic2D;
    o.farfield = FarField::Exact;
    o.images = 1;
    PolarizableSolver solver(o);
    solver.set_box(0.0, 0.0, L, L);
    solver.set_z_range(0.0, 100.0);
    solver.set_environment(env);
    PolarizationSettings ind;
    ind.tolerance = accuracy < 1e-10 ? 1e-12 : 0.1 * accuracy;
    solver.set_induction(ind);
    std::vector<double> p(3 * s.size(), 0.0);
    PolarizableOutputs out;
    solver.compute(s.size(), s.x.data(), s.y.data(), s.z.data(), s.q.data(), alpha.data(), p.data(), out);
    return out.force;
  };
  const std::vector<double> ref = forces(1e-11);
  for (const double acc : {1e-3, 1e-4}) {
    const std::vector<double> f = forces(acc);
    double num = 0.0, den = 0.0;
    for (std::size_t k = 0; k < f.size(); ++k) {
      num += (f[k] - ref[k]) * (f[k] - ref[k]);
      den += ref[k] * ref[k];
    }
    const double err = std::sqrt(num / den);
    std::printf("[ delivered ] polarised forces at accuracy %g: %.3g\n", acc, err);
    EXPECT_LT(err, acc);
  }
}
