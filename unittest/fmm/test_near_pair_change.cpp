// The near pairs' change between evaluations (near_pair_change.hpp) against closed forms and
// against an independent brute-force sum over explicit periodic copies and images.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "gcfmm/dipole_kernels.hpp"
#include "gcfmm/near_pair_change.hpp"

using namespace gcfmm;

namespace {

std::vector<std::size_t> all_targets(std::size_t n) {
  std::vector<std::size_t> t(n);
  for (std::size_t i = 0; i < n; ++i) t[i] = i;
  return t;
}

// Brute force: every other particle and its copies (i lx, j ly) with |i|, |j| <= 2, and every
// image (with its copies), near when closer than rc at either end (a particle's own image at
// any height); built from add_charge,
// add_dipole and point_force directly, without cells or minimum images.
NearChange brute_force(std::size_t n, const std::vector<double> &now, const std::vector<double> &then,
                       const std::vector<double> &q, const std::vector<double> *p, double rc, const NearGeometry &g) {
  NearChange out;
  out.field.assign(3 * n, 0.0);
  out.pot.assign(n, 0.0);
  out.force.assign(3 * n, 0.0);
  const int copies = g.periodic ? 2 : 0;
  for (std::size_t i = 0; i < n; ++i) {
    PointField fn, ft;
    const Vec3 ri{now[3 * i], now[3 * i + 1], now[3 * i + 2]};
    const Vec3 ri_t{then[3 * i], then[3 * i + 1], then[3 * i + 2]};
    for (std::size_t j = 0; j < n; ++j)
      for (int image = 0; image <= (g.electrode ? 1 : 0); ++image)
        for (int cx = -copies; cx <= copies; ++cx)
          for (int cy = -copies; cy <= copies; ++cy) {
            if (j == i && !image && cx == 0 && cy == 0) continue;
            const Vec3 shift{cx * g.lx, cy * g.ly, 0.0};
            Vec3 sn{now[3 * j], now[3 * j + 1], now[3 * j + 2]};
            Vec3 st{then[3 * j], then[3 * j + 1], then[3 * j + 2]};
            double qs = q[j];
            Vec3 ps = p ? Vec3{(*p)[3 * j], (*p)[3 * j + 1], (*p)[3 * j + 2]} : Vec3{};
            if (image) {
              sn = mirror_point(sn, g.electrode_z);
              st = mirror_point(st, g.electrode_z);
              qs = image_charge(qs);
              ps = image_dipole(ps);
            }
            const Vec3 dn = ri - (sn + shift), dt = ri_t - (st + shift);
            const bool own_image = j == i && image && cx == 0 && cy == 0;    // near at any height
            if (!own_image && !(norm2(dn) < rc * rc || norm2(dt) < rc * rc)) continue;
            add_charge(qs, dn, fn);
            add_charge(qs, dt, ft);
            if (p) {
              add_dipole(ps, dn, fn);
              add_dipole(ps, dt, ft);
            }
          }
    const Vec3 pi = p ? Vec3{(*p)[3 * i], (*p)[3 * i + 1], (*p)[3 * i + 2]} : Vec3{};
    const Vec3 f = point_force(q[i], pi, fn) - point_force(q[i], pi, ft);
    const Vec3 e = fn.e - ft.e;
    out.pot[i] = fn.pot - ft.pot;
    const double fv[3] = {f.x, f.y, f.z}, ev[3] = {e.x, e.y, e.z};
    for (int a = 0; a < 3; ++a) {
      out.force[3 * i + a] = fv[a];
      out.field[3 * i + a] = ev[a];
    }
  }
  return out;
}

double max_abs(const std::vector<double> &v) {
  double m = 0.0;
  for (double x : v) m = std::max(m, std::fabs(x));
  return m;
}

}  // namespace

// a charge above a grounded plane moved from h1 to h2: the change of its image force
// -q^2 / (4 h^2) (the image -q at distance 2 h), exact to round-off
TEST(NearPairChange, ImageForceOfOneCharge) {
  NearGeometry g;
  g.electrode = true;
  g.electrode_z = -1.0;
  NearPairChange near(5.0, g);
  const double q = 1.7, h1 = 2.0, h2 = 0.75;
  const std::vector<double> then{0.3, -0.2, g.electrode_z + h1}, now{0.35, -0.1, g.electrode_z + h2}, qs{q};
  const std::size_t t = 0;
  NearChange out;
  ASSERT_TRUE(near.compute(1, now.data(), then.data(), qs.data(), nullptr, &t, 1, out));
  const double expected = -q * q / 4.0 * (1.0 / (h2 * h2) - 1.0 / (h1 * h1));
  EXPECT_NEAR(out.force[2], expected, 1e-14 * std::fabs(expected));
  EXPECT_NEAR(out.force[0], 0.0, 1e-15);
  EXPECT_NEAR(out.force[1], 0.0, 1e-15);
  // potential of the image -q at 2 h
  EXPECT_NEAR(out.pot[0], -q / (2 * h2) + q / (2 * h1), 1e-14);
  // its own image counts at any height: the same change with a cutoff below 2 h at both ends
  NearPairChange short_near(0.5, g);
  NearChange out2;
  ASSERT_TRUE(short_near.compute(1, now.data(), then.data(), qs.data(), nullptr, &t, 1, out2));
  EXPECT_EQ(out2.force[2], out.force[2]);
}

