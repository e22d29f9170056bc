// P2P kernel of gcfmm against a plain long-double double loop, and the direct sums.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "gcfmm/expansions.hpp"
#include "gcfmm/kernels.hpp"
#include "gcfmm/options.hpp"
#include "fmm_test_util.hpp"

using namespace gcfmm;

namespace {
// reference: long double, exact sqrt, no vectorisation tricks
void ref_sum(const gcfmm_test::Particles &t, const gcfmm_test::Particles &s, double sx, double sy, double sz,
             std::vector<double> &p, std::vector<double> &ex, std::vector<double> &ey, std::vector<double> &ez) {
  for (std::size_t i = 0; i < t.size(); ++i) {
    long double a = 0, b = 0, c = 0, d = 0;
    for (std::size_t j = 0; j < s.size(); ++j) {
      const long double dx = (long double)t.x[i] - s.x[j] - sx, dy = (long double)t.y[i] - s.y[j] - sy,
                        dz = (long double)t.z[i] - s.z[j] - sz;
      const long double r2 = dx * dx + dy * dy + dz * dz;
      if (r2 == 0) continue;
      const long double r = std::sqrt(r2);
      a += s.q[j] / r;
      b += s.q[j] * dx / (r * r2);
      c += s.q[j] * dy / (r * r2);
      d += s.q[j] * dz / (r * r2);
    }
    p[i] = (double)a;
    ex[i] = (double)b;
    ey[i] = (double)c;
    ez[i] = (double)d;
  }
}
}  // namespace

// Every target/source count from 0 to 19 (covers the 8-wide masked tails) plus a big one.
// Tolerance: double round-off over <= 1000 terms with cancellation between signs, relative to
// the sum of |terms| ~ 1e-13 (the 1/sqrt refinement itself is good to ~1e-16).
TEST(P2P, MatchesLongDoubleReference) {
  auto src = gcfmm_test::random_cube(1000, 21);
  auto tgt = gcfmm_test::random_cube(50, 22);
  for (std::size_t nt : {0u, 1u, 3u, 7u, 8u, 9u, 15u, 16u, 17u, 50u})
    for (std::size_t ns : {0u, 1u, 5u, 8u, 13u, 19u, 1000u}) {
      gcfmm_test::Particles t = tgt, s = src;
      t.resize(nt);
      s.resize(ns);
      std::vector<double> p(nt, 0), ex(nt, 0), ey(nt, 0), ez(nt, 0), rp(nt), rx(nt), ry(nt), rz(nt);
      p2p(nt, t.x.data(), t.y.data(), t.z.data(), ns, s.x.data(), s.y.data(), s.z.data(), s.q.data(), 0.3, -0.2,
          0.1, p.data(), ex.data(), ey.data(), ez.data());
      ref_sum(t, s, 0.3, -0.2, 0.1, rp, rx, ry, rz);
      for (std::size_t i = 0; i < nt; ++i) {
        const double scale = 1.0 + std::abs(rp[i]) + std::abs(rx[i]) + std::abs(ry[i]) + std::abs(rz[i]);
        EXPECT_LT(std::abs(p[i] - rp[i]), 1e-12 * scale * std::sqrt(double(ns) + 1.0));
        EXPECT_LT(std::abs(ex[i] - rx[i]) + std::abs(ey[i] - ry[i]) + std::abs(ez[i] - rz[i]),
                  1e-11 * scale * std::sqrt(double(ns) + 1.0));
      }
    }
}

// the self term (zero distance) is dropped, also between distinct coincident points
TEST(P2P, ZeroDistanceSkippedAndAccumulates) {
  double x[2] = {0.0, 0.0}, y[2] = {0.0, 0.0}, z[2] = {0.0, 2.0}, q[2] = {3.0, 5.0};
  double p[2] = {1.0, 1.0}, ex[2] = {0, 0}, ey[2] = {0, 0}, ez[2] = {0, 0};
  p2p(2, x, y, z, 2, x, y, z, q, 0, 0, 0, p, ex, ey, ez);
  // accumulates onto the initial 1.0; particle 0 sees 5/2, particle 1 sees 3/2
  EXPECT_NEAR(p[0], 1.0 + 2.5, 1e-15);
  EXPECT_NEAR(p[1], 1.0 + 1.5, 1e-15);
  EXPECT_NEAR(ez[0], -5.0 / 4.0, 1e-15);  // E = q (r_i - r_j) / r^3 points away from the source
  EXPECT_NEAR(ez[1], 3.0 / 4.0, 1e-15);
  EXPECT_EQ(ex[0], 0.0);
  EXPECT_FALSE(std::isnan(p[0]));
}

