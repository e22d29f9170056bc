// The gcfmm Solver end to end: accuracy against the O(N^2) references, invariances,
// conservation, error handling and bit-identical work partitions.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <numeric>
#include <random>
#include <stdexcept>
#include <thread>
#include <vector>

#include "gcfmm/kernels.hpp"
#include "gcfmm/solver.hpp"
#include "fmm_test_util.hpp"

using namespace gcfmm;
using gcfmm_test::Field;
using gcfmm_test::Particles;

namespace {

Field run(Solver &s, const Particles &p, int part = 0, int nparts = 1) {
  Field f(p.size());
  s.evaluate(p.q.data(), f.pot.data(), f.ex.data(), f.ey.data(), f.ez.data(), part, nparts);
  return f;
}

Field free_fmm(const Particles &p, const Options &o, Stats *st = nullptr) {
  Solver s(o);
  s.build(p.size(), p.x.data(), p.y.data(), p.z.data());
  Field f = run(s, p);
  if (st) *st = s.stats();
  return f;
}

Options periodic_opts(double acc, int images) {
  Options o;
  o.accuracy = acc;
  o.boundary = Boundary::Periodic2D;
  o.farfield = FarField::None;
  o.images = images;
  return o;
}

Field periodic_fmm(const Particles &p, const Options &o, double lx, Stats *st = nullptr) {
  Solver s(o);
  s.set_box(0.0, 0.0, lx, lx);
  s.build(p.size(), p.x.data(), p.y.data(), p.z.data());
  Field f = run(s, p);
  if (st) *st = s.stats();
  return f;
}

Field direct(const Particles &p) {
  Field f(p.size());
  direct_free(p.size(), p.x.data(), p.y.data(), p.z.data(), p.q.data(), f.pot.data(), f.ex.data(), f.ey.data(),
              f.ez.data());
  return f;
}

Field direct_img(const Particles &p, double lx, int images) {
  Field f(p.size());
  direct_images(p.size(), p.x.data(), p.y.data(), p.z.data(), p.q.data(), lx, lx, images, f.pot.data(), f.ex.data(),
                f.ey.data(), f.ez.data());
  return f;
}

double max_rel_diff(const Field &a, const Field &b) {
  double num = 0, den = 0;
  for (std::size_t i = 0; i < a.pot.size(); ++i) {
    num = std::max({num, std::abs(a.ex[i] - b.ex[i]), std::abs(a.ey[i] - b.ey[i]), std::abs(a.ez[i] - b.ez[i]),
                    std::abs(a.pot[i] - b.pot[i])});
    den = std::max({den, std::abs(b.ex[i]), std::abs(b.ey[i]), std::abs(b.ez[i]), std::abs(b.pot[i])});
  }
  return num / den;
}

}  // namespace

// The headline requirement: measured relative RMS force error below the requested accuracy.
// No slack is given: the rule (src/options.cpp) is calibrated to stay 1.2-4x below.
TEST(Solver, FreeSpaceRandomChargesMeetAccuracy) {
  auto p = gcfmm_test::random_cube(1000, 101);
  Field ref = direct(p);
  for (double acc : {1e-3, 1e-4, 1e-6}) {
    Options o;
    o.accuracy = acc;
    Stats st;
    Field f = free_fmm(p, o, &st);
    const double err = gcfmm_test::force_error(p.q, f, ref);
    EXPECT_LT(err, acc) << "order " << st.order << " theta " << st.theta;
    EXPECT_LT(st.estimated_error, acc);
    // the far field really went through expansions (at 1e-6 on 1000 particles the cost rule
    // legitimately prefers P2P for every accepted pair)
    if (acc >= 1e-4) {
      EXPECT_GT(st.m2l_count, 0u);
    }
    // the potential is at least as accurate as the force
    EXPECT_LT(gcfmm_test::potential_error(f, ref), acc);
  }
}

