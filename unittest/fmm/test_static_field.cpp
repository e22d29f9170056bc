// StaticSourceField: the field of a fixed source set at other points (targets), against
// direct sums (free space, the image block, the 2D-periodic Green's function) and against
// Solver on the whole set (Solver(A) at A + StaticSourceField(S) at A = Solver(A u S) at A).
//
// Tolerances. The error model (doc/theory.md, eq. (3.15)) bounds the relative RMS force error
// of the near field for the resolved (p, theta); StaticSourceField uses the same resolve(), the
// same MAC and the same operators, and each target's field is an FMM sum over the same kind of
// interactions as in Solver, so the same bound is asked of it: error < accuracy, no slack, for
// the field against direct sums (relative RMS over the targets, normalised by the RMS of the
// reference field there). The model lies 1.2-4x above the calibration measurements, which is
// the margin. With FarField::Exact the far field adds its own error, kept 3x below the request by
// its parameter sets (doc/fmm-far-field.md), so the bound stays `accuracy`. The potential is
// held to the same bound relative to its RMS (it converges faster than the field: one power of
// distance more).
// A comparison of two FMM results (split against whole) has the errors of both sides; each is
// bounded by `accuracy` times the RMS field at the targets, so the difference by 2 x accuracy.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <vector>

#include "gcfmm/kernels.hpp"
#include "gcfmm/lattice_sum.hpp"
#include "gcfmm/solver.hpp"
#include "gcfmm/static_field.hpp"
#include "fmm_test_util.hpp"

using namespace gcfmm;
using gcfmm_test::Field;
using gcfmm_test::Particles;

