// Solver hooks into the 2D-periodic far field (FarField::Exact / Average). The far field's
// own accuracy is tested in test_lattice_sum / test_average_field.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

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