TEST(Solver, FreeSpaceLargerSetMeetsAccuracy) {
  auto p = gcfmm_test::random_cube(6000, 102);
  Field ref = direct(p);
  for (double acc : {1e-3, 1e-5}) {
    Options o;
    o.accuracy = acc;
    Field f = free_fmm(p, o);
    EXPECT_LT(gcfmm_test::force_error(p.q, f, ref), acc);
  }
}

// Deposition geometry (lx = ly = 28, bed + sparse particles up to z = 160), equal charges,
// periodic near field (FarField::None) against direct_images with the same shells.
TEST(Solver, DepositionPeriodicNearFieldMeetsAccuracy) {
  auto p = gcfmm_test::deposition(2000, 103);
  const double lx = 28.0;
  Field ref1 = direct_img(p, lx, 1);
  for (double acc : {1e-3, 1e-4, 1e-6}) {
    Stats st;
    Field f = periodic_fmm(p, periodic_opts(acc, 1), lx, &st);
    EXPECT_LT(gcfmm_test::force_error(p.q, f, ref1), acc) << "order " << st.order;
    EXPECT_LT(st.p2p_pairs, 9u * 2000u * 2000u / 2u);  // not a brute-force sum over copies
  }
  Field ref2 = direct_img(p, lx, 2);
  for (double acc : {1e-4}) {
    Field f = periodic_fmm(p, periodic_opts(acc, 2), lx);
    EXPECT_LT(gcfmm_test::force_error(p.q, f, ref2), acc);
  }
  // images 0: just the primary cell (free-space sum of the wrapped particles)
  Field ref0 = direct(p);
  Field f0 = periodic_fmm(p, periodic_opts(1e-4, 0), lx);
  EXPECT_LT(gcfmm_test::force_error(p.q, f0, ref0), 1e-4);
}

// A request is delivered, not overshot: from 1e-2 to 1e-3 (orders 4 to 7 at theta 0.7) the
// measured error lies within [0.1, 1] x accuracy in free space and in the deposition geometry
// at N = 2000, so a loose request costs a low order (before, the automatic order started at 5:
// 1e-2 gave 3e-4). Measured ratios 0.22-0.39 at N = 2000 (doc/fmm-accuracy.md, "Opening angle
// by accuracy"; N = 20,000 in the deposition geometry gives 0.08-0.12); the bounds are the target.
TEST(Solver, LooseRequestsAreDeliveredNotOvershot) {
  auto cube = gcfmm_test::random_cube(2000, 105);
  Field ref_cube = direct(cube);
  auto dep = gcfmm_test::deposition(2000, 106);
  const double lx = 28.0;
  Field ref_dep = direct_img(dep, lx, 1);
  for (double acc : {1e-2, 3e-3, 1e-3}) {
    Options o;
    o.accuracy = acc;
    Stats st;
    const double e_cube = gcfmm_test::force_error(cube.q, free_fmm(cube, o, &st), ref_cube);
    EXPECT_LT(e_cube, acc) << "free space, order " << st.order;
    EXPECT_GT(e_cube, 0.1 * acc) << "free space, order " << st.order;
    const double e_dep = gcfmm_test::force_error(dep.q, periodic_fmm(dep, periodic_opts(acc, 1), lx, &st), ref_dep);
    EXPECT_LT(e_dep, acc) << "deposition, order " << st.order;
    EXPECT_GT(e_dep, 0.1 * acc) << "deposition, order " << st.order;
  }
}

// Explicit order/theta/leaf are honoured and the error falls with the order.
TEST(Solver, ExplicitOrderConverges) {
  auto p = gcfmm_test::random_cube(2000, 104);
  Field ref = direct(p);
  double prev = 1.0;
  for (int order : {2, 4, 6, 8, 10}) {
    Options o;
    o.order = order;
    o.theta = 0.6;
    o.leaf = 16;
    Stats st;
    Field f = free_fmm(p, o, &st);
    EXPECT_EQ(st.order, order);
    EXPECT_EQ(st.leaf, 16);
    EXPECT_DOUBLE_EQ(st.theta, 0.6);
    const double err = gcfmm_test::force_error(p.q, f, ref);
    EXPECT_LT(err, 0.7 * prev) << "order " << order;
    EXPECT_LT(err, 3.0 * predicted_error(order, 0.6));
    prev = err;
  }
}

