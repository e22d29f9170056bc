// Shared helpers of the gcfmm unit tests: particle sets and error measures.
#ifndef GCFMM_TEST_UTIL_HPP
#define GCFMM_TEST_UTIL_HPP

#include <cmath>
#include <cstddef>
#include <random>
#include <vector>

namespace gcfmm_test {

struct Particles {
  std::vector<double> x, y, z, q;
  std::size_t size() const { return x.size(); }
  void resize(std::size_t n) {
    x.resize(n);
    y.resize(n);
    z.resize(n);
    q.resize(n);
  }
};

struct Field {
  std::vector<double> pot, ex, ey, ez;
  explicit Field(std::size_t n = 0) : pot(n), ex(n), ey(n), ez(n) {}
};

// n random charges of both signs (|q| in [0.5, 1.5]) uniform in a unit cube
inline Particles random_cube(std::size_t n, unsigned seed, double side = 1.0) {
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Particles p;
  p.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    p.x[i] = side * u(g);
    p.y[i] = side * u(g);
    p.z[i] = side * u(g);
    p.q[i] = (u(g) < 0.5 ? -1.0 : 1.0) * (0.5 + u(g));
  }
  return p;
}

// Deposition-like geometry: box lx = ly = 28 for N = 2000 (particle radius 1), 90% of the
// particles in a dense bed of volume fraction ~0.3 at the bottom (about 32 high), 10% spread
// up to z = 160. Equal charges. For other N the box width scales as sqrt(N / 2000) so that
// the bed keeps its height (lx <= 0: automatic).
// Positions are uniformly random (no minimum separation, so not a real packing: same density,
// and pairs closer than in a packing, which only makes the P2P part harder).
inline double deposition_width(std::size_t n) { return 28.0 * std::sqrt(double(n) / 2000.0); }
inline Particles deposition(std::size_t n, unsigned seed, double lx = 0.0, double ly = 0.0, double zmax = 160.0) {
  if (lx <= 0.0) lx = deposition_width(n);
  if (ly <= 0.0) ly = lx;
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const std::size_t nbed = (n * 9) / 10;
  const double vol = 4.0 / 3.0 * M_PI;                // sphere of radius 1
  const double hbed = nbed * vol / (0.3 * lx * ly);  // bed height for phi = 0.3
  Particles p;
  p.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const bool bed = i < nbed;
    p.x[i] = lx * u(g);
    p.y[i] = ly * u(g);
    p.z[i] = bed ? 1.0 + hbed * u(g) : 1.0 + hbed + (zmax - 1.0 - hbed) * u(g);
    p.q[i] = 1.0;
  }
  return p;
}

// relative RMS force error sqrt(sum |F - F_ref|^2 / sum |F_ref|^2) with F_i = q_i E_i,
// over the particles where the reference is available (mask empty = all)
inline double force_error(const std::vector<double> &q, const Field &a, const Field &ref) {
  double num = 0.0, den = 0.0;
  for (std::size_t i = 0; i < q.size(); ++i) {
    const double dx = q[i] * (a.ex[i] - ref.ex[i]), dy = q[i] * (a.ey[i] - ref.ey[i]),
                 dz = q[i] * (a.ez[i] - ref.ez[i]);
    num += dx * dx + dy * dy + dz * dz;
    den += q[i] * q[i] * (ref.ex[i] * ref.ex[i] + ref.ey[i] * ref.ey[i] + ref.ez[i] * ref.ez[i]);
  }
  return std::sqrt(num / den);
}

// relative RMS potential error
inline double potential_error(const Field &a, const Field &ref) {
  double num = 0.0, den = 0.0;
  for (std::size_t i = 0; i < a.pot.size(); ++i) {
    num += (a.pot[i] - ref.pot[i]) * (a.pot[i] - ref.pot[i]);
    den += ref.pot[i] * ref.pot[i];
  }
  return std::sqrt(num / den);
}

}  // namespace gcfmm_test

#endif
