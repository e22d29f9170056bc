// The near refresh's pair kernel (gcfmm::charge_pair_change) on each instruction-set path, against
// the scalar formula called pair by pair (fix coul/fmm's loop before the kernel): ns per pair.
//   bench_charge_pair_change [pairs (default 14000: a paper-size bed, ~7 pairs per atom within
//   3 r_p)] [repetitions (default 2000)]
// Not a test (doc/benchmarks.md, "The near refresh").
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include "gcfmm/charge_pair_change.hpp"
#include "gcsimd/simd.hpp"

namespace {

// the scalar formula of the loop before: one pair per call (not inlined, as it was called from
// another translation unit)
__attribute__((noinline)) void scalar_pair(const double now[3], const double then[3], double dg[4]) {
  const double rn2 = now[0] * now[0] + now[1] * now[1] + now[2] * now[2];
  const double rt2 = then[0] * then[0] + then[1] * then[1] + then[2] * then[2];
  const double in = 1.0 / std::sqrt(rn2), it = 1.0 / std::sqrt(rt2);
  const double sn = in * in * in, st = it * it * it;
  for (int k = 0; k < 3; k++) dg[k] = sn * now[k] - st * then[k];
  dg[3] = in - it;
}

template <class F>
double best_ns_per_pair(std::size_t n, int reps, F &&f) {
  double best = 1e300;
  for (int trial = 0; trial < 3; ++trial) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int r = 0; r < reps; ++r) f();
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    best = std::min(best, 1e9 * s / (double(n) * reps));
  }
  return best;
}

}  // namespace

int main(int argc, char **argv) {
  const std::size_t n = argc > 1 ? std::strtoul(argv[1], nullptr, 10) : 14000;
  const int reps = argc > 2 ? std::atoi(argv[2]) : 2000;
  std::mt19937_64 gen(1);
  std::uniform_real_distribution<double> u(-3.0, 3.0), d(-0.01, 0.01);
  std::vector<double> now(3 * n), then(3 * n), out(6 * n), dg(4 * n);
  for (std::size_t k = 0; k < n; ++k)
    for (int c = 0; c < 3; ++c) {
      now[c * n + k] = u(gen);
      then[c * n + k] = now[c * n + k] - d(gen);
    }
  double sink = 0.0;
  const double t_scalar = best_ns_per_pair(n, reps, [&] {
    for (std::size_t k = 0; k < n; ++k) {
      const double a[3] = {now[k], now[n + k], now[2 * n + k]}, b[3] = {then[k], then[n + k], then[2 * n + k]};
      scalar_pair(a, b, &dg[4 * k]);
    }
    sink += dg[0];
  });
  std::printf("pairs %zu, repetitions %d\n%-28s %8s %10s\n", n, reps, "kernel", "ns/pair", "/ scalar");
  std::printf("%-28s %8.2f %10.3f\n", "scalar, pair by pair", t_scalar, 1.0);
  for (gcsimd::SimdPath path : {gcsimd::SimdPath::Generic, gcsimd::SimdPath::AVX2, gcsimd::SimdPath::AVX512}) {
    if (!gcsimd::simd_path_available(path)) continue;
    const gcfmm::Separations a{&now[0], &now[n], &now[2 * n]}, b{&then[0], &then[n], &then[2 * n]};
    const gcfmm::ChargePairChange o{&out[0], &out[n], &out[2 * n], &out[3 * n], &out[4 * n], &out[5 * n]};
    const double t = best_ns_per_pair(n, reps, [&] {
      gcfmm::charge_pair_change(n, a, b, o, path);
      sink += out[0];
    });
    std::printf("charge_pair_change %-9s %8.2f %10.3f\n", gcsimd::simd_path_name(path), t, t / t_scalar);
  }
  return sink == 12345.0;    // keeps the work
}