// Periodic: positions outside the primary cell are wrapped; translating every particle by a
// lattice vector changes nothing. Coordinates are multiples of 2^-20, so x + n lx and the
// wrap back are exact and the result must be bit-identical.
TEST(Solver, LatticeTranslationInvariance) {
  auto p = gcfmm_test::deposition(1500, 105);
  for (std::size_t i = 0; i < p.size(); ++i) {
    p.x[i] = std::ldexp(std::round(std::ldexp(p.x[i], 20)), -20);
    p.y[i] = std::ldexp(std::round(std::ldexp(p.y[i], 20)), -20);
  }
  Field a = periodic_fmm(p, periodic_opts(1e-4, 1), 28.0);
  Particles t = p;
  for (std::size_t i = 0; i < t.size(); ++i) {
    t.x[i] += 28.0 * ((i % 3) - 1.0) + 56.0;
    t.y[i] -= 28.0 * (i % 4);
  }
  Field b = periodic_fmm(t, periodic_opts(1e-4, 1), 28.0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    EXPECT_EQ(a.ex[i], b.ex[i]);
    EXPECT_EQ(a.ez[i], b.ez[i]);
    EXPECT_EQ(a.pot[i], b.pot[i]);
  }
  // a box not at the origin: shift box and particles together
  Options o = periodic_opts(1e-4, 1);
  Solver s(o);
  s.set_box(-14.0, 3.5, 28.0, 28.0);
  Particles u = p;
  for (std::size_t i = 0; i < u.size(); ++i) {
    u.x[i] -= 14.0;
    u.y[i] += 3.5;
  }
  s.build(u.size(), u.x.data(), u.y.data(), u.z.data());
  Field c = run(s, u);
  // round-off only (coordinates are no longer in the same binade): 1e-10 relative
  EXPECT_LT(max_rel_diff(c, a), 1e-10);
}

// Free space: an arbitrary translation and a permutation of the particles change the result
// only at round-off (the tree is built relative to the bounding box and particle order only
// changes the summation order). 1e-10 relative to the largest value.
TEST(Solver, TranslationAndPermutationInvariance) {
  auto p = gcfmm_test::random_cube(3000, 106);
  Options o;
  o.accuracy = 1e-5;
  Field a = free_fmm(p, o);
  Particles t = p;
  for (std::size_t i = 0; i < t.size(); ++i) {
    t.x[i] += 0.3125;
    t.y[i] -= 0.5;
    t.z[i] += 0.25;
  }
  EXPECT_LT(max_rel_diff(free_fmm(t, o), a), 1e-10);
  std::vector<std::size_t> perm(p.size());
  std::iota(perm.begin(), perm.end(), 0);
  std::mt19937_64 g(3);
  std::shuffle(perm.begin(), perm.end(), g);
  Particles s;
  s.resize(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    s.x[i] = p.x[perm[i]];
    s.y[i] = p.y[perm[i]];
    s.z[i] = p.z[perm[i]];
    s.q[i] = p.q[perm[i]];
  }
  Field b = free_fmm(s, o);
  Field bb(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    bb.pot[perm[i]] = b.pot[i];
    bb.ex[perm[i]] = b.ex[i];
    bb.ey[perm[i]] = b.ey[i];
    bb.ez[perm[i]] = b.ez[i];
  }
  EXPECT_LT(max_rel_diff(bb, a), 1e-10);
}

