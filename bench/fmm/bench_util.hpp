// GRANULAR-CHARGED FMM benchmarks: small helpers shared by the benchmark programs.
#ifndef GCFMM_BENCH_UTIL_HPP
#define GCFMM_BENCH_UTIL_HPP

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

namespace gcfmm_bench {

// a comma-separated list of numbers ("2000,20000") as a vector
template <class T>
std::vector<T> list(const char *s) {
  std::vector<T> v;
  std::string str(s);
  std::size_t a = 0;
  while (a <= str.size()) {
    std::size_t b = str.find(',', a);
    if (b == std::string::npos) b = str.size();
    v.push_back(static_cast<T>(std::atof(str.substr(a, b - a).c_str())));
    a = b + 1;
  }
  return v;
}

struct Bed {
  std::vector<double> x, y, z, q;
  double L = 0.0;
  std::size_t size() const { return x.size(); }
};

// The deposition geometry of the polarised benchmarks: lx = ly = 28 sqrt(N / 2000), radius-1
// particles, 90% on a jittered simple cubic lattice of spacing 2.2 from z = 1.2 (the bed), 10% at
// random above it up to z = 160 (at least 2.2 from every other); charges 1.
inline Bed deposition(std::size_t n, unsigned seed) {
  Bed b;
  b.L = 28.0 * std::sqrt(double(n) / 2000.0);
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double a = 2.2;
  const int m = std::max(1, int(b.L / a));
  const double s = b.L / m;  // lattice spacing that tiles the cell (>= a)
  const std::size_t nbed = n * 9 / 10;
  for (std::size_t k = 0; k < nbed; ++k) {
    b.x.push_back(s * (0.5 + k % m) + 0.05 * (u(g) - 0.5));
    b.y.push_back(s * (0.5 + (k / m) % m) + 0.05 * (u(g) - 0.5));
    b.z.push_back(1.2 + a * double(k / (m * m)) + 0.05 * (u(g) - 0.5));
  }
  const double top = b.z.back() + a;
  while (b.size() < n) {
    const double x = b.L * u(g), y = b.L * u(g), z = top + (160.0 - top) * u(g);
    bool ok = true;
    for (std::size_t j = nbed; j < b.size() && ok; ++j) {
      const double dx = std::remainder(x - b.x[j], b.L), dy = std::remainder(y - b.y[j], b.L), dz = z - b.z[j];
      ok = dx * dx + dy * dy + dz * dz >= a * a;
    }
    if (!ok) continue;
    b.x.push_back(x);
    b.y.push_back(y);
    b.z.push_back(z);
  }
  b.q.assign(n, 1.0);
  return b;
}

}  // namespace gcfmm_bench

#endif