namespace {

// relative RMS difference of the field (and of the potential), normalised by the reference's RMS
double field_error(const Field &a, const Field &ref) {
  double num = 0, den = 0;
  for (std::size_t i = 0; i < a.ex.size(); ++i) {
    const double dx = a.ex[i] - ref.ex[i], dy = a.ey[i] - ref.ey[i], dz = a.ez[i] - ref.ez[i];
    num += dx * dx + dy * dy + dz * dz;
    den += ref.ex[i] * ref.ex[i] + ref.ey[i] * ref.ey[i] + ref.ez[i] * ref.ez[i];
  }
  return std::sqrt(num / den);
}
double pot_error(const Field &a, const Field &ref) { return gcfmm_test::potential_error(a, ref); }

// Deposition geometry for the static field: ns sources in a dense bed (volume fraction 0.3,
// particle radius 1) over [0, l)^2 from z = 1, positive charges in [0.5, 1.5] (triboelectric
// charging of one material); nt targets, 80% in a thin layer [top - 2, top + 3] at the bed's
// top (overlapping it: the awake particles settling onto the bed), 20% high above, up to z = 160.
struct Scene {
  Particles src, tgt;
  double l = 28.0, top = 0.0;
};
Scene deposition_scene(std::size_t ns, std::size_t nt, unsigned seed, double l = 28.0, double zmax = 160.0) {
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Scene s;
  s.l = l;
  const double hbed = ns * (4.0 / 3.0 * M_PI) / (0.3 * l * l);
  s.top = 1.0 + hbed;
  s.src.resize(ns);
  for (std::size_t i = 0; i < ns; ++i) {
    s.src.x[i] = l * u(g);
    s.src.y[i] = l * u(g);
    s.src.z[i] = 1.0 + hbed * u(g);
    s.src.q[i] = 0.5 + u(g);
  }
  s.tgt.resize(nt);
  for (std::size_t i = 0; i < nt; ++i) {
    s.tgt.x[i] = l * u(g);
    s.tgt.y[i] = l * u(g);
    s.tgt.z[i] = i < nt * 4 / 5 ? s.top - 2.0 + 5.0 * u(g) : s.top + 3.0 + (zmax - s.top - 3.0) * u(g);
    s.tgt.q[i] = 0.5 + u(g);
  }
  return s;
}

Options opts_of(double acc, Boundary b, FarField ff = FarField::None, int images = 1) {
  Options o;
  o.accuracy = acc;
  o.boundary = b;
  o.farfield = ff;
  o.images = images;
  return o;
}

Field static_field(StaticSourceField &f, const Particles &t) {
  Field r(t.size());
  f.evaluate(t.size(), t.x.data(), t.y.data(), t.z.data(), r.pot.data(), r.ex.data(), r.ey.data(), r.ez.data());
  return r;
}

Field static_run(const Options &o, const Particles &s, const Particles &t, double l = 0.0, double zlo = NAN,
                 double zhi = NAN, StaticFieldStats *st = nullptr, double *energy = nullptr) {
  StaticSourceField f(o);
  if (o.boundary == Boundary::Periodic2D) {
    f.set_box(0.0, 0.0, l, l);
    if (!std::isnan(zlo)) f.set_z_range(zlo, zhi);
  }
  f.set_sources(s.size(), s.x.data(), s.y.data(), s.z.data(), s.q.data());
  Field r = static_field(f, t);
  if (st) *st = f.stats();
  if (energy) *energy = f.source_energy();
  return r;
}

// Solver over p; field at all of p, and its energy (1/2) sum q u
Field solver_run(const Options &o, const Particles &p, double l = 0.0, double zlo = NAN, double zhi = NAN,
                 double *energy = nullptr) {
  Solver s(o);
  if (o.boundary == Boundary::Periodic2D) {
    s.set_box(0.0, 0.0, l, l);
    if (!std::isnan(zlo)) s.set_z_range(zlo, zhi);
  }
  s.build(p.size(), p.x.data(), p.y.data(), p.z.data());
  Field r(p.size());
  s.evaluate(p.q.data(), r.pot.data(), r.ex.data(), r.ey.data(), r.ez.data());
  if (energy) {
    std::vector<double> u(p.size());
    s.energy_potential(u.data());
    double e = 0;
    for (std::size_t i = 0; i < p.size(); ++i) e += p.q[i] * u[i];
    *energy = 0.5 * e;
  }
  return r;
}

// direct sums at the targets: free space, the image block |nx|, |ny| <= images (no far field)
Field direct_targets(const Particles &s, const Particles &t, double l = 0.0, int images = 0) {
  Field r(t.size());
  for (std::size_t i = 0; i < t.size(); ++i) {
    double p = 0, ex = 0, ey = 0, ez = 0;
    for (int a = -images; a <= images; ++a)
      for (int b = -images; b <= images; ++b)
        for (std::size_t j = 0; j < s.size(); ++j) {
          const double dx = t.x[i] - s.x[j] - a * l, dy = t.y[i] - s.y[j] - b * l, dz = t.z[i] - s.z[j];
          const double r2 = dx * dx + dy * dy + dz * dz, ir = 1.0 / std::sqrt(r2), ir3 = ir * ir * ir;
          p += s.q[j] * ir;
          ex += s.q[j] * dx * ir3;
          ey += s.q[j] * dy * ir3;
          ez += s.q[j] * dz * ir3;
        }
    r.pot[i] = p;
    r.ex[i] = ex;
    r.ey[i] = ey;
    r.ez[i] = ez;
  }
  return r;
}

// the full 2D-periodic sum (2D Ewald, doc/theory.md, eqs. (4.2)-(4.4)): what the near block
// plus the exact far field approximate, in the same constant convention
Field green_targets(const Particles &s, const Particles &t, double l) {
  Field r(t.size());
  for (std::size_t i = 0; i < t.size(); ++i)
    for (std::size_t j = 0; j < s.size(); ++j) {
      double g, gx, gy, gz;
      periodic_green(t.x[i] - s.x[j], t.y[i] - s.y[j], t.z[i] - s.z[j], l, l, &g, &gx, &gy, &gz);
      r.pot[i] += s.q[j] * g;
      r.ex[i] -= s.q[j] * gx;
      r.ey[i] -= s.q[j] * gy;
      r.ez[i] -= s.q[j] * gz;
    }
  return r;
}

// Solver over the sources plus the targets as zero-charge particles, field at the targets: the
// existing solver's accuracy at exactly these targets (for populations the error model's RMS
// bound does not cover on its own, see PeriodicTargetsHighAbove)
Field solver_at_targets(const Options &o, const Particles &s, const Particles &t, double l = 0.0) {
  Particles all = s;
  for (std::size_t i = 0; i < t.size(); ++i) {
    all.x.push_back(t.x[i]);
    all.y.push_back(t.y[i]);
    all.z.push_back(t.z[i]);
    all.q.push_back(0.0);
  }
  Solver sv(o);
  if (o.boundary == Boundary::Periodic2D) sv.set_box(0.0, 0.0, l, l);
  sv.build(all.size(), all.x.data(), all.y.data(), all.z.data());
  Field r(all.size());
  sv.evaluate(all.q.data(), r.pot.data(), r.ex.data(), r.ey.data(), r.ez.data());
  Field out(t.size());
  for (std::size_t i = 0; i < t.size(); ++i) {
    out.pot[i] = r.pot[s.size() + i];
    out.ex[i] = r.ex[s.size() + i];
    out.ey[i] = r.ey[s.size() + i];
    out.ez[i] = r.ez[s.size() + i];
  }
  return out;
}

Particles subset(const Particles &p, const std::vector<std::size_t> &idx) {
  Particles r;
  for (std::size_t i : idx) {
    r.x.push_back(p.x[i]);
    r.y.push_back(p.y[i]);
    r.z.push_back(p.z[i]);
    r.q.push_back(p.q[i]);
  }
  return r;
}

Field restrict(const Field &f, const std::vector<std::size_t> &idx) {
  Field r;
  for (std::size_t i : idx) {
    r.pot.push_back(f.pot[i]);
    r.ex.push_back(f.ex[i]);
    r.ey.push_back(f.ey[i]);
    r.ez.push_back(f.ez[i]);
  }
  return r;
}

Field sum(const Field &a, const Field &b) {
  Field r = a;
  for (std::size_t i = 0; i < a.pot.size(); ++i) {
    r.pot[i] += b.pot[i];
    r.ex[i] += b.ex[i];
    r.ey[i] += b.ey[i];
    r.ez[i] += b.ez[i];
  }
  return r;
}

}  // namespace

