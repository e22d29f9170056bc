// gcfmm::charge_pair_change (the near refresh's pair kernel) on every instruction-set path:
// bit for bit the scalar formula fix coul/fmm used pair by pair before (its runs must not move),
// and within round-off of the closed form in long double.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "gcfmm/charge_pair_change.hpp"
#include "gcsimd/simd.hpp"

using namespace gcfmm;

namespace {

struct Pairs {
  std::vector<double> nx, ny, nz, tx, ty, tz;
};

// separations of 0.5-3 (the near cutoff's range in units of r_p), the evaluation's displaced by
// up to 0.01, with a zero separation now (index 3) and then (index 5) where n allows
Pairs random_pairs(std::size_t n, unsigned seed) {
  std::mt19937_64 gen(seed);
  std::uniform_real_distribution<double> u(-3.0, 3.0), d(-0.01, 0.01);
  Pairs p;
  for (std::size_t k = 0; k < n; ++k) {
    double now[3];
    do {
      for (double &c : now) c = u(gen);
    } while (now[0] * now[0] + now[1] * now[1] + now[2] * now[2] < 0.25);
    p.nx.push_back(now[0]);
    p.ny.push_back(now[1]);
    p.nz.push_back(now[2]);
    p.tx.push_back(now[0] - d(gen));
    p.ty.push_back(now[1] - d(gen));
    p.tz.push_back(now[2] - d(gen));
  }
  if (n > 3) p.nx[3] = p.ny[3] = p.nz[3] = 0.0;
  if (n > 5) p.tx[5] = p.ty[5] = p.tz[5] = 0.0;
  return p;
}

struct Out {
  std::vector<double> ex, ey, ez, pot, r2n, r2t;
  explicit Out(std::size_t n) : ex(n), ey(n), ez(n), pot(n), r2n(n), r2t(n) {}
  ChargePairChange view() { return {ex.data(), ey.data(), ez.data(), pot.data(), r2n.data(), r2t.data()}; }
};

// the scalar formula as fix coul/fmm evaluated it pair by pair (this test is compiled without
// fused multiply-adds: unittest/fmm/CMakeLists.txt)
void scalar(const double now[3], const double then[3], double dg[4]) {
  auto terms = [](const double *r, double t[4]) {
    const double r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
    const double in = r2 > 0.0 ? 1.0 / std::sqrt(r2) : 0.0, s = in * in * in;
    for (int k = 0; k < 3; k++) t[k] = s * r[k];
    t[3] = in;
  };
  double a[4], b[4];
  terms(now, a);
  terms(then, b);
  for (int k = 0; k < 4; k++) dg[k] = a[k] - b[k];
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0 || (a == 0.0 && b == 0.0); }

std::vector<gcsimd::SimdPath> available_paths() {
  std::vector<gcsimd::SimdPath> paths;
  for (gcsimd::SimdPath p : {gcsimd::SimdPath::Generic, gcsimd::SimdPath::AVX2, gcsimd::SimdPath::AVX512})
    if (gcsimd::simd_path_available(p)) paths.push_back(p);
  return paths;
}

}  // namespace

// Every count from 0 to 19 (the 2-, 4- and 8-wide tails) and a long batch, on every path the CPU
// has: the same bits as the scalar formula (a signed zero aside), r2 exact.
TEST(ChargePairChange, EveryPathGivesTheScalarBits) {
  std::vector<std::size_t> counts;
  for (std::size_t n = 0; n < 20; ++n) counts.push_back(n);
  counts.push_back(1037);
  for (gcsimd::SimdPath path : available_paths()) {
    for (std::size_t n : counts) {
      const Pairs p = random_pairs(n, 7 + n);
      Out out(n);
      charge_pair_change(n, {p.nx.data(), p.ny.data(), p.nz.data()}, {p.tx.data(), p.ty.data(), p.tz.data()},
                         out.view(), path);
      for (std::size_t k = 0; k < n; ++k) {
        const double now[3] = {p.nx[k], p.ny[k], p.nz[k]}, then[3] = {p.tx[k], p.ty[k], p.tz[k]};
        double dg[4];
        scalar(now, then, dg);
        const double got[4] = {out.ex[k], out.ey[k], out.ez[k], out.pot[k]};
        for (int c = 0; c < 4; ++c)
          ASSERT_TRUE(same_bits(got[c], dg[c]))
              << gcsimd::simd_path_name(path) << " n " << n << " pair " << k << " component " << c << ": " << got[c]
              << " != " << dg[c];
        EXPECT_EQ(out.r2n[k], now[0] * now[0] + now[1] * now[1] + now[2] * now[2]);
        EXPECT_EQ(out.r2t[k], then[0] * then[0] + then[1] * then[1] + then[2] * then[2]);
      }
    }
  }
}

