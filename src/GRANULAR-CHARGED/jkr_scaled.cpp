/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

// Compiled with -ffp-contract=off -fno-math-errno -fno-trapping-math (CMakeLists.txt): the
// batched root must give the scalar one's result on every path (no fused multiply-adds), and
// GCC vectorises the guarded square root only without errno and traps.
#include "jkr_scaled.h"

#include "gcsimd/simd.hpp"
#include "gcsimd/simd_paths.hpp"

#include <array>
#include <cmath>

namespace {

// s on a uniform grid in u = sqrt(Delta + 1): near the separation point s - 1 ~ u / sqrt(2),
// so s is smooth in u where it has a square-root cusp in Delta. The table covers
// Delta <= U_MAX^2 - 1 = 255 (overlaps of ~20 delta_C at 1 m/s; beyond it, Newton from the
// asymptote).
constexpr int N_INTERVALS = 1024;
constexpr double U_MAX = 16.0;
constexpr double H = U_MAX / N_INTERVALS;

GCSIMD_ALWAYS_INLINE double residual(double s, double Delta)
{
  return s * (s * s * s - 4.0) - 3.0 * Delta;
}

// one Newton step on g(s) = s^4 - 4 s - 3 Delta; g' = 4 (s^3 - 1) > 0 for s > 1
GCSIMD_ALWAYS_INLINE double newton_step(double s, double Delta)
{
  const double slope = 4.0 * (s * s * s - 1.0);
  return slope > 0.0 ? s - residual(s, Delta) / slope : s;
}

// s and its slope H ds/du at the nodes, for cubic Hermite interpolation; ds/du follows from
// differentiating s^4 - 4 s = 3 (u^2 - 1): ds/du = 3 u / (2 (s^3 - 1)), 1/sqrt(2) at u = 0
struct Node {
  double s, slope;
};

const std::array<Node, N_INTERVALS + 2> &table()
{
  static const std::array<Node, N_INTERVALS + 2> s_of_u = [] {
    std::array<Node, N_INTERVALS + 2> t{};
    for (int i = 0; i < N_INTERVALS + 2; ++i) {
      const double u = i * H;
      const double s = LAMMPS_NS::JKRScaled::root_by_bisection(u * u - 1.0);
      const double dsdu = (i == 0) ? 1.0 / std::sqrt(2.0) : 3.0 * u / (2.0 * (s * s * s - 1.0));
      t[i] = {s, H * dsdu};
    }
    return t;
  }();
  return s_of_u;
}

// Cubic Hermite interpolation in u on the table, then one Newton step (root(), below, says why
// that is accurate); u < U_MAX
GCSIMD_ALWAYS_INLINE double table_root(const Node *t, double u, double Delta)
{
  const double x = u * (1.0 / H);
  const long i = static_cast<long>(x);    // long: GCC vectorises the gather with 64-bit indices
  const double f = x - i;
  const Node &a = t[i], &b = t[i + 1];
  // Hermite form s = a.s + f (a.slope + f (c2 + f c3))
  const double ds = b.s - a.s;
  const double c2 = 3.0 * ds - 2.0 * a.slope - b.slope;
  const double c3 = a.slope + b.slope - 2.0 * ds;
  const double s = a.s + f * (a.slope + f * (c2 + f * c3));
  return newton_step(s, Delta);
}

// root()'s table branch for every element (one outside the table, u >= U_MAX, is computed at
// u = 0 here and replaced by the caller)
GCSIMD_ALWAYS_INLINE void roots_loop(std::size_t n, const double *__restrict Delta,
                                    double *__restrict out, const Node *__restrict t)
{
#pragma omp simd
  for (std::size_t k = 0; k < n; ++k) {
    const double Delta_k = Delta[k];
    const bool attached = Delta_k > -1.0;
    const double u = std::sqrt(attached ? Delta_k + 1.0 : 0.0);
    const double s = table_root(t, u < U_MAX ? u : 0.0, Delta_k);
    out[k] = attached ? s : 1.0;
  }
}

#define GC_ROOTS_PARAMS (std::size_t n, const double *Delta, double *out, const Node *t)
#define GC_ROOTS_ARGS (n, Delta, out, t)
GCSIMD_DEFINE_PATHS(void, roots_kernel, GC_ROOTS_PARAMS, roots_loop, GC_ROOTS_ARGS)

}    // namespace

namespace LAMMPS_NS {
namespace JKRScaled {

double root_by_bisection(double Delta)
{
  if (!(Delta > -1.0)) return 1.0;
  double lo = 1.0, hi = 2.0;    // g(1) = -3 (Delta + 1) < 0; g increases for s > 1
  while (residual(hi, Delta) < 0.0) hi *= 2.0;
  for (int it = 0; it < 200 && hi - lo > 0.0; ++it) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;
    if (residual(mid, Delta) < 0.0)
      lo = mid;
    else
      hi = mid;
  }
  return (std::fabs(residual(lo, Delta)) < std::fabs(residual(hi, Delta))) ? lo : hi;
}

// Cubic Hermite interpolation in u is good to ~1e-10 (h^4 / 384 times the fourth derivative
// of s(u), of order 1; near u = 0 the error falls with u^2, as the interpolant matches s and
// ds/du at the node), and one Newton step squares that to rounding. Near u = 0 the Newton step
// amplifies the squared error by 1 / (2 (s - 1)), which the u^2 of the interpolation error
// more than compensates (the unit test checks the result against bisection down to
// Delta + 1 = 1e-12).
double root(double Delta)
{
  if (!(Delta > -1.0)) return 1.0;
  const double u = std::sqrt(Delta + 1.0);
  double s;
  if (u < U_MAX) {
    s = table_root(table().data(), u, Delta);
  } else {
    // s^4 = 3 Delta + 4 s: one fixed-point pass from (3 Delta)^(1/4) leaves ~1e-4 (the map
    // contracts by 1 / s^3 < 0.007), three Newton steps finish
    const double s0 = std::sqrt(std::sqrt(3.0 * Delta));
    s = std::sqrt(std::sqrt(3.0 * Delta + 4.0 * s0));
    for (int it = 0; it < 3; ++it) s = newton_step(s, Delta);
  }
  return s;
}

void roots(std::size_t n, const double *Delta, double *s, gcsimd::SimdPath path)
{
  if (!gcsimd::simd_path_available(path)) path = gcsimd::SimdPath::Generic;
  roots_kernel_for(path)(n, Delta, s, table().data());
  // beyond the table (Delta >= U_MAX^2 - 1 = 255; from 254, clear of sqrt's rounding): root()
  for (std::size_t k = 0; k < n; ++k)
    if (Delta[k] >= U_MAX * U_MAX - 2.0) s[k] = root(Delta[k]);
}

void roots(std::size_t n, const double *Delta, double *s)
{
  static const gcsimd::SimdPath path = gcsimd::default_simd_path();
  roots(n, Delta, s, path);
}

}    // namespace JKRScaled
}    // namespace LAMMPS_NS