// Free space: random charges of both signs in a unit cube as sources; targets inside the cube
// (between the sources) and far outside it (up to 1e4 cube sizes away: the target tree's cells
// have nothing to do with the source tree's).
TEST(StaticField, FreeSpaceMatchesDirectSum) {
  Particles s = gcfmm_test::random_cube(1500, 201);
  Particles t = gcfmm_test::random_cube(400, 202);
  std::mt19937_64 g(203);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (std::size_t i = 300; i < 400; ++i) {
    const double d = std::pow(10.0, 1.0 + 3.0 * (i - 300) / 100.0);  // 10 .. 1e4 away
    t.x[i] = 0.5 + d * u(g);
    t.y[i] = 0.5 + d * u(g);
    t.z[i] = 0.5 + d * (1.0 + 0.1 * u(g));
  }
  const Field ref = direct_targets(s, t);
  std::vector<std::size_t> far_idx;
  for (std::size_t i = 300; i < 400; ++i) far_idx.push_back(i);
  const Field ref_far = restrict(ref, far_idx);
  for (double acc : {1e-3, 1e-4, 1e-6}) {
    StaticFieldStats st;
    const Field f = static_run(opts_of(acc, Boundary::Free), s, t, 0.0, NAN, NAN, &st);
    // The far targets alone: there the field of the (nearly neutral) cube is the small remainder
    // of cancelling charges (net charge ~ sqrt(N) |q|), while an M2L truncation error scales with
    // sum |q|: a target node accepted near the MAC's limit has an error ~e(p, theta) relative to
    // the field the charges would make with one sign, sum_j |q_j| / |r_t - r_j|^2, and that is
    // the scale the far targets' error is normalised by here (relative to their own, cancelling
    // field it is up to ~sqrt(N) = 40 x larger: 7e-4 at 1e-4 measured with target leaves of 8).
    double num = 0, den = 0;
    for (std::size_t i : far_idx) {
      const double dx = f.ex[i] - ref.ex[i], dy = f.ey[i] - ref.ey[i], dz = f.ez[i] - ref.ez[i];
      num += dx * dx + dy * dy + dz * dz;
      double sc = 0;
      for (std::size_t j = 0; j < s.size(); ++j) {
        const double rx = t.x[i] - s.x[j], ry = t.y[i] - s.y[j], rz = t.z[i] - s.z[j];
        sc += std::abs(s.q[j]) / (rx * rx + ry * ry + rz * rz);
      }
      den += sc * sc;
    }
    const double e_far = std::sqrt(num / den), e_far_own = field_error(restrict(f, far_idx), ref_far);
    std::printf("  free, accuracy %.0e: field %.2e, potential %.2e, far targets %.2e (relative to their own field "
                "%.2e)\n", acc, field_error(f, ref), pot_error(f, ref), e_far, e_far_own);
    EXPECT_LT(e_far, acc) << "far targets, accuracy " << acc;
    EXPECT_LT(field_error(f, ref), acc) << "accuracy " << acc;
    EXPECT_LT(pot_error(f, ref), acc) << "accuracy " << acc;
    EXPECT_GT(st.m2l_count, 0u);
  }
}

