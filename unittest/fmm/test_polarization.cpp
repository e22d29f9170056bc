// Point charges and dipoles, the grounded plane's images and the induced-dipole solve against
// closed forms (doc/polarization.md). Bare units throughout (the kernel 1/r).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>
#include <vector>

#include "gcfmm/dipole_kernels.hpp"
#include "gcfmm/direct_polarizable.hpp"
#include "gcfmm/polarization.hpp"

using namespace gcfmm;

namespace {

double component(const Vec3 &v, int a) { return a == 0 ? v.x : (a == 1 ? v.y : v.z); }
double component(const SymTensor &g, int a, int b)
{
  const double m[3][3] = {{g.xx, g.xy, g.xz}, {g.xy, g.yy, g.yz}, {g.xz, g.yz, g.zz}};
  return m[a][b];
}
Vec3 shifted(Vec3 d, int b, double h)
{
  (b == 0 ? d.x : (b == 1 ? d.y : d.z)) += h;
  return d;
}

// E = -grad pot and G = grad E by central differences of the kernels themselves (step 1e-5 of
// |d| = 1: truncation ~1e-10, rounding ~1e-11 of the O(1) values)
template <class Add> void check_derivatives(Add add, const Vec3 &d)
{
  const double h = 1e-5;
  PointField f;
  add(d, f);
  for (int b = 0; b < 3; ++b) {
    PointField up, dn;
    add(shifted(d, b, h), up);
    add(shifted(d, b, -h), dn);
    EXPECT_NEAR(component(f.e, b), -(up.pot - dn.pot) / (2 * h), 1e-8);
    for (int a = 0; a < 3; ++a)
      EXPECT_NEAR(component(f.g, a, b), (component(up.e, a) - component(dn.e, a)) / (2 * h), 1e-8);
  }
  EXPECT_NEAR(f.g.xx + f.g.yy + f.g.zz, 0.0, 1e-12);   // div E = 0 away from the source
}

}  // namespace

TEST(DipoleKernels, FieldIsMinusGradientOfPotentialAndGradientOfField)
{
  const Vec3 d{0.6, -0.5, 0.62};
  check_derivatives([](const Vec3 &x, PointField &f) { add_charge(1.3, x, f); }, d);
  check_derivatives([](const Vec3 &x, PointField &f) { add_dipole({0.3, -0.7, 0.45}, x, f); }, d);
}

TEST(DipoleKernels, DipoleIsTheLimitOfTwoCharges)
{
  // +-q at +-h/2 along p / |p| with q h = |p|: the pair's field differs from the point
  // dipole's by O((h / r)^2) (the octupole; the quadrupole cancels by symmetry)
  const Vec3 p{0.2, 0.5, -0.4}, d{1.1, 0.4, 0.9};
  const double pn = std::sqrt(norm2(p)), h = 1e-3;
  const Vec3 u = (1.0 / pn) * p;
  PointField pair, point;
  add_charge(pn / h, d - (0.5 * h) * u, pair);
  add_charge(-pn / h, d + (0.5 * h) * u, pair);
  add_dipole(p, d, point);
  const double scale = pn / norm2(d);   // |E| ~ p / r^3 with r ~ 1.5
  EXPECT_NEAR(pair.pot, point.pot, 1e-6 * scale);
  EXPECT_NEAR(pair.e.x, point.e.x, 1e-6 * scale);
  EXPECT_NEAR(pair.e.z, point.e.z, 1e-6 * scale);
  EXPECT_NEAR(pair.g.xz, point.g.xz, 1e-5 * scale);
}

TEST(DirectPolarizable, ChargeAboveGroundedPlane)
{
  // image force q^2 / (4 h^2) towards the plane (SI: q^2 / (16 pi eps0 h^2)), energy -q^2/(4h)
  const double q = 2.0, h = 0.7, z0 = -0.3;
  const double x = 0.1, y = 0.2, z = z0 + h;
  PolarizableSystem s = particles_of(1, &x, &y, &z, &q);
    s.electrode = true;
  s.electrode_z = z0;
  const auto r = solve_polarizable_direct(s, {});
  EXPECT_NEAR(r.force[0].z, -q * q / (4 * h * h), 1e-14);
  EXPECT_NEAR(r.force[0].x, 0.0, 1e-15);
  EXPECT_NEAR(r.energy, -q * q / (4 * h), 1e-14);
  EXPECT_NEAR(r.field[0].pot, -q / (2 * h), 1e-14);   // zero on the plane: the image's potential
}