// Newton's third law: the total force vanishes for the exact sum (free space, and for the
// symmetric image block). FMM errors do not cancel exactly; each force carries a relative
// error ~ accuracy, so |sum F| must stay below accuracy * sum |F| (a bound that holds even if
// every error had the same sign) and in practice is far smaller.
TEST(Solver, NewtonThirdLaw) {
  for (int periodic = 0; periodic < 2; ++periodic) {
    auto p = periodic ? gcfmm_test::deposition(2000, 107) : gcfmm_test::random_cube(2000, 107);
    const double acc = 1e-4;
    Options o = periodic ? periodic_opts(acc, 1) : Options{};
    o.accuracy = acc;
    Field f = periodic ? periodic_fmm(p, o, 28.0) : free_fmm(p, o);
    double sx = 0, sy = 0, sz = 0, sabs = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      sx += p.q[i] * f.ex[i];
      sy += p.q[i] * f.ey[i];
      sz += p.q[i] * f.ez[i];
      sabs += std::abs(p.q[i]) * std::sqrt(f.ex[i] * f.ex[i] + f.ey[i] * f.ey[i] + f.ez[i] * f.ez[i]);
    }
    EXPECT_LT(std::sqrt(sx * sx + sy * sy + sz * sz), acc * sabs) << "periodic " << periodic;
  }
}

TEST(Solver, CoincidentChargedParticlesThrow) {
  auto p = gcfmm_test::random_cube(500, 108);
  p.x[7] = p.x[300];
  p.y[7] = p.y[300];
  p.z[7] = p.z[300];
  Solver s(Options{});
  s.build(p.size(), p.x.data(), p.y.data(), p.z.data());  // build does not need charges
  Field f(p.size());
  EXPECT_THROW(s.evaluate(p.q.data(), f.pot.data(), f.ex.data(), f.ey.data(), f.ez.data()), std::runtime_error);
  // both uncharged: allowed (they are sources of nothing); the others are finite
  p.q[7] = p.q[300] = 0.0;
  EXPECT_NO_THROW(s.evaluate(p.q.data(), f.pot.data(), f.ex.data(), f.ey.data(), f.ez.data()));
  for (std::size_t i = 0; i < p.size(); ++i) EXPECT_TRUE(std::isfinite(f.ex[i]) && std::isfinite(f.pot[i]));
  // periodic: coincident after wrapping (x and x + lx)
  Options o = periodic_opts(1e-4, 1);
  Solver sp(o);
  sp.set_box(0, 0, 28, 28);
  auto d = gcfmm_test::deposition(300, 109);
  d.x[9] = 13.5;  // exactly representable, so 41.5 wraps exactly onto 13.5
  d.x[5] = 41.5;
  d.y[5] = d.y[9];
  d.z[5] = d.z[9];
  sp.build(d.size(), d.x.data(), d.y.data(), d.z.data());
  Field g(d.size());
  EXPECT_THROW(sp.evaluate(d.q.data(), g.pot.data(), g.ex.data(), g.ey.data(), g.ez.data()), std::runtime_error);
}

TEST(Solver, NoChargesGiveZerosAndZeroChargeTargetsGetTheirField) {
  auto p = gcfmm_test::random_cube(800, 110);
  std::vector<double> q0(p.size(), 0.0);
  Solver s(Options{});
  s.build(p.size(), p.x.data(), p.y.data(), p.z.data());
  Field f(p.size());
  std::fill(f.ex.begin(), f.ex.end(), 7.0);  // outputs are overwritten, not accumulated
  s.evaluate(q0.data(), f.pot.data(), f.ex.data(), f.ey.data(), f.ez.data());
  for (std::size_t i = 0; i < p.size(); ++i) {
    EXPECT_EQ(f.pot[i], 0.0);
    EXPECT_EQ(f.ex[i], 0.0);
    EXPECT_EQ(f.ez[i], 0.0);
  }
  // half the particles uncharged: they still get the field of the others (force error with
  // unit test charges on every particle)
  Particles h = p;
  for (std::size_t i = 0; i < h.size(); i += 2) h.q[i] = 0.0;
  Field ref = direct(h);
  Options o;
  o.accuracy = 1e-5;
  Field fh = free_fmm(h, o);
  std::vector<double> unit(h.size(), 1.0);
  EXPECT_LT(gcfmm_test::force_error(unit, fh, ref), 1e-5);
  EXPECT_NE(fh.ex[0], 0.0);
  // empty and single-particle systems
  Solver e(Options{});
  e.build(0, nullptr, nullptr, nullptr);
  EXPECT_NO_THROW(e.evaluate(nullptr, nullptr, nullptr, nullptr, nullptr));
  double x = 1, y = 2, z = 3, q = 4, pot = 9, ex = 9, ey = 9, ez = 9;
  e.build(1, &x, &y, &z);
  e.evaluate(&q, &pot, &ex, &ey, &ez);
  EXPECT_EQ(pot, 0.0);
  EXPECT_EQ(ex, 0.0);
}