// Periodic2D without far field: the image block |nx|, |ny| <= images, for images 1 and 2, in the
// deposition geometry (dense bed, targets on its top and high above).
TEST(StaticField, PeriodicImageBlockMatchesDirectSum) {
  const Scene sc = deposition_scene(2000, 300, 211);
  for (int images : {1, 2}) {
    const Field ref = direct_targets(sc.src, sc.tgt, sc.l, images);
    for (double acc : {1e-3, 1e-4, 1e-6}) {
      const Field f = static_run(opts_of(acc, Boundary::Periodic2D, FarField::None, images), sc.src, sc.tgt, sc.l);
      std::printf("  images %d, accuracy %.0e: field %.2e, potential %.2e\n", images, acc, field_error(f, ref),
                  pot_error(f, ref));
      EXPECT_LT(field_error(f, ref), acc) << "images " << images << ", accuracy " << acc;
      EXPECT_LT(pot_error(f, ref), acc) << "images " << images << ", accuracy " << acc;
    }
  }
}

// Periodic2D with the exact far field against the 2D-periodic Green's function (all images,
// eqs. (4.2)-(4.4)); targets wrapped from outside the cell; the column given by set_z_range.
TEST(StaticField, PeriodicExactMatchesGreensFunction) {
  Scene sc = deposition_scene(700, 60, 221);
  for (std::size_t i = 0; i < sc.tgt.size(); i += 3) sc.tgt.x[i] += (i % 2 ? 2.0 : -3.0) * sc.l;  // wrapped
  const Field ref = green_targets(sc.src, sc.tgt, sc.l);
  for (double acc : {1e-3, 1e-4, 1e-6}) {
    StaticFieldStats st;
    const Field f = static_run(opts_of(acc, Boundary::Periodic2D, FarField::Exact), sc.src, sc.tgt, sc.l, 0.0,
                               160.0, &st);
    std::printf("  exact, accuracy %.0e: field %.2e, potential %.2e\n", acc, field_error(f, ref), pot_error(f, ref));
    EXPECT_LT(field_error(f, ref), acc) << "accuracy " << acc;
    EXPECT_LT(pot_error(f, ref), acc) << "accuracy " << acc;
    EXPECT_EQ(st.far_setups, 1);
  }
}