// The physics: (K(now) - K(then), 1/|now| - 1/|then|), K(d) = d / |d|^3, a zero separation
// contributing nothing, against long double. Tolerance: each term is a few roundings of a value
// of size |K| <= 1/r^2 <= 4 (r >= 0.5), so the difference carries an absolute error of a few
// eps |K|: 1e-14 (~45 eps) is loose enough for every path and 1e4 times below the changes
// themselves (~1e-3 |K| for displacements of 0.01).
TEST(ChargePairChange, IsTheKernelDifference) {
  const std::size_t n = 64;
  const Pairs p = random_pairs(n, 3);
  for (gcsimd::SimdPath path : available_paths()) {
    Out out(n);
    charge_pair_change(n, {p.nx.data(), p.ny.data(), p.nz.data()}, {p.tx.data(), p.ty.data(), p.tz.data()},
                       out.view(), path);
    for (std::size_t k = 0; k < n; ++k) {
      auto kernel = [](long double x, long double y, long double z, long double t[4]) {
        const long double r2 = x * x + y * y + z * z;
        const long double in = r2 > 0 ? 1.0L / std::sqrt(r2) : 0.0L;
        t[0] = x * in * in * in;
        t[1] = y * in * in * in;
        t[2] = z * in * in * in;
        t[3] = in;
      };
      long double a[4], b[4];
      kernel(p.nx[k], p.ny[k], p.nz[k], a);
      kernel(p.tx[k], p.ty[k], p.tz[k], b);
      const double got[4] = {out.ex[k], out.ey[k], out.ez[k], out.pot[k]};
      for (int c = 0; c < 4; ++c) EXPECT_NEAR(got[c], (double) (a[c] - b[c]), 1e-14) << "pair " << k;
    }
    EXPECT_EQ(out.pot[3], -1.0 / std::sqrt(out.r2t[3]));    // zero now: only then's term
    EXPECT_EQ(out.pot[5], 1.0 / std::sqrt(out.r2n[5]));     // zero then: only now's term
  }
}

// charge_terms_at, the `now` half alone (the near refresh holds the evaluation's half): on every
// path the same bits as the scalar terms, for every tail length; a zero separation has no terms.
TEST(ChargePairChange, TermsAtEveryPathGiveTheScalarBits) {
  std::vector<std::size_t> counts;
  for (std::size_t n = 0; n < 20; ++n) counts.push_back(n);
  counts.push_back(1037);
  const double zero[3] = {0.0, 0.0, 0.0};
  for (gcsimd::SimdPath path : available_paths()) {
    for (std::size_t n : counts) {
      const Pairs p = random_pairs(n, 11 + n);
      Out out(n);
      charge_terms_at(n, {p.nx.data(), p.ny.data(), p.nz.data()},
                      {out.ex.data(), out.ey.data(), out.ez.data(), out.pot.data(), out.r2n.data()}, path);
      for (std::size_t k = 0; k < n; ++k) {
        const double now[3] = {p.nx[k], p.ny[k], p.nz[k]};
        double t[4];
        scalar(now, zero, t);
        const double got[4] = {out.ex[k], out.ey[k], out.ez[k], out.pot[k]};
        for (int c = 0; c < 4; ++c)
          ASSERT_TRUE(same_bits(got[c], t[c]))
              << gcsimd::simd_path_name(path) << " n " << n << " pair " << k << " component " << c << ": " << got[c]
              << " != " << t[c];
        EXPECT_EQ(out.r2n[k], now[0] * now[0] + now[1] * now[1] + now[2] * now[2]);
      }
      if (n > 3) EXPECT_EQ(out.pot[3], 0.0);
    }
  }
}