// Build once, evaluate many: new charges on the same tree give the right answer.
TEST(Solver, BuildOnceEvaluateMany) {
  auto p = gcfmm_test::random_cube(1500, 111);
  Options o;
  o.accuracy = 1e-4;
  Solver s(o);
  s.build(p.size(), p.x.data(), p.y.data(), p.z.data());
  for (int r = 0; r < 3; ++r) {
    std::mt19937_64 g(r);
    std::uniform_real_distribution<double> u(-1, 1);
    for (auto &q : p.q) q = u(g);
    Field f = run(s, p);
    EXPECT_LT(gcfmm_test::force_error(p.q, f, direct(p)), 1e-4);
  }
}

// Work partitions: the sum over parts is bit-identical to one part, part by part exactly one
// owner per particle, and the parts are balanced.
TEST(Solver, PartitionsSumBitIdentically) {
  for (int periodic = 0; periodic < 2; ++periodic) {
    auto p = periodic ? gcfmm_test::deposition(3000, 112) : gcfmm_test::random_cube(3000, 112);
    Options o = periodic ? periodic_opts(1e-4, 1) : Options{};
    Solver s(o);
    if (periodic) s.set_box(0, 0, 28, 28);
    s.build(p.size(), p.x.data(), p.y.data(), p.z.data());
    Field all = run(s, p);
    for (int nparts : {2, 3, 7}) {
      Field sum(p.size());
      std::vector<int> owners(p.size(), 0);
      for (int part = 0; part < nparts; ++part) {
        Field f = run(s, p, part, nparts);
        for (std::size_t i = 0; i < p.size(); ++i) {
          if (f.ex[i] != 0.0 || f.pot[i] != 0.0) ++owners[i];
          sum.pot[i] += f.pot[i];
          sum.ex[i] += f.ex[i];
          sum.ey[i] += f.ey[i];
          sum.ez[i] += f.ez[i];
        }
        std::size_t a, b;
        s.partition(part, nparts, a, b);
        EXPECT_LE(a, b);
      }
      std::size_t mismatches = 0;
      for (std::size_t i = 0; i < p.size(); ++i) {
        mismatches += (sum.pot[i] != all.pot[i]) + (sum.ex[i] != all.ex[i]) + (sum.ey[i] != all.ey[i]) +
                      (sum.ez[i] != all.ez[i]);
        EXPECT_EQ(owners[i], 1);
      }
      EXPECT_EQ(mismatches, 0u) << "nparts " << nparts << " periodic " << periodic;
    }
    // partition ranges tile [0, n)
    std::size_t prev = 0;
    for (int part = 0; part < 3; ++part) {
      std::size_t a, b;
      s.partition(part, 3, a, b);
      EXPECT_EQ(a, prev);
      prev = b;
    }
    EXPECT_EQ(prev, p.size());
  }
}

// A PartSum for parts running as threads (what MPI_Allreduce does for ranks): every part adds
// its array into a shared one, waits for all, and copies the total back.
class ThreadPartSum {
 public:
  explicit ThreadPartSum(int nparts) : nparts_(nparts) {}
  void operator()(double *data, std::size_t count) {
    std::unique_lock<std::mutex> lock(m_);
    ++calls_;
    if (arrived_ == 0) total_.assign(count, 0.0);
    for (std::size_t i = 0; i < count; ++i) total_[i] += data[i];
    wait_for_all(lock);
    std::copy(total_.begin(), total_.end(), data);
    wait_for_all(lock);  // nobody resets total_ before every part has copied it
  }
  int calls() const { return calls_; }  // over all parts