// The headline property: for a split of P into awake A and sleeping S,
//   Solver(A) at A + StaticSourceField(S) at A = Solver(P) restricted to A,
// field and potential, and U_P = U_A + U_S + sum_a q_a pot^S_a. Splits: a random 10% of P, and
// the deposition split (A = the topmost 15%). Free space, Periodic2D with FarField::None,
// Exact, and Average with the bed given (then the average field is linear in the charge).
TEST(StaticField, SplitPlusStaticEqualsWholeSolver) {
  struct Case {
    Boundary b;
    FarField ff;
    const char *name;
  };
  const Case cases[] = {{Boundary::Free, FarField::None, "free"},
                        {Boundary::Periodic2D, FarField::None, "periodic none"},
                        {Boundary::Periodic2D, FarField::Exact, "periodic exact"},
                        {Boundary::Periodic2D, FarField::Average, "periodic average"}};
  const Particles P = gcfmm_test::deposition(3000, 231);
  const double l = gcfmm_test::deposition_width(3000);
  std::vector<std::size_t> order(P.size());
  for (std::size_t i = 0; i < P.size(); ++i) order[i] = i;
  std::vector<std::vector<std::size_t>> awake(2), sleeping(2);
  std::mt19937_64 g(232);
  std::shuffle(order.begin(), order.end(), g);
  for (std::size_t k = 0; k < P.size(); ++k) (k < P.size() / 10 ? awake[0] : sleeping[0]).push_back(order[k]);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return P.z[a] > P.z[b]; });
  for (std::size_t k = 0; k < P.size(); ++k) (k < P.size() * 15 / 100 ? awake[1] : sleeping[1]).push_back(order[k]);
  for (const Case &c : cases)
    for (double acc : {1e-3, 1e-4, 1e-6}) {
      Options o = opts_of(acc, c.b, c.ff);
      if (c.ff == FarField::Average) {
        o.bed_zlo = 0.0;
        o.bed_zhi = 40.0;
      }
      double eP;
      const Field whole = solver_run(o, P, l, 0.0, 160.0, &eP);
      for (int split = 0; split < 2; ++split) {
        const Particles A = subset(P, awake[split]), S = subset(P, sleeping[split]);
        double eA, eS;
        const Field fa = solver_run(o, A, l, 0.0, 160.0, &eA);
        const Field fs = static_run(o, S, A, l, 0.0, 160.0, nullptr, &eS);
        const Field combined = sum(fa, fs), ref = restrict(whole, awake[split]);
        double cross = 0;
        for (std::size_t k = 0; k < A.size(); ++k) cross += A.q[k] * fs.pot[k];
        std::printf("  %s, split %d, accuracy %.0e: field %.2e, potential %.2e, energy %.2e\n", c.name, split, acc,
                    field_error(combined, ref), pot_error(combined, ref), std::abs(eA + eS + cross - eP) / std::abs(eP));
        EXPECT_LT(field_error(combined, ref), 2 * acc) << c.name << ", split " << split << ", accuracy " << acc;
        EXPECT_LT(pot_error(combined, ref), 2 * acc) << c.name << ", split " << split << ", accuracy " << acc;
        if (c.ff == FarField::Average) continue;  // not a pair energy (static_field.hpp)
        // energies: each side's error is ~accuracy x the typical |q pot|, summed over particles
        // of one sign; relative to U_P it is bounded the same way (2 x accuracy: both sides)
        EXPECT_LT(std::abs(eA + eS + cross - eP), 2 * acc * std::abs(eP))
            << c.name << ", split " << split << ", accuracy " << acc;
      }
    }
}