TEST(DirectPolarizable, TwoSpheresInAUniformField)
{
  // mutually inducing point dipoles: along the field p = alpha E / (1 - 2 alpha / d^3) and the
  // force -6 p^2 / d^4 (attraction); across it p = alpha E / (1 + alpha / d^3) and +3 p^2 / d^4
  // (repulsion). Several separations, the dipoles solved to 1e-13.
  const double alpha = 0.8 * 1.0;   // beta = 0.8, radius 1
  for (double dist : {2.0, 2.5, 4.0, 8.0}) {
    for (int along = 0; along < 2; ++along) {
      const double x[2] = {0.0, along ? 0.0 : dist}, y[2] = {0.0, 0.0},
                   z[2] = {0.0, along ? dist : 0.0}, q[2] = {0.0, 0.0}, a[2] = {alpha, alpha};
      PolarizableSystem s = particles_of(2, x, y, z, q, a);
            s.applied_field = {0.0, 0.0, 1.5};
      PolarizationSettings set;
      set.tolerance = 1e-13;
      const auto r = solve_polarizable_direct(s, set);
      ASSERT_TRUE(r.report.converged);
      const double d3 = dist * dist * dist, d4 = d3 * dist;
      const double p = along ? alpha * 1.5 / (1 - 2 * alpha / d3) : alpha * 1.5 / (1 + alpha / d3);
      EXPECT_NEAR(r.dipole[1].z, p, 1e-12 * p);
      EXPECT_NEAR(r.dipole[0].x, 0.0, 1e-14);
      // force on particle 1 along the separation (z when along, x when across)
      const double f = along ? r.force[1].z : r.force[1].x;
      const double want = along ? -6 * p * p / d4 : 3 * p * p / d4;
      EXPECT_NEAR(f, want, 1e-11 * std::fabs(want)) << "d = " << dist << " along " << along;
      EXPECT_NEAR(r.force[0].x + r.force[1].x, 0.0, 1e-14);   // Newton's third law
      EXPECT_NEAR(r.force[0].z + r.force[1].z, 0.0, 1e-14);
    }
  }
}

TEST(DirectPolarizable, InducedDipoleAboveGroundedPlane)
{
  // a sphere at height h in the normal field E: its image dipole (0, 0, p) at distance 2 h adds
  // 2 p / (2h)^3 at it, so p = alpha E / (1 - alpha / (4 h^3)); the pull is -6 p^2 / (2h)^4
  const double alpha = 0.9, h = 1.1, E = 2.0, x = 0, y = 0, z = h, q = 0;
  PolarizableSystem s = particles_of(1, &x, &y, &z, &q, &alpha);
    s.applied_field = {0.0, 0.0, E};
  s.electrode = true;
  PolarizationSettings set;
  set.tolerance = 1e-14;
  const auto r = solve_polarizable_direct(s, set);
  const double p = alpha * E / (1 - alpha / (4 * h * h * h));
  EXPECT_NEAR(r.dipole[0].z, p, 1e-13 * p);
  EXPECT_NEAR(r.force[0].z, -6 * p * p / std::pow(2 * h, 4), 1e-12);
}

namespace {

PolarizableResult random_system(const std::vector<double> &pos, const std::vector<double> &q,
                                const std::vector<double> &alpha, double tol)
{
  const std::size_t n = q.size();
  static std::vector<double> x, y, z;
  x.assign(n, 0);
  y.assign(n, 0);
  z.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = pos[3 * i];
    y[i] = pos[3 * i + 1];
    z[i] = pos[3 * i + 2];
  }
  PolarizableSystem s = particles_of(n, x.data(), y.data(), z.data(), q.data(), alpha.data());
    s.applied_field = {0.0, 0.0, 0.7};
  s.electrode = true;
  s.electrode_z = -0.5;
  s.lx = 6.0;
  s.ly = 5.0;
  s.images = 1;
  PolarizationSettings set;
  set.tolerance = tol;
  set.max_iterations = 500;
  return solve_polarizable_direct(s, set);
}

void random_particles(std::size_t n, std::vector<double> &pos, std::vector<double> &q,
                      std::vector<double> &alpha)
{
  // spheres of radius 0.5, at least 1.05 apart (not touching), above the electrode at -0.5
  std::mt19937 gen(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  pos.clear();
  while (pos.size() < 3 * n) {
    const double c[3] = {6.0 * u(gen), 5.0 * u(gen), 0.2 + 3.0 * u(gen)};
    bool ok = true;
    for (std::size_t j = 0; j < pos.size(); j += 3) {
      double dx = c[0] - pos[j], dy = c[1] - pos[j + 1];
      dx -= 6.0 * std::round(dx / 6.0);
      dy -= 5.0 * std::round(dy / 5.0);
      if (dx * dx + dy * dy + (c[2] - pos[j + 2]) * (c[2] - pos[j + 2]) < 1.05 * 1.05) ok = false;
    }
    if (ok) pos.insert(pos.end(), c, c + 3);
  }
  q.resize(n);
  alpha.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    q[i] = (i % 3 == 0 ? -1.0 : 1.0) * (0.5 + u(gen));
    alpha[i] = polarizability(0.75, 0.5);
  }
}

}  // namespace

