// Robustness of the solver at the edges of the input range: any length scale at
// high order, and particles that nearly coincide.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "gcfmm/kernels.hpp"
#include "gcfmm/options.hpp"
#include "gcfmm/solver.hpp"
#include "fmm_test_util.hpp"

using namespace gcfmm;
using gcfmm_test::Field;

namespace {
// problem sizes: reduced under the sanitizer build (GCFMM_TEST_SMALL set by its ctest entry)
std::size_t scaled_n(std::size_t n) { return std::getenv("GCFMM_TEST_SMALL") ? n / 10 : n; }

Field solve(const gcfmm_test::Particles &p, const Options &o) {
  Solver s(o);
  s.build(p.size(), p.x.data(), p.y.data(), p.z.data());
  Field f(p.size());
  s.evaluate(p.q.data(), f.pot.data(), f.ex.data(), f.ey.data(), f.ez.data());
  return f;
}
}  // namespace

// Order 30 in a box of side 1e-9 (SI coordinates of a nanometre cell) and of side 1e3: the
// solid harmonics r^n and r^-(n+1) of unscaled coordinates over/underflow at the small box.
// The solver works in coordinates relative to the box, so both agree with direct summation.
TEST(Robustness, Order30AnyBoxSize) {
  const std::size_t n = scaled_n(6000);
  for (double side : {1e-9, 3e-9, 1e3}) {
    auto p = gcfmm_test::random_cube(n, 201, side);
    for (auto &q : p.q) q *= 1.602e-19 * 100;  // charges in coulomb, as in SI LAMMPS runs
    Options o;
    o.order = 30;
    Field f = solve(p, o);
    Field ref(n);
    direct_free(n, p.x.data(), p.y.data(), p.z.data(), p.q.data(), ref.pot.data(), ref.ex.data(), ref.ey.data(),
                ref.ez.data());
    for (std::size_t i = 0; i < n; ++i)
      ASSERT_TRUE(std::isfinite(f.ex[i]) && std::isfinite(f.ey[i]) && std::isfinite(f.ez[i]) &&
                  std::isfinite(f.pot[i]))
          << "side " << side << " particle " << i;
    const double err = gcfmm_test::force_error(p.q, f, ref);
    EXPECT_LT(err, 1e-10) << "side " << side;
    EXPECT_LT(gcfmm_test::potential_error(f, ref), 1e-10) << "side " << side;
  }
}

// The same at accuracy 1e-12 in a periodic 1 nm cell (the automatic order is 30 there).
TEST(Robustness, TightAccuracyPeriodicNanometreCell) {
  const std::size_t n = scaled_n(4000);
  const double l = 1e-9;
  auto p = gcfmm_test::deposition(n, 202);
  const double w = gcfmm_test::deposition_width(n);
  for (std::size_t i = 0; i < n; ++i) {
    p.x[i] *= l / w;
    p.y[i] *= l / w;
    p.z[i] *= l / w;
  }
  Options o;
  o.accuracy = 1e-12;
  o.boundary = Boundary::Periodic2D;
  o.farfield = FarField::None;
  Solver s(o);
  s.set_box(0.0, 0.0, l, l);
  s.build(n, p.x.data(), p.y.data(), p.z.data());
  Field f(n), ref(n);
  s.evaluate(p.q.data(), f.pot.data(), f.ex.data(), f.ey.data(), f.ez.data());
  direct_images(n, p.x.data(), p.y.data(), p.z.data(), p.q.data(), l, l, 1, ref.pot.data(), ref.ex.data(),
                ref.ey.data(), ref.ez.data());
  for (std::size_t i = 0; i < n; ++i) ASSERT_TRUE(std::isfinite(f.ex[i]) && std::isfinite(f.ez[i])) << i;
  EXPECT_LT(gcfmm_test::force_error(p.q, f, ref), 1e-10);
}