// a pair entering the cutoff is counted with both ends (no jump): Coulomb's law
// F = q_i q_j d / r^3 now minus then, though it was outside the cutoff then
TEST(NearPairChange, PairEnteringTheCutoff) {
  NearPairChange near(1.0, NearGeometry{});
  const std::vector<double> then{0, 0, 0, 1.2, 0, 0}, now{0, 0, 0, 0.8, 0, 0}, q{2.0, -0.5};
  const std::vector<std::size_t> t{0, 1};
  NearChange out;
  ASSERT_TRUE(near.compute(2, now.data(), then.data(), q.data(), nullptr, t.data(), 2, out));
  const double fx = 2.0 * -0.5 * (-1.0 / (0.8 * 0.8) + 1.0 / (1.2 * 1.2));   // on 0, d = -x
  EXPECT_NEAR(out.force[0], fx, 1e-14);
  EXPECT_NEAR(out.force[3], -fx, 1e-14);
  EXPECT_EQ(near.pairs(), 2u);
  // beyond the cutoff at both ends: nothing
  const std::vector<double> far_then{0, 0, 0, 1.5, 0, 0}, far_now{0, 0, 0, 1.1, 0, 0};
  ASSERT_TRUE(near.compute(2, far_now.data(), far_then.data(), q.data(), nullptr, t.data(), 2, out));
  EXPECT_EQ(out.force[0], 0.0);
  EXPECT_EQ(near.pairs(), 0u);
}

// charges and held dipoles in a periodic box above a plane, moved a little: the cell search
// against the brute force over explicit copies and images. A missing copy, image, dipole term or
// sign shows as an O(1) relative difference; the tolerance is round-off of the differences.
TEST(NearPairChange, AgreesWithBruteForce) {
  for (const bool periodic : {false, true})
    for (const bool electrode : {false, true}) {
      NearGeometry g;
      g.periodic = periodic;
      g.lx = 10.0;
      g.ly = 8.0;
      g.electrode = electrode;
      g.electrode_z = -0.1;
      const double rc = 2.5;
      const std::size_t n = 120;
      std::mt19937 rng(7);
      std::uniform_real_distribution<double> u(0.0, 1.0), d(-0.15, 0.15), s(-1.0, 1.0);
      std::vector<double> now(3 * n), then(3 * n), q(n), p(3 * n);
      for (std::size_t i = 0; i < n; ++i) {
        now[3 * i] = g.lx * u(rng);
        now[3 * i + 1] = g.ly * u(rng);
        now[3 * i + 2] = 0.2 + 6.0 * u(rng);
        q[i] = s(rng);
        for (int a = 0; a < 3; ++a) p[3 * i + a] = 0.3 * s(rng);
      }
      // one particle just across the periodic edge from another: a pair only through the copy
      now[0] = 0.05;
      now[3] = g.lx - 0.1;
      now[1] = now[4] = 1.0;
      now[2] = now[5] = 1.0;
      for (std::size_t i = 0; i < n; ++i) {
        for (int a = 0; a < 3; ++a) then[3 * i + a] = now[3 * i + a] - d(rng);
        then[3 * i + 2] = std::max(then[3 * i + 2], 0.05);
      }
      NearPairChange near(rc, g);
      const auto targets = all_targets(n);
      NearChange out;
      ASSERT_TRUE(near.compute(n, now.data(), then.data(), q.data(), p.data(), targets.data(), n, out));
      const NearChange ref = brute_force(n, now, then, q, &p, rc, g);
      const double scale = max_abs(ref.force);
      ASSERT_GT(scale, 0.0);
      for (std::size_t k = 0; k < 3 * n; ++k) {
        EXPECT_NEAR(out.force[k], ref.force[k], 1e-11 * scale) << periodic << electrode << " " << k;
        EXPECT_NEAR(out.field[k], ref.field[k], 1e-11 * max_abs(ref.field));
      }
      for (std::size_t k = 0; k < n; ++k) EXPECT_NEAR(out.pot[k], ref.pot[k], 1e-11 * max_abs(ref.pot));
      // a subset of targets gives the same rows
      const std::vector<std::size_t> some{5, 0, 77};
      NearChange part;
      ASSERT_TRUE(near.compute(n, now.data(), then.data(), q.data(), p.data(), some.data(), some.size(), part));
      for (std::size_t t = 0; t < some.size(); ++t)
        for (int a = 0; a < 3; ++a) EXPECT_EQ(part.force[3 * t + a], out.force[3 * some[t] + a]);
    }
}

// no displacement, no change; a displacement too large for the periodic cell is refused
// (compute returns false) and a particle below the electrode throws
TEST(NearPairChange, LimitsAndErrors) {
  NearGeometry g;
  g.periodic = true;
  g.lx = g.ly = 6.0;
  g.electrode = true;
  NearPairChange near(2.0, g);
  const std::vector<double> x{1, 1, 1, 2, 1.5, 1.2}, q{1.0, -1.0};
  const std::vector<std::size_t> t{0, 1};
  NearChange out;
  ASSERT_TRUE(near.compute(2, x.data(), x.data(), q.data(), nullptr, t.data(), 2, out));
  EXPECT_EQ(max_abs(out.force), 0.0);
  EXPECT_TRUE(near.fits(0.49));
  EXPECT_FALSE(near.fits(0.5));    // 2 + 2 x 0.5 = 3 = half the period
  std::vector<double> moved = x;
  moved[0] += 0.6;
  EXPECT_FALSE(near.compute(2, moved.data(), x.data(), q.data(), nullptr, t.data(), 2, out));
  std::vector<double> below = x;
  below[2] = -0.1;
  EXPECT_THROW(near.compute(2, below.data(), x.data(), q.data(), nullptr, t.data(), 2, out), std::invalid_argument);
  EXPECT_THROW(NearPairChange(0.0, g), std::invalid_argument);
  NearGeometry bad;
  bad.periodic = true;
  EXPECT_THROW(NearPairChange(1.0, bad), std::invalid_argument);
}
