/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "jkr_scaled.h"

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

double residual(double s, double Delta)
{
  return s * (s * s * s - 4.0) - 3.0 * Delta;
}

// one Newton step on g(s) = s^4 - 4 s - 3 Delta; g' = 4 (s^3 - 1) > 0 for s > 1
double newton_step(double s, double Delta)
{
  const double slope = 4.0 * (s * s * s - 1.0);
  return slope > 0.0 ? s - residual(s, Delta) / slope : s;
}

const std::array<double, N_INTERVALS + 2> &table()
{
  static const std::array<double, N_INTERVALS + 2> s_of_u = [] {
    std::array<double, N_INTERVALS + 2> t{};
    for (int i = 0; i < N_INTERVALS + 2; ++i) {
      const double u = i * H;
      t[i] = LAMMPS_NS::JKRScaled::root_by_bisection(u * u - 1.0);
    }
    return t;
  }();
  return s_of_u;
}

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

// Linear interpolation in u is good to ~3e-5 (h^2 / 8 times |s''| <= 1); two Newton steps
// square that twice. Near u = 0 the interpolation error shrinks with u as fast as s - 1 does,
// so the steps converge there too (the unit test checks the result against bisection).
double root(double Delta)
{
  if (!(Delta > -1.0)) return 1.0;
  const double u = std::sqrt(Delta + 1.0);
  double s;
  if (u < U_MAX) {
    const auto &t = table();
    const double x = u * (1.0 / H);
    const int i = static_cast<int>(x);
    const double f = x - i;
    s = t[i] + f * (t[i + 1] - t[i]);
    s = newton_step(s, Delta);
    s = newton_step(s, Delta);
  } else {
    // s^4 = 3 Delta + 4 s: one fixed-point pass from (3 Delta)^(1/4) leaves ~1e-4 (the map
    // contracts by 1 / s^3 < 0.007), three Newton steps finish
    const double s0 = std::sqrt(std::sqrt(3.0 * Delta));
    s = std::sqrt(std::sqrt(3.0 * Delta + 4.0 * s0));
    for (int it = 0; it < 3; ++it) s = newton_step(s, Delta);
  }
  return s;
}

}    // namespace JKRScaled
}    // namespace LAMMPS_NS