TEST(DirectPolarizable, ForceIsMinusGradientOfEnergy)
{
  // charges, induced dipoles, the applied field, the electrode's images and a 3 x 3 block of
  // periodic copies together: F_i = -dU/dr_i by central differences (step 1e-5: truncation
  // ~1e-10 of forces of O(1); the dipoles solved to 1e-14, so U is exact to that order)
  std::vector<double> pos, q, alpha;
  random_particles(8, pos, q, alpha);
  const auto r = random_system(pos, q, alpha, 1e-14);
  ASSERT_TRUE(r.report.converged);
  const double h = 1e-5;
  for (std::size_t k = 0; k < pos.size(); ++k) {
    auto up = pos, dn = pos;
    up[k] += h;
    dn[k] -= h;
    const double du = random_system(up, q, alpha, 1e-14).energy -
                      random_system(dn, q, alpha, 1e-14).energy;
    EXPECT_NEAR(component(r.force[k / 3], int(k % 3)), -du / (2 * h), 2e-8) << "coordinate " << k;
  }
}

TEST(InducedDipoles, ConjugateGradientsMatchADenseSolve)
{
  // T as an explicit 3n x 3n matrix (free space) solved by Eigen's LU against the operator solve
  const std::size_t n = 12;
  std::vector<double> pos, q, alpha;
  random_particles(n, pos, q, alpha);
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) {
      if (i == j) continue;
      for (int b = 0; b < 3; ++b) {
        Vec3 e{};
        (b == 0 ? e.x : (b == 1 ? e.y : e.z)) = 1.0;
        PointField f;
        add_dipole(e, {pos[3 * i] - pos[3 * j], pos[3 * i + 1] - pos[3 * j + 1],
                       pos[3 * i + 2] - pos[3 * j + 2]}, f);
        for (int a = 0; a < 3; ++a) A(3 * i + a, 3 * j + b) = -component(f.e, a);
      }
    }
  Eigen::VectorXd e0(3 * n);
  for (std::size_t k = 0; k < 3 * n; ++k) e0[k] = std::sin(1.0 + k);
  for (std::size_t k = 0; k < 3 * n; ++k) A(k, k) = 1.0 / alpha[k / 3];
  const Eigen::VectorXd want = A.partialPivLu().solve(e0);
  Eigen::MatrixXd T = -A;
  for (std::size_t k = 0; k < 3 * n; ++k) T(k, k) = 0.0;
  const DipoleFieldOperator op = [&](const double *p, double *out) {
    Eigen::Map<Eigen::VectorXd>(out, 3 * n) = T * Eigen::Map<const Eigen::VectorXd>(p, 3 * n);
  };
  std::vector<double> p(3 * n, 0.0);
  PolarizationSettings set;
  set.tolerance = 1e-12;
  const auto rep = solve_induced_dipoles(n, alpha.data(), e0.data(), op, p.data(), set);
  ASSERT_TRUE(rep.converged);
  EXPECT_LT(rep.iterations, int(3 * n));   // CG: at most the dimension, here far fewer
  EXPECT_LT((Eigen::Map<Eigen::VectorXd>(p.data(), 3 * n) - want).norm(), 1e-10 * want.norm());
  // warm start from the solution: one application (the residual check) and done
  const auto again = solve_induced_dipoles(n, alpha.data(), e0.data(), op, p.data(), set);
  EXPECT_TRUE(again.converged);
  EXPECT_EQ(again.iterations, 1);
}

TEST(InducedDipoles, BadInputIsRefused)
{
  const double alpha[2] = {0.1, -0.1}, e0[6] = {1, 0, 0, 1, 0, 0};
  double p[6] = {};
  const DipoleFieldOperator none = [](const double *, double *out) {
    for (int k = 0; k < 6; ++k) out[k] = 0.0;
  };
  EXPECT_THROW(solve_induced_dipoles(2, alpha, e0, none, p, {}), std::invalid_argument);
  const double x = 0, y = 0, z = -1, q = 1;
  PolarizableSystem s = particles_of(1, &x, &y, &z, &q);
    s.electrode = true;
  EXPECT_THROW(solve_polarizable_direct(s, {}), std::invalid_argument);
}

// ---- dipoles in the expansions (doc/polarization.md, section 5) ------------------------------

