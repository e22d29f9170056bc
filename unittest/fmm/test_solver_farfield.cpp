// Solver hooks into the 2D-periodic far field (FarField::Exact / Average). The far field's
// own accuracy is tested in test_lattice_sum / test_average_field.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "gcfmm/far_field.hpp"
#include "gcfmm/kernels.hpp"
#include "gcfmm/solver.hpp"
#include "fmm_test_util.hpp"

using namespace gcfmm;
using gcfmm_test::Field;

namespace {
Field periodic_run(const gcfmm_test::Particles &p, FarField ff, Stats *st = nullptr, int part = 0, int nparts = 1) {
  Options o;
  o.accuracy = 1e-4;
  o.boundary = Boundary::Periodic2D;
  o.farfield = ff;
  o.images = 1;
  Solver s(o);
  s.set_box(0.0, 0.0, 28.0, 28.0);
  s.build(p.size(), p.x.data(), p.y.data(), p.z.data());
  Field f(p.size());
  s.evaluate(p.q.data(), f.pot.data(), f.ex.data(), f.ey.data(), f.ez.data(), part, nparts);
  if (st) *st = s.stats();
  return f;
}
}  // namespace

// The exact far field changes the near-field result, is finite, keeps the total force ~ 0
// (a periodic layer exerts no net force on itself; FMM + far-field errors ~ accuracy), and
// the work partitions still sum bit-identically.
TEST(SolverFarField, ExactHook) {
  auto p = gcfmm_test::deposition(1000, 113);
  Stats st;
  Field f = periodic_run(p, FarField::Exact, &st);
  Field n = periodic_run(p, FarField::None);
  double d = 0, sz = 0, sabs = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    d = std::max(d, std::abs(f.ez[i] - n.ez[i]));
    sz += p.q[i] * f.ez[i];
    sabs += std::abs(p.q[i] * f.ez[i]);
    EXPECT_TRUE(std::isfinite(f.ez[i]));
  }
  EXPECT_GT(d, 0.0);
  EXPECT_LT(std::abs(sz), 1e-3 * sabs);
  EXPECT_GE(st.estimated_error, 0.0);
  Field a = periodic_run(p, FarField::Exact, nullptr, 0, 2), b = periodic_run(p, FarField::Exact, nullptr, 1, 2);
  std::size_t mism = 0;
  for (std::size_t i = 0; i < p.size(); ++i) mism += (a.ez[i] + b.ez[i] != f.ez[i]) + (a.pot[i] + b.pot[i] != f.pot[i]);
  EXPECT_EQ(mism, 0u);
}

// The average far field adds a field along z only (uniform slab outside the block; its
// in-plane parts cancel by symmetry up to the targets' offsets) and is finite.
TEST(SolverFarField, AverageHook) {
  auto p = gcfmm_test::deposition(1000, 114);
  Field f = periodic_run(p, FarField::Average);
  Field n = periodic_run(p, FarField::None);
  double dz = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    EXPECT_TRUE(std::isfinite(f.ez[i]) && std::isfinite(f.pot[i]));
    dz = std::max(dz, std::abs(f.ez[i] - n.ez[i]));
  }
  EXPECT_GT(dz, 0.0);
}

// A single charged particle (bed of zero height by the automatic bed range) must not fail.
TEST(SolverFarField, AverageWithFlatBed) {
  auto p = gcfmm_test::deposition(300, 115);
  for (std::size_t i = 1; i < p.size(); ++i) p.q[i] = 0.0;
  Field f = periodic_run(p, FarField::Average);
  for (std::size_t i = 0; i < p.size(); ++i) EXPECT_TRUE(std::isfinite(f.ez[i]));
}

namespace {
// E_z on the axis of a uniform box of unit density, half sides a, b in x and y, spanning
// [z1, z2] in z, at height t: the field of a rectangle of unit surface density on its axis,
// 4 atan(a b / (d sqrt(a^2 + b^2 + d^2))) sign(d), integrated over the box's height by
// composite 5-point Gauss-Legendre (independent of cuboid_field's closed form).
double box_axis_field(double a, double b, double z1, double z2, double t) {
  static const double xg[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831,
                               0.9061798459386640};
  static const double wg[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665,
                               0.2369268850561891};
  auto piece = [&](double lo, double hi) {
    double s = 0;
    const int m = 400;
    const double hstep = (hi - lo) / m;
    for (int k = 0; k < m; ++k)
      for (int g = 0; g < 5; ++g) {
        const double zp = lo + hstep * (k + 0.5 * (xg[g] + 1.0));
        const double d = t - zp, ad = std::abs(d);
        s += 0.5 * hstep * wg[g] * 4.0 * (d > 0 ? 1.0 : -1.0) * std::atan(a * b / (ad * std::sqrt(a * a + b * b + d * d)));
      }
    return s;
  };
  if (t <= z1 || t >= z2) return piece(z1, z2);
  return piece(z1, t) + piece(t, z2);
}

Field periodic_run_bed(const gcfmm_test::Particles &p, double l, FarField ff, Solver **keep = nullptr) {
  Options o;
  o.accuracy = 1e-6;
  o.boundary = Boundary::Periodic2D;
  o.farfield = ff;
  o.images = 1;
  o.bed_zlo = 0.0;
  o.bed_zhi = 40.0;
  auto *s = new Solver(o);
  s->set_box(0.0, 0.0, l, l);
  s->build(p.size(), p.x.data(), p.y.data(), p.z.data());
  Field f(p.size());
  s->evaluate(p.q.data(), f.pot.data(), f.ex.data(), f.ey.data(), f.ez.data());
  if (keep)
    *keep = s;
  else
    delete s;
  return f;
}
}  // namespace

