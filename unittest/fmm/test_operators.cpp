// Translation operators of gcfmm in isolation, against direct evaluation of the 1/r sum.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "gcfmm/expansions.hpp"
#include "gcfmm/kernels.hpp"
#include "fmm_test_util.hpp"

using namespace gcfmm;
using gcfmm_test::Particles;

namespace {

// sources in a cube of half side 0.5 around cs, one target point
struct SourceSet {
  Particles src;
  Vec3 cs{0.0, 0.0, 0.0};
  SourceSet(unsigned seed, Vec3 c) : cs(c) {
    src = gcfmm_test::random_cube(20, seed);
    for (std::size_t i = 0; i < src.size(); ++i) {
      src.x[i] += c.x - 0.5;
      src.y[i] += c.y - 0.5;
      src.z[i] += c.z - 0.5;
    }
  }
  void direct(const Vec3 &t, double &pot, double &ex, double &ey, double &ez) const {
    pot = ex = ey = ez = 0.0;
    p2p(1, &t.x, &t.y, &t.z, src.size(), src.x.data(), src.y.data(), src.z.data(), src.q.data(), 0, 0, 0, &pot, &ex,
        &ey, &ez);
  }
};

double field_err(double ex, double ey, double ez, double rx, double ry, double rz) {
  return std::sqrt(((ex - rx) * (ex - rx) + (ey - ry) * (ey - ry) + (ez - rz) * (ez - rz)) /
                   (rx * rx + ry * ry + rz * rz));
}

}  // namespace

// Solid harmonics satisfy the addition theorem behind every operator:
// 1/|x-y| = sum conj(Y(y)) T(x); with |y|/|x| = 0.3 and p = 20 the truncation is 0.3^21 ~ 1e-11.
TEST(Operators, HarmonicsExpansionOfInverseDistance) {
  const int p = 20;
  Operators ops(p);
  const int S = (p + 1) * (p + 1);
  std::vector<double> yr(S), yi(S), tr(S), ti(S);
  const Vec3 xv{1.0, -2.0, 1.5}, yv{0.3, 0.2, -0.4};
  ops.regular(yv, p, yr.data(), yi.data());
  ops.irregular(xv, p, tr.data(), ti.data());
  double s = 0.0;
  for (int i = 0; i < S; ++i) s += yr[i] * tr[i] + yi[i] * ti[i];  // Re(conj(Y) T)
  const double ref = 1.0 / std::sqrt(norm2(xv - yv));
  EXPECT_LT(std::abs(s - ref) / ref, 1e-10);
}

// P2M then evaluation of the multipole (M2P), and P2M + M2M (children to parent):
// error falls geometrically with order, ratio (source radius / distance) ~ 0.87/3 per order.
TEST(Operators, P2M_M2M_ConvergeGeometrically) {
  SourceSet s(1, {0.0, 0.0, 0.0});
  const Vec3 t{2.0, 1.5, -1.0};  // |t| = 2.7, source radius <= 0.87
  double pot, ex, ey, ez;
  s.direct(t, pot, ex, ey, ez);
  double prev = 1.0;
  for (int p : {2, 4, 6, 8, 10, 12}) {
    Operators ops(p);
    std::vector<double> M(ops.size(), 0.0), Mc(ops.size(), 0.0), Mp(ops.size(), 0.0);
    ops.p2m(s.src.size(), s.src.x.data(), s.src.y.data(), s.src.z.data(), s.src.q.data(), s.cs, M.data());
    ops.symmetrize(M.data());
    const double e1 = std::abs(ops.m2p_potential(M.data(), t - s.cs) - pot) / std::abs(pot);
    // P2M about an off-centre child centre, then M2M to cs
    const Vec3 cc{0.1, -0.05, 0.08};
    ops.p2m(s.src.size(), s.src.x.data(), s.src.y.data(), s.src.z.data(), s.src.q.data(), cc, Mc.data());
    ops.symmetrize(Mc.data());
    ops.m2m(Mc.data(), cc - s.cs, Mp.data());
    ops.symmetrize(Mp.data());
    const double e2 = std::abs(ops.m2p_potential(Mp.data(), t - s.cs) - pot) / std::abs(pot);
    // bound: (0.87/2.7)^(p+1) times a modest constant
    const double bound = 10.0 * std::pow(0.87 / 2.7, p + 1);
    EXPECT_LT(e1, bound) << "p=" << p;
    EXPECT_LT(e2, 2.0 * bound) << "p=" << p;
    EXPECT_LT(e1, prev) << "p=" << p;
    prev = e1;
  }
}