// Targets far from the sources in the periodic column: high above the bed (z up to 10 cell
// sides), first with the column given, then without it (evaluate() extends the far-field column
// itself: one more set-up, same result).
TEST(StaticField, PeriodicTargetsHighAbove) {
  Scene sc = deposition_scene(600, 40, 241);
  for (std::size_t i = 0; i < sc.tgt.size(); ++i) sc.tgt.z[i] = 30.0 + 250.0 * i / sc.tgt.size();
  const Field ref = green_targets(sc.src, sc.tgt, sc.l);
  const double acc = 1e-4;
  StaticFieldStats st;
  const Field given = static_run(opts_of(acc, Boundary::Periodic2D, FarField::Exact), sc.src, sc.tgt, sc.l, 0.0,
                                 300.0, &st);
  EXPECT_EQ(st.far_setups, 1);
  EXPECT_LT(field_error(given, ref), acc);
  const Field grown = static_run(opts_of(acc, Boundary::Periodic2D, FarField::Exact), sc.src, sc.tgt, sc.l, NAN,
                                 NAN, &st);
  EXPECT_EQ(st.far_setups, 2);
  EXPECT_LT(field_error(grown, ref), acc);
  // near field only (the image block) far above. Only far targets: every one of them sees the bed
  // through a few large M2L near the MAC's limit, whose errors add coherently (all charges
  // positive), so the RMS bound of the error model, calibrated on populations that include the
  // near targets, does not hold for this population alone: the whole Solver at the same targets
  // measures 1.95e-4 at 1e-4. The static field is held to the Solver's own error here (x 1.2)
  // and to 3 x accuracy.
  const Field refn = direct_targets(sc.src, sc.tgt, sc.l, 1);
  const Options on = opts_of(acc, Boundary::Periodic2D);
  const double en = field_error(static_run(on, sc.src, sc.tgt, sc.l), refn);
  const double es = field_error(solver_at_targets(on, sc.src, sc.tgt, sc.l), refn);
  std::printf("  high above, none: static %.2e, whole solver at the same targets %.2e\n", en, es);
  EXPECT_LT(en, std::max(acc, 1.2 * es));
  EXPECT_LT(en, 3 * acc);
}

// No sources, no charged sources, no targets: zeros written (over garbage), energy 0.
TEST(StaticField, EmptySourceAndTargetSets) {
  const Scene sc = deposition_scene(300, 50, 251);
  for (auto ff : {FarField::None, FarField::Exact, FarField::Average}) {
    for (int zero_charges = 0; zero_charges < 2; ++zero_charges) {
      StaticSourceField f(opts_of(1e-4, Boundary::Periodic2D, ff));
      f.set_box(0, 0, sc.l, sc.l);
      Particles s = sc.src;
      for (auto &q : s.q) q = 0.0;
      f.set_sources(zero_charges ? s.size() : 0, s.x.data(), s.y.data(), s.z.data(), s.q.data());
      EXPECT_EQ(f.source_energy(), 0.0);
      Field r(sc.tgt.size());
      for (auto *v : {&r.pot, &r.ex, &r.ey, &r.ez}) std::fill(v->begin(), v->end(), 7.0);
      f.evaluate(sc.tgt.size(), sc.tgt.x.data(), sc.tgt.y.data(), sc.tgt.z.data(), r.pot.data(), r.ex.data(),
                 r.ey.data(), r.ez.data());
      for (std::size_t i = 0; i < sc.tgt.size(); ++i)
        EXPECT_TRUE(r.pot[i] == 0.0 && r.ex[i] == 0.0 && r.ey[i] == 0.0 && r.ez[i] == 0.0);
    }
    StaticSourceField f(opts_of(1e-4, Boundary::Periodic2D, ff));
    f.set_box(0, 0, sc.l, sc.l);
    f.set_sources(sc.src.size(), sc.src.x.data(), sc.src.y.data(), sc.src.z.data(), sc.src.q.data());
    f.evaluate(0, nullptr, nullptr, nullptr, nullptr, nullptr, nullptr, nullptr);  // no targets
    EXPECT_EQ(f.stats().targets, 0u);
  }
  StaticSourceField f(opts_of(1e-4, Boundary::Free));
  f.set_sources(0, nullptr, nullptr, nullptr, nullptr);
  Field r(3);
  const double x[3] = {0, 1, 2};
  f.evaluate(3, x, x, x, r.pot.data(), r.ex.data(), r.ey.data(), r.ez.data());
  for (int i = 0; i < 3; ++i) EXPECT_EQ(r.pot[i], 0.0);
}

// Zero-charge sources are sources of nothing: dropping them changes nothing (bit-identical).
TEST(StaticField, ZeroChargeSourcesAreIgnored) {
  const Scene sc = deposition_scene(800, 100, 261);
  Particles s = sc.src;
  for (std::size_t i = 0; i < s.size(); i += 4) s.q[i] = 0.0;
  std::vector<std::size_t> charged;
  for (std::size_t i = 0; i < s.size(); ++i)
    if (s.q[i] != 0.0) charged.push_back(i);
  const Options o = opts_of(1e-4, Boundary::Periodic2D, FarField::Exact);
  const Field a = static_run(o, s, sc.tgt, sc.l, 0, 160), b = static_run(o, subset(s, charged), sc.tgt, sc.l, 0, 160);
  EXPECT_EQ(a.ez, b.ez);
  EXPECT_EQ(a.pot, b.pot);
}