 private:
  void wait_for_all(std::unique_lock<std::mutex> &lock) {
    const long gen = generation_;
    if (++arrived_ == nparts_) {
      arrived_ = 0;
      ++generation_;
      cv_.notify_all();
    } else {
      cv_.wait(lock, [&] { return generation_ != gen; });
    }
  }
  int nparts_, arrived_ = 0, calls_ = 0;
  long generation_ = 0;
  std::mutex m_;
  std::condition_variable cv_;
  std::vector<double> total_;
};

// With a PartSum the parts split the far field's anterpolation; run at the same time, they
// still sum bit-identically to one part (every summed element comes from one part).
TEST(Solver, SplitWorkWithPartSumStaysBitIdentical) {
  for (int periodic = 0; periodic < 2; ++periodic) {
    auto p = periodic ? gcfmm_test::deposition(3000, 113) : gcfmm_test::random_cube(3000, 113);
    Options o = periodic ? periodic_opts(1e-4, 1) : Options{};
    if (periodic) o.farfield = FarField::Exact;  // the far field with its anterpolation
    auto make = [&] {
      auto s = std::make_unique<Solver>(o);
      if (periodic) s->set_box(0, 0, 28, 28);
      s->build(p.size(), p.x.data(), p.y.data(), p.z.data());
      return s;
    };
    auto one = make();
    const Field all = run(*one, p);
    for (int nparts : {2, 3}) {
      ThreadPartSum sum(nparts);
      const PartSum part_sum = [&](double *d, std::size_t c) { sum(d, c); };
      std::vector<std::unique_ptr<Solver>> solvers;
      std::vector<Field> fields;
      for (int k = 0; k < nparts; ++k) {
        solvers.push_back(make());
        fields.emplace_back(p.size());
      }
      std::vector<std::thread> threads;
      for (int k = 0; k < nparts; ++k)
        threads.emplace_back([&, k] {
          Field &f = fields[k];
          solvers[k]->evaluate(p.q.data(), f.pot.data(), f.ex.data(), f.ey.data(), f.ez.data(), k, nparts,
                               part_sum);
        });
      for (auto &t : threads) t.join();
      std::size_t mismatches = 0;
      for (std::size_t i = 0; i < p.size(); ++i) {
        double pot = 0, ex = 0, ey = 0, ez = 0;
        for (const Field &f : fields) {
          pot += f.pot[i];
          ex += f.ex[i];
          ey += f.ey[i];
          ez += f.ez[i];
        }
        mismatches += (pot != all.pot[i]) + (ex != all.ex[i]) + (ey != all.ey[i]) + (ez != all.ez[i]);
      }
      EXPECT_EQ(mismatches, 0u) << "nparts " << nparts << " periodic " << periodic;
      // the work was split: one sum of the far-field node charges (none in free space)
      EXPECT_EQ(sum.calls(), nparts * (periodic ? 1 : 0));
    }
  }
}