// The average far field through the solver against the closed form on the cell's axis: a
// uniform slab of density rho = Q / (A H_p) (sheet field 2 pi rho (2 clamp(z) - zlo - zhi))
// minus the 3 x 3 block, whose axis field is a 1D quadrature (doc/theory.md, eq. (4.7)).
TEST(SolverFarField, AverageMatchesClosedFormOnAxis) {
  auto p = gcfmm_test::deposition(1000, 116);
  const double l = 28.0, zs[] = {5.0, 20.0, 38.0, 60.0, 150.0};
  for (int k = 0; k < 5; ++k) {
    p.x[k] = 0.5 * l;
    p.y[k] = 0.5 * l;
    p.z[k] = zs[k];
  }
  Field fa = periodic_run_bed(p, l, FarField::Average), fn = periodic_run_bed(p, l, FarField::None);
  double qsum = 0;
  for (double q : p.q) qsum += q;
  const double rho = qsum / (l * l * 40.0), sheet = 2.0 * M_PI * rho * 40.0;
  for (int k = 0; k < 5; ++k) {
    const double c = std::min(std::max(zs[k], 0.0), 40.0);
    const double ez = 2.0 * M_PI * rho * (2.0 * c - 40.0) - rho * box_axis_field(1.5 * l, 1.5 * l, 0.0, 40.0, zs[k]);
    EXPECT_NEAR(fa.ez[k] - fn.ez[k], ez, 1e-9 * sheet) << "z = " << zs[k];
    EXPECT_NEAR(fa.ex[k] - fn.ex[k], 0.0, 1e-9 * sheet) << "z = " << zs[k];
    EXPECT_NEAR(fa.ey[k] - fn.ey[k], 0.0, 1e-9 * sheet) << "z = " << zs[k];
  }
}

// With FarField::Average and a net-charged layer, the energy 1/2 sum q_i u_i of
// energy_potential() has minus the applied far-field force as its gradient (central finite
// differences of the far parts, Average minus None, so the FMM's own error cancels), while
// 1/2 sum q_i pot_i gives only half of it (doc/theory.md, eq. (4.10)).
TEST(SolverFarField, AverageEnergyGradientIsTheForce) {
  const std::size_t n = 200;
  auto p = gcfmm_test::deposition(n, 117, 10.0, 10.0, 60.0);
  const double l = 10.0;
  auto far_energy = [&](const gcfmm_test::Particles &pp, double *upot) {
    Solver *sa = nullptr, *sn = nullptr;
    Field fa = periodic_run_bed(pp, l, FarField::Average, &sa), fn = periodic_run_bed(pp, l, FarField::None, &sn);
    std::vector<double> ua(n);
    sa->energy_potential(ua.data());
    double e = 0, ep = 0;
    for (std::size_t i = 0; i < n; ++i) {
      e += 0.5 * pp.q[i] * (ua[i] - fn.pot[i]);
      ep += 0.5 * pp.q[i] * (fa.pot[i] - fn.pot[i]);
    }
    delete sa;
    delete sn;
    *upot = ep;
    return e;
  };
  Field fa = periodic_run_bed(p, l, FarField::Average), fn = periodic_run_bed(p, l, FarField::None);
  const double delta = 1e-3;
  for (std::size_t k : {3u, 50u, 190u}) {
    const double force[3] = {p.q[k] * (fa.ex[k] - fn.ex[k]), p.q[k] * (fa.ey[k] - fn.ey[k]),
                             p.q[k] * (fa.ez[k] - fn.ez[k])};
    const double scale = std::abs(force[0]) + std::abs(force[1]) + std::abs(force[2]);
    for (int c = 0; c < 3; ++c) {
      auto pp = p, pm = p;
      double *xp = c == 0 ? &pp.x[k] : (c == 1 ? &pp.y[k] : &pp.z[k]);
      double *xm = c == 0 ? &pm.x[k] : (c == 1 ? &pm.y[k] : &pm.z[k]);
      *xp += delta;
      *xm -= delta;
      double up_pot, um_pot;
      const double up = far_energy(pp, &up_pot), um = far_energy(pm, &um_pot);
      EXPECT_NEAR(-(up - um) / (2 * delta), force[c], 1e-6 * scale) << "particle " << k << " component " << c;
      EXPECT_NEAR(-(up_pot - um_pot) / (2 * delta), 0.5 * force[c], 1e-6 * scale)
          << "particle " << k << " component " << c;
    }
  }
}