// A target on a source (closer than the coincidence radius, also across the periodic boundary)
// throws CoincidentParticles(target, source); on a zero-charge source it is fine. Two charged
// sources at one point throw from source_energy() with their indices.
TEST(StaticField, CoincidentTargetThrows) {
  Scene sc = deposition_scene(500, 50, 271);
  StaticSourceField f(opts_of(1e-4, Boundary::Periodic2D, FarField::Exact));
  f.set_box(0, 0, sc.l, sc.l);
  sc.src.x[123] = 1e-13;  // at the wall x = 0
  sc.src.q[77] = 0.0;
  f.set_sources(sc.src.size(), sc.src.x.data(), sc.src.y.data(), sc.src.z.data(), sc.src.q.data());
  Field r(sc.tgt.size());
  auto eval = [&] {
    f.evaluate(sc.tgt.size(), sc.tgt.x.data(), sc.tgt.y.data(), sc.tgt.z.data(), r.pot.data(), r.ex.data(),
               r.ey.data(), r.ez.data());
  };
  Particles t0 = sc.tgt;
  // on source 40, 1e-12 h away
  sc.tgt.x[17] = sc.src.x[40] + 1e-12;
  sc.tgt.y[17] = sc.src.y[40];
  sc.tgt.z[17] = sc.src.z[40];
  try {
    eval();
    ADD_FAILURE() << "no exception";
  } catch (const CoincidentParticles &c) {
    EXPECT_EQ(c.first(), 17u);
    EXPECT_EQ(c.second(), 40u);
  }
  // across the wall: target just below x = lx, source 123 just above x = 0
  sc.tgt = t0;
  sc.tgt.x[5] = sc.l - 1e-13;
  sc.tgt.y[5] = sc.src.y[123];
  sc.tgt.z[5] = sc.src.z[123];
  try {
    eval();
    ADD_FAILURE() << "no exception across the wall";
  } catch (const CoincidentParticles &c) {
    EXPECT_EQ(c.first(), 5u);
    EXPECT_EQ(c.second(), 123u);
  }
  // on the zero-charge source 77: no error, finite field
  sc.tgt = t0;
  sc.tgt.x[9] = sc.src.x[77];
  sc.tgt.y[9] = sc.src.y[77];
  sc.tgt.z[9] = sc.src.z[77];
  eval();
  for (std::size_t i = 0; i < sc.tgt.size(); ++i) EXPECT_TRUE(std::isfinite(r.ez[i]) && std::isfinite(r.pot[i]));
  // two charged sources at one point
  sc.src.x[300] = sc.src.x[200];
  sc.src.y[300] = sc.src.y[200];
  sc.src.z[300] = sc.src.z[200];
  try {
    f.set_sources(sc.src.size(), sc.src.x.data(), sc.src.y.data(), sc.src.z.data(), sc.src.q.data());
    f.source_energy();    // the sources' own Solver finds them
    ADD_FAILURE() << "no exception for coincident sources";
  } catch (const CoincidentParticles &c) {
    EXPECT_EQ(c.first(), 200u);
    EXPECT_EQ(c.second(), 300u);
  }
  // free space too
  StaticSourceField g(opts_of(1e-4, Boundary::Free));
  Particles s = gcfmm_test::random_cube(200, 272);
  g.set_sources(s.size(), s.x.data(), s.y.data(), s.z.data(), s.q.data());
  double x = s.x[11], y = s.y[11], z = s.z[11], p, ex, ey, ez;
  EXPECT_THROW(g.evaluate(1, &x, &y, &z, &p, &ex, &ey, &ez), CoincidentParticles);
}