// Two charged particles closer than the coincidence radius (1e-10 of the box) but not
// identical: a std::runtime_error of type CoincidentParticles naming both input indices, also
// across the periodic boundary; uncharged pairs that close are allowed and give finite fields.
TEST(Robustness, NearlyCoincidentParticles) {
  for (double sep : {1e-12, 1e-158, 1e-170}) {
    auto p = gcfmm_test::random_cube(500, 203);
    p.x[11] = p.x[400] + sep;
    p.y[11] = p.y[400];
    p.z[11] = p.z[400];
    Solver s(Options{});
    s.build(p.size(), p.x.data(), p.y.data(), p.z.data());
    Field f(p.size());
    try {
      s.evaluate(p.q.data(), f.pot.data(), f.ex.data(), f.ey.data(), f.ez.data());
      ADD_FAILURE() << "no exception at separation " << sep;
    } catch (const CoincidentParticles &e) {
      EXPECT_EQ(std::min(e.first(), e.second()), 11u);
      EXPECT_EQ(std::max(e.first(), e.second()), 400u);
      EXPECT_NE(std::string(e.what()).find("particles 11 and 400"), std::string::npos) << e.what();
    }
    p.q[11] = p.q[400] = 0.0;
    EXPECT_NO_THROW(s.evaluate(p.q.data(), f.pot.data(), f.ex.data(), f.ey.data(), f.ez.data()));
    for (std::size_t i = 0; i < p.size(); ++i)
      ASSERT_TRUE(std::isfinite(f.ex[i]) && std::isfinite(f.pot[i])) << "separation " << sep << " particle " << i;
  }
  // across the periodic boundary: x = 1e-13 and x = 28 - 1e-13 are 2e-13 apart
  Options o;
  o.boundary = Boundary::Periodic2D;
  o.farfield = FarField::None;
  Solver sp(o);
  sp.set_box(0, 0, 28, 28);
  auto d = gcfmm_test::deposition(300, 204);
  d.x[9] = 1e-13;
  d.x[5] = 28.0 - 1e-13;
  d.y[5] = d.y[9];
  d.z[5] = d.z[9];
  sp.build(d.size(), d.x.data(), d.y.data(), d.z.data());
  Field g(d.size());
  try {
    sp.evaluate(d.q.data(), g.pot.data(), g.ex.data(), g.ey.data(), g.ez.data());
    ADD_FAILURE() << "no exception across the periodic boundary";
  } catch (const CoincidentParticles &e) {
    EXPECT_EQ(std::min(e.first(), e.second()), 5u);
    EXPECT_EQ(std::max(e.first(), e.second()), 9u);
  }
}

// A pair just outside the coincidence radius is an ordinary pair: finite and exact to the P2P's
// own precision at this accuracy (its term is nearly all of this target's field).
TEST(Robustness, CloseButDistinctPairIsExact) {
  auto p = gcfmm_test::random_cube(300, 205);
  p.x[3] = p.x[200] + 1e-6;
  p.y[3] = p.y[200];
  p.z[3] = p.z[200];
  Field f = solve(p, Options{});
  Field ref(p.size());
  direct_free(p.size(), p.x.data(), p.y.data(), p.z.data(), p.q.data(), ref.pot.data(), ref.ex.data(),
              ref.ey.data(), ref.ez.data());
  const double term = p2p_kernel_within(p2p_term_tolerance(Options{})).term_error;
  EXPECT_LT(std::abs(f.ex[3] - ref.ex[3]), (1e-9 + term) * std::abs(ref.ex[3]));
}

// A nearly coincident pair split by the root's octant plane (different leaves), among
// particles on a lattice whose planes hold many particles exactly on cube faces.
TEST(Robustness, NearlyCoincidentAcrossLeavesOnALattice) {
  gcfmm_test::Particles p;
  for (int i = 0; i < 12; ++i)
    for (int j = 0; j < 12; ++j)
      for (int k = 0; k < 12; ++k) {
        p.x.push_back(0.125 * i);
        p.y.push_back(0.125 * j);
        p.z.push_back(0.125 * k);
        p.q.push_back((i + j + k) % 2 ? 1.0 : -1.0);
      }
  // the root cube is centred at 0.6875 (the lattice's bounding box): a pair across x = 0.6875
  const std::size_t a = p.size(), b = a + 1;
  for (double x : {0.6875 - 1e-13, 0.6875 + 1e-13}) {
    p.x.push_back(x);
    p.y.push_back(0.3);
    p.z.push_back(0.7);
    p.q.push_back(1.0);
  }
  Options o;
  o.leaf = 8;
  Solver s(o);
  s.build(p.size(), p.x.data(), p.y.data(), p.z.data());
  Field f(p.size());
  try {
    s.evaluate(p.q.data(), f.pot.data(), f.ex.data(), f.ey.data(), f.ez.data());
    ADD_FAILURE() << "no exception";
  } catch (const CoincidentParticles &e) {
    EXPECT_EQ(e.first(), a);
    EXPECT_EQ(e.second(), b);
  }
  // without the pair the lattice (many particles on cube faces, none coincident) is accepted
  p.q[a] = p.q[b] = 0.0;
  EXPECT_NO_THROW(s.evaluate(p.q.data(), f.pot.data(), f.ex.data(), f.ey.data(), f.ez.data()));
}