// a target's result must not depend on which other targets are evaluated with it (needed for
// bit-identical work partitions): evaluate one by one vs all at once, compare exactly
TEST(P2P, TargetResultIndependentOfBlocking) {
  auto src = gcfmm_test::random_cube(37, 31);
  auto tgt = gcfmm_test::random_cube(29, 32);
  const std::size_t nt = tgt.size();
  std::vector<double> p(nt, 0), ex(nt, 0), ey(nt, 0), ez(nt, 0);
  p2p(nt, tgt.x.data(), tgt.y.data(), tgt.z.data(), src.size(), src.x.data(), src.y.data(), src.z.data(),
      src.q.data(), 0, 0, 0, p.data(), ex.data(), ey.data(), ez.data());
  for (std::size_t off = 0; off < nt; ++off) {
    double a = 0, b = 0, c = 0, d = 0;
    p2p(1, &tgt.x[off], &tgt.y[off], &tgt.z[off], src.size(), src.x.data(), src.y.data(), src.z.data(), src.q.data(),
        0, 0, 0, &a, &b, &c, &d);
    EXPECT_EQ(a, p[off]);
    EXPECT_EQ(b, ex[off]);
    EXPECT_EQ(c, ey[off]);
    EXPECT_EQ(d, ez[off]);
  }
}

// direct_images = own cell + all shifted copies; with images 0 it is direct_free
TEST(P2P, DirectImagesMatchesShiftedCopies) {
  auto s = gcfmm_test::random_cube(60, 41, 5.0);
  const std::size_t n = s.size();
  gcfmm_test::Field a(n), b(n), c(n);
  direct_images(n, s.x.data(), s.y.data(), s.z.data(), s.q.data(), 5.0, 6.0, 0, a.pot.data(), a.ex.data(), a.ey.data(),
                a.ez.data());
  direct_free(n, s.x.data(), s.y.data(), s.z.data(), s.q.data(), b.pot.data(), b.ex.data(), b.ey.data(), b.ez.data());
  for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(a.pot[i], b.pot[i]);
  direct_images(n, s.x.data(), s.y.data(), s.z.data(), s.q.data(), 5.0, 6.0, 2, a.pot.data(), a.ex.data(), a.ey.data(),
                a.ez.data());
  // explicit copies of the sources in the 5 x 5 block
  gcfmm_test::Particles big;
  for (int i = -2; i <= 2; ++i)
    for (int j = -2; j <= 2; ++j)
      for (std::size_t k = 0; k < n; ++k) {
        big.x.push_back(s.x[k] + 5.0 * i);
        big.y.push_back(s.y[k] + 6.0 * j);
        big.z.push_back(s.z[k]);
        big.q.push_back(s.q[k]);
      }
  std::vector<double> rp(n), rx(n), ry(n), rz(n);
  ref_sum(s, big, 0, 0, 0, rp, rx, ry, rz);
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_NEAR(a.pot[i], rp[i], 1e-11 * (1 + std::abs(rp[i])));
    EXPECT_NEAR(a.ez[i], rz[i], 1e-11 * (1 + std::abs(rz[i])));
  }
}