// Evaluate many times with moving targets: each call is a fresh target tree (same result as a
// new instance, bit-identical), and the result does not depend on the targets' order.
TEST(StaticField, RepeatedEvaluationsAndPermutation) {
  const Scene sc = deposition_scene(1500, 200, 281);
  const Options o = opts_of(1e-4, Boundary::Periodic2D, FarField::Exact);
  StaticSourceField f(o);
  f.set_box(0, 0, sc.l, sc.l);
  f.set_z_range(0, 160);
  f.set_sources(sc.src.size(), sc.src.x.data(), sc.src.y.data(), sc.src.z.data(), sc.src.q.data());
  Particles t = sc.tgt;
  for (int step = 0; step < 3; ++step) {
    for (std::size_t i = 0; i < t.size(); ++i) t.z[i] += 0.3;  // the targets move
    const Field a = static_field(f, t);
    const Field b = static_run(o, sc.src, t, sc.l, 0, 160);
    EXPECT_EQ(a.ez, b.ez);
    EXPECT_EQ(a.pot, b.pot);
  }
  std::vector<std::size_t> perm(t.size());
  for (std::size_t i = 0; i < t.size(); ++i) perm[i] = t.size() - 1 - i;
  const Field a = static_field(f, t), b = static_field(f, subset(t, perm));
  std::size_t mism = 0;
  for (std::size_t k = 0; k < t.size(); ++k) mism += a.ex[perm[k]] != b.ex[k] || a.pot[perm[k]] != b.pot[k];
  EXPECT_EQ(mism, 0u);
}

// The cost of an evaluation does not grow with the number of sources: the same targets at the
// top of a bed 8 times deeper (same cell) need about the same direct pairs and M2L.
TEST(StaticField, EvaluationCostIndependentOfSources) {
  StaticFieldStats st[2];
  for (int k = 0; k < 2; ++k) {
    const std::size_t ns = k ? 16000 : 2000;
    const Scene sc = deposition_scene(ns, 300, 291, 28.0, 1.0 + ns * (4.0 / 3.0 * M_PI) / (0.3 * 28 * 28) + 130.0);
    static_run(opts_of(1e-4, Boundary::Periodic2D), sc.src, sc.tgt, sc.l, NAN, NAN, &st[k]);
    std::printf("  N_s = %zu: %zu M2L, %zu P2P pairs, %zu target nodes\n", ns, st[k].m2l_count, st[k].p2p_pairs,
                st[k].target_nodes);
  }
  EXPECT_LT(double(st[1].p2p_pairs), 1.5 * double(st[0].p2p_pairs));
  EXPECT_LT(double(st[1].m2l_count), 2.0 * double(st[0].m2l_count));
  EXPECT_GT(st[1].m2l_count, 0u);
}

TEST(StaticField, Misuse) {
  StaticSourceField f(opts_of(1e-4, Boundary::Periodic2D));
  double x = 1, p, e;
  EXPECT_THROW(f.set_sources(1, &x, &x, &x, &x), std::runtime_error);  // no box
  EXPECT_THROW(f.evaluate(1, &x, &x, &x, &p, &e, &e, &e), std::runtime_error);
  EXPECT_THROW(f.source_energy(), std::runtime_error);
  EXPECT_THROW(f.set_box(0, 0, -1, 1), std::invalid_argument);
  EXPECT_THROW(f.set_target_leaf(-1), std::invalid_argument);
  StaticSourceField g(opts_of(1e-4, Boundary::Free));
  EXPECT_THROW(g.set_box(0, 0, 1, 1), std::invalid_argument);
  EXPECT_THROW(g.set_z_range(0, 1), std::invalid_argument);
  Options bad;
  bad.accuracy = 2.0;
  EXPECT_THROW(StaticSourceField{bad}, std::invalid_argument);
  // set_box() forgets the sources
  f.set_box(0, 0, 10, 10);
  f.set_sources(1, &x, &x, &x, &x);
  f.set_box(0, 0, 10, 10);
  EXPECT_THROW(f.evaluate(1, &x, &x, &x, &p, &e, &e, &e), std::runtime_error);
}