TEST(Solver, OptionsValidation) {
  auto bad = [](auto mutate) {
    Options o;
    mutate(o);
    EXPECT_THROW(o.validate(), std::invalid_argument);
    EXPECT_THROW(Solver s(o), std::invalid_argument);
  };
  bad([](Options &o) { o.accuracy = 0.0; });
  bad([](Options &o) { o.accuracy = 1.0; });
  bad([](Options &o) { o.accuracy = NAN; });
  bad([](Options &o) { o.order = -1; });
  bad([](Options &o) { o.order = kMaxOrder + 1; });
  bad([](Options &o) { o.theta = 1.0; });
  bad([](Options &o) { o.theta = -0.1; });
  bad([](Options &o) { o.leaf = -1; });
  bad([](Options &o) { o.images = -1; });
  bad([](Options &o) { o.bed_zlo = 1.0; });  // bed_zhi missing
  bad([](Options &o) {
    o.bed_zlo = 2.0;
    o.bed_zhi = 1.0;
  });
  Options ok;
  EXPECT_NO_THROW(ok.validate());
  try {
    Options o;
    o.accuracy = 2.0;
    o.validate();
  } catch (const std::invalid_argument &e) {
    EXPECT_NE(std::string(e.what()).find("accuracy"), std::string::npos);
  }
  // API misuse
  Solver f(Options{});
  EXPECT_THROW(f.set_box(0, 0, 1, 1), std::invalid_argument);  // free space has no box
  Field x(1);
  double q = 1;
  EXPECT_THROW(f.evaluate(&q, x.pot.data(), x.ex.data(), x.ey.data(), x.ez.data()), std::runtime_error);
  Solver per(periodic_opts(1e-4, 1));
  double a = 0;
  EXPECT_THROW(per.build(1, &a, &a, &a), std::runtime_error);  // no box
  EXPECT_THROW(per.set_box(0, 0, -1, 1), std::invalid_argument);
  per.set_box(0, 0, 1, 1);
  per.build(1, &a, &a, &a);
  EXPECT_THROW(per.evaluate(&q, x.pot.data(), x.ex.data(), x.ey.data(), x.ez.data(), 2, 2), std::invalid_argument);
}

// A rectangular cell (lx != ly) with images 1 and 2 against direct_images.
TEST(Solver, RectangularCell) {
  const double lx = 28.0, ly = 19.0;
  auto p = gcfmm_test::deposition(1500, 115, lx, ly);
  for (int images : {1, 2}) {
    Field ref(p.size());
    direct_images(p.size(), p.x.data(), p.y.data(), p.z.data(), p.q.data(), lx, ly, images, ref.pot.data(),
                  ref.ex.data(), ref.ey.data(), ref.ez.data());
    Solver s(periodic_opts(1e-4, images));
    s.set_box(0.0, 0.0, lx, ly);
    s.build(p.size(), p.x.data(), p.y.data(), p.z.data());
    Field f = run(s, p);
    EXPECT_LT(gcfmm_test::force_error(p.q, f, ref), 1e-4) << "images " << images;
  }
}

// Physical units (LAMMPS si: micron particles, femtocoulomb charges): scaling positions by
// 1e-6 and charges by 1e-15 scales E by 1e-15 / 1e-12 and leaves the relative error unchanged.
TEST(Solver, SmallLengthScales) {
  auto p = gcfmm_test::deposition(1200, 116);
  for (std::size_t i = 0; i < p.size(); ++i) {
    p.x[i] *= 1e-6;
    p.y[i] *= 1e-6;
    p.z[i] *= 1e-6;
    p.q[i] *= 1e-15;
  }
  Field ref(p.size());
  direct_images(p.size(), p.x.data(), p.y.data(), p.z.data(), p.q.data(), 28e-6, 28e-6, 1, ref.pot.data(),
                ref.ex.data(), ref.ey.data(), ref.ez.data());
  Solver s(periodic_opts(1e-4, 1));
  s.set_box(0.0, 0.0, 28e-6, 28e-6);
  s.build(p.size(), p.x.data(), p.y.data(), p.z.data());
  Field f = run(s, p);
  EXPECT_LT(gcfmm_test::force_error(p.q, f, ref), 1e-4);
}

// More parts than leaves: empty parts are legal and give zeros; the sum is still exact.
TEST(Solver, MorePartsThanLeaves) {
  auto p = gcfmm_test::random_cube(5, 117);
  Solver s(Options{});
  s.build(p.size(), p.x.data(), p.y.data(), p.z.data());
  Field all = run(s, p);
  Field sum(p.size());
  for (int part = 0; part < 4; ++part) {
    Field f = run(s, p, part, 4);
    for (std::size_t i = 0; i < p.size(); ++i) {
      sum.pot[i] += f.pot[i];
      sum.ex[i] += f.ex[i];
    }
  }
  for (std::size_t i = 0; i < p.size(); ++i) {
    EXPECT_EQ(sum.pot[i], all.pot[i]);
    EXPECT_EQ(sum.ex[i], all.ex[i]);
  }
}