// Every instruction-set path available on this CPU (gcsimd/simd.hpp, src/simd) against the
// generic one: P2P (the AVX-512 path is a different kernel, rsqrt14 + Newton) and the batched
// P2M, M2L and L2P; round-off only.
TEST(P2P, EverySimdPathMatchesGeneric) {
  auto src = gcfmm_test::random_cube(301, 31);
  auto tgt = gcfmm_test::random_cube(97, 32, 1.5);
  for (gcsimd::SimdPath path : {gcsimd::SimdPath::AVX2, gcsimd::SimdPath::AVX512}) {
    if (!gcsimd::simd_path_available(path)) {
      std::printf("[ skipped  ] path %s not available on this CPU\n", gcsimd::simd_path_name(path));
      continue;
    }
    gcfmm_test::Field a(tgt.size()), b(tgt.size());
    p2p_with(gcsimd::SimdPath::Generic, tgt.size(), tgt.x.data(), tgt.y.data(), tgt.z.data(), src.size(), src.x.data(),
             src.y.data(), src.z.data(), src.q.data(), 0.1, -0.2, 0.3, a.pot.data(), a.ex.data(), a.ey.data(),
             a.ez.data());
    p2p_with(path, tgt.size(), tgt.x.data(), tgt.y.data(), tgt.z.data(), src.size(), src.x.data(), src.y.data(),
             src.z.data(), src.q.data(), 0.1, -0.2, 0.3, b.pot.data(), b.ex.data(), b.ey.data(), b.ez.data());
    for (std::size_t i = 0; i < tgt.size(); ++i) {
      const double s = std::abs(a.pot[i]) + std::abs(a.ex[i]) + std::abs(a.ey[i]) + std::abs(a.ez[i]);
      EXPECT_LT(std::abs(a.pot[i] - b.pot[i]) + std::abs(a.ex[i] - b.ex[i]) + std::abs(a.ey[i] - b.ey[i]) +
                    std::abs(a.ez[i] - b.ez[i]),
                1e-13 * s)
          << gcsimd::simd_path_name(path) << " target " << i;
    }
    for (int p : {4, 9, 18}) {
      Operators g(p, gcsimd::SimdPath::Generic), v(p, path);
      std::vector<double> Mg(g.size(), 0.0), Mv(g.size(), 0.0), Lg(g.size(), 0.0), Lv(g.size(), 0.0);
      const Vec3 c{0.5, 0.5, 0.5};
      g.p2m_batch(src.size(), src.x.data(), src.y.data(), src.z.data(), src.q.data(), c, Mg.data());
      v.p2m_batch(src.size(), src.x.data(), src.y.data(), src.z.data(), src.q.data(), c, Mv.data());
      g.symmetrize(Mg.data());
      v.symmetrize(Mv.data());
      std::vector<const double *> ms(13, Mg.data());
      std::vector<Vec3> rs(13);
      for (int e = 0; e < 13; ++e) rs[e] = {3.0 + 0.2 * e, -2.5 + 0.1 * e, 2.0 - 0.3 * e};
      g.m2l_batch(13, ms.data(), rs.data(), Lg.data());
      v.m2l_batch(13, ms.data(), rs.data(), Lv.data());
      double dm = 0, sm = 0, dl = 0, sl = 0;
      for (std::size_t i = 0; i < g.size(); ++i) {
        dm = std::max(dm, std::abs(Mg[i] - Mv[i]));
        sm = std::max(sm, std::abs(Mg[i]));
        dl = std::max(dl, std::abs(Lg[i] - Lv[i]));
        sl = std::max(sl, std::abs(Lg[i]));
      }
      EXPECT_LT(dm, 1e-13 * sm) << gcsimd::simd_path_name(path) << " p2m p=" << p;
      EXPECT_LT(dl, 1e-13 * sl) << gcsimd::simd_path_name(path) << " m2l p=" << p;
      g.symmetrize(Lg.data());
      gcfmm_test::Field fg(tgt.size()), fv(tgt.size());
      g.l2p_batch(Lg.data(), c, tgt.size(), tgt.x.data(), tgt.y.data(), tgt.z.data(), fg.pot.data(), fg.ex.data(),
                  fg.ey.data(), fg.ez.data());
      v.l2p_batch(Lg.data(), c, tgt.size(), tgt.x.data(), tgt.y.data(), tgt.z.data(), fv.pot.data(), fv.ex.data(),
                  fv.ey.data(), fv.ez.data());
      for (std::size_t i = 0; i < tgt.size(); ++i)
        EXPECT_LT(std::abs(fg.ez[i] - fv.ez[i]) + std::abs(fg.pot[i] - fv.pot[i]),
                  1e-12 * (std::abs(fg.ez[i]) + std::abs(fg.pot[i])))
            << gcsimd::simd_path_name(path) << " l2p p=" << p << " target " << i;
    }
  }
}