// set_z_range: the operator covers the given range, so a solver that saw only the upper half of
// a column first and then the whole column gives the same field as a fresh solver (to the
// far field's accuracy), without setting the operator up again; bad ranges are refused.
TEST(SolverFarField, ZRangeHintCoversLaterBuilds) {
  auto p = gcfmm_test::deposition(1000, 114);
  Options o;
  o.accuracy = 1e-4;
  o.boundary = Boundary::Periodic2D;
  o.farfield = FarField::Exact;
  Solver hinted(o), fresh(o);
  hinted.set_box(0.0, 0.0, 28.0, 28.0);
  fresh.set_box(0.0, 0.0, 28.0, 28.0);
  hinted.set_z_range(0.0, 170.0);
  // first only the particles above z = 80 (the rain), then all of them
  gcfmm_test::Particles top;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.z[i] > 80.0) {
      top.x.push_back(p.x[i]);
      top.y.push_back(p.y[i]);
      top.z.push_back(p.z[i]);
      top.q.push_back(p.q[i]);
    }
  ASSERT_GT(top.size(), 10u);
  hinted.build(top.size(), top.x.data(), top.y.data(), top.z.data());
  Field ft(top.size());
  hinted.evaluate(top.q.data(), ft.pot.data(), ft.ex.data(), ft.ey.data(), ft.ez.data());
  const double setup_first = hinted.stats().t_build;
  hinted.build(p.size(), p.x.data(), p.y.data(), p.z.data());
  fresh.build(p.size(), p.x.data(), p.y.data(), p.z.data());
  Field fh(p.size()), ff(p.size());
  hinted.evaluate(p.q.data(), fh.pot.data(), fh.ex.data(), fh.ey.data(), fh.ez.data());
  fresh.evaluate(p.q.data(), ff.pot.data(), ff.ex.data(), ff.ey.data(), ff.ez.data());
  // both within 1e-4 of the truth: they differ by less than twice that
  EXPECT_LT(gcfmm_test::force_error(p.q, fh, ff), 2e-4);
  // the second build reused the operator: no SVD set-up in it (set-up ~0.1-1 s, build ~ms)
  EXPECT_LT(hinted.stats().t_build, 0.5 * setup_first);
  EXPECT_THROW(hinted.set_z_range(1.0, 0.0), std::invalid_argument);
  EXPECT_THROW(hinted.set_z_range(0.0, NAN), std::invalid_argument);
}

// The compressed operator (truncated SVD per block) gives the field of the dense one, and a
// block on which Eigen's divide-and-conquer SVD returns NaN (this cell and column did, with
// Eigen 3.4.0) stays dense instead of poisoning the field. Tolerance: the truncation drops
// singular values below 1e-6 x accuracy = 1e-10 of each block's largest; 1e-8 of the field
// leaves a factor 100 for the growth with the box offset (doc/theory.md, after eq. (4.6)).
TEST(SolverFarField, CompressedOperatorMatchesDense) {
  for (double l : {0.4577, 0.9155}) {
    const double zhi = 5.864 * l;
    PeriodicFarField compressed, dense;
    compressed.setup(0.0, 0.0, l, l, 0.0, zhi, 1, 1e-4);
    int pxy = 0, pz = 0;
    double hzl = 0.0;
    PeriodicFarField::parameters_for(1e-4, &pxy, &pz, &hzl);
    dense.setup_explicit(0.0, 0.0, l, l, 0.0, zhi, 1, pxy, pz, hzl * l);
    ASSERT_TRUE(std::isfinite(compressed.estimated_error())) << "l = " << l;
    EXPECT_LT(compressed.estimated_error(), 1e-4);
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const std::size_t n = 300;
    std::vector<double> x(n), y(n), z(n), q(n);
    for (std::size_t i = 0; i < n; ++i) {
      x[i] = l * u(rng);
      y[i] = l * u(rng);
      z[i] = zhi * u(rng);
      q[i] = (i % 2) ? 1.0 : -1.0;
    }
    std::vector<double> ec(3 * n, 0.0), ed(3 * n, 0.0);
    compressed.evaluate(n, x.data(), y.data(), z.data(), q.data(), 0, n, nullptr, ec.data(),
                        ec.data() + n, ec.data() + 2 * n);
    dense.evaluate(n, x.data(), y.data(), z.data(), q.data(), 0, n, nullptr, ed.data(),
                   ed.data() + n, ed.data() + 2 * n);
    double num = 0.0, den = 0.0;
    for (std::size_t k = 0; k < 3 * n; ++k) {
      ASSERT_TRUE(std::isfinite(ec[k]));
      num += (ec[k] - ed[k]) * (ec[k] - ed[k]);
      den += ed[k] * ed[k];
    }
    EXPECT_LT(std::sqrt(num / den), 1e-8) << "l = " << l;
  }
}