#include "gcfmm/expansions.hpp"

namespace {

struct Cluster {
  std::vector<double> x, y, z, q, px, py, pz;
};

Cluster cluster(const Vec3 &c, double radius, std::size_t n, unsigned seed)
{
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Cluster k;
  while (k.x.size() < n) {
    const Vec3 d{u(gen), u(gen), u(gen)};
    if (norm2(d) > 1.0) continue;
    k.x.push_back(c.x + radius * d.x);
    k.y.push_back(c.y + radius * d.y);
    k.z.push_back(c.z + radius * d.z);
    k.q.push_back(u(gen));
    k.px.push_back(u(gen));
    k.py.push_back(u(gen));
    k.pz.push_back(u(gen));
  }
  return k;
}

}  // namespace

TEST(DipoleExpansions, MultipoleOfDipolesGivesTheirPotential)
{
  // order 14, sources within 0.5 of the centre, targets at distance 4: truncation ~(1/8)^15
  const int order = 14;
  Operators ops(order);
  const Vec3 c{0.2, -0.1, 0.3};
  const Cluster k = cluster(c, 0.5, 20, 3);
  std::vector<double> M(ops.size(), 0.0);
  ops.p2m_dipoles(k.x.size(), k.x.data(), k.y.data(), k.z.data(), k.px.data(), k.py.data(), k.pz.data(), c,
                  M.data());
  ops.symmetrize(M.data());
  for (const Vec3 t : {Vec3{4.0, 0.3, -0.2}, Vec3{-1.0, 3.5, 2.0}, Vec3{0.5, 0.0, -4.1}}) {
    PointField f;
    for (std::size_t j = 0; j < k.x.size(); ++j)
      add_dipole({k.px[j], k.py[j], k.pz[j]}, t - Vec3{k.x[j], k.y[j], k.z[j]}, f);
    EXPECT_NEAR(ops.m2p_potential(M.data(), t - c), f.pot, 1e-11 * std::fabs(f.pot) + 1e-13);
  }
}

TEST(DipoleExpansions, LocalExpansionGivesFieldGradient)
{
  // charges and dipoles in a source cluster (radius 0.5), M2L to a target centre at distance 4,
  // targets within 0.5 of it: (r_s + r_t) / R = 1/4, truncation ~0.25^(p+1) = 2e-9 at p = 14
  // relative to the field's scale; the gradient converges one order slower
  const int order = 14;
  Operators ops(order);
  const Vec3 cs{0.0, 0.0, 0.0}, ct{3.0, 2.0, -1.5};   // |ct - cs| = 3.9
  const Cluster k = cluster(cs, 0.5, 25, 5);
  std::vector<double> M(ops.size(), 0.0), L(ops.size(), 0.0);
  ops.p2m(k.x.size(), k.x.data(), k.y.data(), k.z.data(), k.q.data(), cs, M.data());
  ops.p2m_dipoles(k.x.size(), k.x.data(), k.y.data(), k.z.data(), k.px.data(), k.py.data(), k.pz.data(), cs,
                  M.data());
  ops.symmetrize(M.data());
  ops.m2l(M.data(), ct - cs, L.data());
  ops.symmetrize(L.data());
  const Cluster targets = cluster(ct, 0.5, 10, 9);
  for (std::size_t i = 0; i < targets.x.size(); ++i) {
    const Vec3 t{targets.x[i], targets.y[i], targets.z[i]};
    PointField f;
    for (std::size_t j = 0; j < k.x.size(); ++j) {
      const Vec3 d = t - Vec3{k.x[j], k.y[j], k.z[j]};
      add_charge(k.q[j], d, f);
      add_dipole({k.px[j], k.py[j], k.pz[j]}, d, f);
    }
    double pot = 0, ex = 0, ey = 0, ez = 0, g[6] = {};
    ops.l2p_gradient(L.data(), t - ct, pot, ex, ey, ez, g);
    const double es = std::sqrt(norm2(f.e)), gs = std::fabs(f.g.xx) + std::fabs(f.g.zz) + std::fabs(f.g.xy);
    EXPECT_NEAR(pot, f.pot, 1e-8 * std::fabs(f.pot));
    EXPECT_NEAR(ex, f.e.x, 1e-7 * es);
    EXPECT_NEAR(ey, f.e.y, 1e-7 * es);
    EXPECT_NEAR(ez, f.e.z, 1e-7 * es);
    const double want[6] = {f.g.xx, f.g.xy, f.g.xz, f.g.yy, f.g.yz, f.g.zz};
    for (int a = 0; a < 6; ++a) EXPECT_NEAR(g[a], want[a], 1e-6 * gs) << "component " << a;
  }
}