// The kernels of p2p_kernel_within(): one pair at a time (one source, 64 targets at distances
// log-uniform over 44 decades, beyond the single-precision estimate's range at both ends too),
// each term against long double. A reduced kernel stays within its stated term error (the
// potential within a third of it) and comes near it (the test would pass vacuously on a
// full-precision kernel otherwise); the full-precision one is round-off and is p2p_with().
TEST(P2P, KernelsWithinTheirTermError) {
  std::mt19937 g(17);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const std::size_t nt = 64, trials = 400;
  for (gcsimd::SimdPath path : {gcsimd::SimdPath::Generic, gcsimd::SimdPath::AVX2, gcsimd::SimdPath::AVX512}) {
    if (!gcsimd::simd_path_available(path)) {
      std::printf("[ skipped  ] path %s not available on this CPU\n", gcsimd::simd_path_name(path));
      continue;
    }
    for (double tolerance : {0.0, 1e-12, 1e-7, 1e-6}) {
      const P2PKernel k = p2p_kernel_within(tolerance, path);
      EXPECT_LE(k.term_error, tolerance) << gcsimd::simd_path_name(path);
      double worst_pot = 0.0, worst_field = 0.0;
      for (std::size_t trial = 0; trial < trials; ++trial) {
        std::vector<double> x(nt), y(nt), z(nt), pot(nt, 0.0), ex(nt, 0.0), ey(nt, 0.0), ez(nt, 0.0);
        for (std::size_t i = 0; i < nt; ++i) {
          const double r = std::pow(10.0, -22.0 + 44.0 * u(g)), ct = 2.0 * u(g) - 1.0, ph = 6.283185307179586 * u(g);
          const double st = std::sqrt(1.0 - ct * ct);
          x[i] = r * st * std::cos(ph);
          y[i] = r * st * std::sin(ph);
          z[i] = r * ct;
        }
        const double xs = 0.0, ys = 0.0, zs = 0.0, qs = 1.0;
        k.run(nt, x.data(), y.data(), z.data(), 1, &xs, &ys, &zs, &qs, 0.0, 0.0, 0.0, pot.data(), ex.data(),
              ey.data(), ez.data(), 0.0);
        for (std::size_t i = 0; i < nt; ++i) {
          const long double dx = x[i], dy = y[i], dz = z[i], r2 = dx * dx + dy * dy + dz * dz, r = std::sqrt(r2);
          const long double p = 1.0L / r, e = 1.0L / r2;    // |E| = 1 / r^2
          worst_pot = std::max(worst_pot, (double)(std::fabs(pot[i] - p) / p));
          const long double fx = ex[i] - dx / (r * r2), fy = ey[i] - dy / (r * r2), fz = ez[i] - dz / (r * r2);
          worst_field = std::max(worst_field, (double)(std::sqrt(fx * fx + fy * fy + fz * fz) / e));
        }
      }
      // round-off of a few operations on top of the stated error
      const double roundoff = 1e-15;
      EXPECT_LE(worst_pot, k.term_error / 3.0 + roundoff) << gcsimd::simd_path_name(path) << " tol " << tolerance;
      EXPECT_LE(worst_field, k.term_error + roundoff) << gcsimd::simd_path_name(path) << " tol " << tolerance;
      if (k.term_error > 0.0) EXPECT_GT(worst_field, 0.05 * k.term_error) << gcsimd::simd_path_name(path);
      std::printf("[ kernel   ] %s within %g: term error %g, measured %.3g (field) %.3g (potential)\n",
                  gcsimd::simd_path_name(path), tolerance, k.term_error, worst_field, worst_pot);
    }
    // the full-precision kernel is the one of p2p_with()
    auto src = gcfmm_test::random_cube(101, 41);
    auto tgt = gcfmm_test::random_cube(37, 42, 1.5);
    gcfmm_test::Field a(tgt.size()), b(tgt.size());
    p2p_with(path, tgt.size(), tgt.x.data(), tgt.y.data(), tgt.z.data(), src.size(), src.x.data(), src.y.data(),
             src.z.data(), src.q.data(), 0.1, -0.2, 0.3, a.pot.data(), a.ex.data(), a.ey.data(), a.ez.data());
    p2p_kernel_within(0.0, path)
        .run(tgt.size(), tgt.x.data(), tgt.y.data(), tgt.z.data(), src.size(), src.x.data(), src.y.data(),
             src.z.data(), src.q.data(), 0.1, -0.2, 0.3, b.pot.data(), b.ex.data(), b.ey.data(), b.ez.data(), 0.0);
    for (std::size_t i = 0; i < tgt.size(); ++i) {
      EXPECT_EQ(a.pot[i], b.pot[i]);
      EXPECT_EQ(a.ez[i], b.ez[i]);
    }
  }
  // the solver's share: kP2PTermShare of the accuracy when accuracy chooses the order, full
  // precision with an explicit order
  Options o;
  o.accuracy = 1e-4;
  EXPECT_DOUBLE_EQ(p2p_term_tolerance(o), kP2PTermShare * 1e-4);
  o.order = 6;
  EXPECT_EQ(p2p_term_tolerance(o), 0.0);
}