// P2M + M2L + L2P (potential and field), and L2L in between: compared with direct sums at
// several targets around the local centre. Errors must fall geometrically: the MAC ratio is
// (r_s + r_t) / d = (0.87 + 0.5) / 4.5 ~ 0.3.
TEST(Operators, M2L_L2L_L2P_ConvergeGeometrically) {
  SourceSet s(2, {0.0, 0.0, 0.0});
  const Vec3 ct{3.0, -2.5, 2.0};  // |ct| = 4.4
  std::mt19937_64 g(7);
  std::uniform_real_distribution<double> u(-0.28, 0.28);
  std::vector<Vec3> targets(10);
  for (auto &t : targets) t = {ct.x + u(g), ct.y + u(g), ct.z + u(g)};
  std::vector<double> prevs{1.0, 1.0, 1.0};
  for (int p : {2, 4, 6, 8, 10, 12, 14}) {
    Operators ops(p);
    std::vector<double> M(ops.size(), 0.0), L(ops.size(), 0.0), Lc(ops.size(), 0.0);
    ops.p2m(s.src.size(), s.src.x.data(), s.src.y.data(), s.src.z.data(), s.src.q.data(), s.cs, M.data());
    ops.symmetrize(M.data());
    ops.m2l(M.data(), ct - s.cs, L.data());
    ops.symmetrize(L.data());
    const Vec3 cc{ct.x + 0.1, ct.y - 0.12, ct.z + 0.07};  // child centre
    ops.l2l(L.data(), cc - ct, Lc.data());
    ops.symmetrize(Lc.data());
    double ep = 0.0, ef = 0.0, ec = 0.0;
    for (const auto &t : targets) {
      double pot, ex, ey, ez;
      s.direct(t, pot, ex, ey, ez);
      double fp = 0, fx = 0, fy = 0, fz = 0;
      ops.l2p(L.data(), t - ct, fp, fx, fy, fz);
      ep = std::max(ep, std::abs(fp - pot) / std::abs(pot));
      ef = std::max(ef, field_err(fx, fy, fz, ex, ey, ez));
      double cp = 0, cx = 0, cy = 0, cz = 0;
      ops.l2p(Lc.data(), t - cc, cp, cx, cy, cz);
      ec = std::max(ec, field_err(cx, cy, cz, ex, ey, ez));
    }
    // 0.3^(p+1) with a constant that covers the field (one order lower, factor p)
    const double bound = 20.0 * (p + 1) * std::pow(1.37 / 4.4, p);
    EXPECT_LT(ep, bound) << "p=" << p;
    EXPECT_LT(ef, bound) << "p=" << p;
    EXPECT_LT(ec, bound) << "p=" << p;
    EXPECT_LT(ef, prevs[1]) << "p=" << p;
    EXPECT_LT(ec, prevs[2]) << "p=" << p;
    prevs = {ep, ef, ec};
    if (p == 14) {
      EXPECT_LT(ep, 1e-7);
      EXPECT_LT(ef, 1e-6);
    }
  }
}

// L2L is exact for a local expansion of degree p (a polynomial): shifting and evaluating must
// agree with evaluating the original to round-off, even far from convergence.
TEST(Operators, L2LExactForPolynomial) {
  const int p = 8;
  Operators ops(p);
  std::vector<double> L(ops.size(), 0.0), Lc(ops.size(), 0.0);
  std::mt19937_64 g(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int S = (p + 1) * (p + 1);
  for (int i = 0; i < S; ++i) {
    L[i] = u(g);
    L[S + i] = u(g);
  }
  ops.symmetrize(L.data());
  const Vec3 b{0.3, -0.2, 0.25};
  ops.l2l(L.data(), b, Lc.data());
  ops.symmetrize(Lc.data());
  const Vec3 r{0.1, 0.2, -0.15};
  double p1 = 0, x1 = 0, y1 = 0, z1 = 0, p2 = 0, x2 = 0, y2 = 0, z2 = 0;
  ops.l2p(L.data(), b + r, p1, x1, y1, z1);
  ops.l2p(Lc.data(), r, p2, x2, y2, z2);
  EXPECT_LT(std::abs(p1 - p2), 1e-12 * (1.0 + std::abs(p1)));
  EXPECT_LT(std::abs(x1 - x2) + std::abs(y1 - y2) + std::abs(z1 - z2), 1e-11 * (1.0 + std::abs(x1) + std::abs(z1)));
}

// The batched (SIMD-lane) P2M, M2L and L2P used by the solver agree with the single operators
// to round-off (1e-13 relative: only the summation order differs), and a point's L2P result
// does not depend on the batch it is evaluated in (bit-identical).
TEST(Operators, BatchedMatchSingle) {
  auto src = gcfmm_test::random_cube(29, 5);
  for (int p : {3, 8, 13, 17}) {  // 17: beyond the register-blocked rows (generic path)
    Operators ops(p);
    const std::size_t es = ops.size();
    std::vector<double> M1(es, 0.0), M2(es, 0.0);
    const Vec3 c{0.45, 0.5, 0.55};
    ops.p2m(src.size(), src.x.data(), src.y.data(), src.z.data(), src.q.data(), c, M1.data());
    ops.p2m_batch(src.size(), src.x.data(), src.y.data(), src.z.data(), src.q.data(), c, M2.data());
    ops.symmetrize(M1.data());
    ops.symmetrize(M2.data());
    double d = 0, s = 0;
    for (std::size_t i = 0; i < es; ++i) {
      d = std::max(d, std::abs(M1[i] - M2[i]));
      s = std::max(s, std::abs(M1[i]));
    }
    EXPECT_LT(d, 1e-13 * s) << "p2m p=" << p;
    // 11 M2L into one local expansion: batched vs one by one
    std::vector<const double *> ms(11, M1.data());
    std::vector<Vec3> rs(11);
    for (int e = 0; e < 11; ++e) rs[e] = {3.0 + 0.1 * e, -2.0 + 0.3 * e, 2.5 - 0.2 * e};
    std::vector<double> L1(es, 0.0), L2(es, 0.0);
    for (int e = 0; e < 11; ++e) ops.m2l(M1.data(), rs[e], L1.data());
    ops.m2l_batch(11, ms.data(), rs.data(), L2.data());
    ops.symmetrize(L1.data());
    ops.symmetrize(L2.data());
    d = s = 0;
    for (std::size_t i = 0; i < es; ++i) {
      d = std::max(d, std::abs(L1[i] - L2[i]));
      s = std::max(s, std::abs(L1[i]));
    }
    EXPECT_LT(d, 1e-13 * s) << "m2l p=" << p;
    // L2P at 13 points
    auto pts = gcfmm_test::random_cube(13, 6, 0.4);
    std::vector<double> pb(13, 0), xb(13, 0), yb(13, 0), zb(13, 0);
    ops.l2p_batch(L1.data(), Vec3{0.2, 0.2, 0.2}, 13, pts.x.data(), pts.y.data(), pts.z.data(), pb.data(), xb.data(),
                  yb.data(), zb.data());
    for (int i = 0; i < 13; ++i) {
      double ps = 0, xs = 0, ys = 0, zs = 0;
      ops.l2p(L1.data(), Vec3{pts.x[i] - 0.2, pts.y[i] - 0.2, pts.z[i] - 0.2}, ps, xs, ys, zs);
      const double sc = std::abs(ps) + std::abs(xs) + std::abs(ys) + std::abs(zs);
      EXPECT_LT(std::abs(ps - pb[i]) + std::abs(xs - xb[i]) + std::abs(ys - yb[i]) + std::abs(zs - zb[i]), 1e-13 * sc);
      // the same point alone in its batch: bit-identical
      double p1 = 0, x1 = 0, y1 = 0, z1 = 0;
      ops.l2p_batch(L1.data(), Vec3{0.2, 0.2, 0.2}, 1, &pts.x[i], &pts.y[i], &pts.z[i], &p1, &x1, &y1, &z1);
      EXPECT_EQ(p1, pb[i]);
      EXPECT_EQ(x1, xb[i]);
      EXPECT_EQ(z1, zb[i]);
    }
  }
}
