/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

// The JKR contact law in the scaled variable s = 6^(1/3) (a / a_0)^(1/2) (doc/theory.md,
// eq. (1.4a)), where it has no material constant left:
//
//   3 delta / delta_C = s^4 - 4 s,    F_ne / F_C = s^6 / 9 - 2 s^3 / 3,    a = a_sep s^2,
//
// stable branch s >= 1; s = 1 is the separation point delta = -delta_C. Free of LAMMPS.

#ifndef LMP_GC_JKR_SCALED_H
#define LMP_GC_JKR_SCALED_H

#include <cstddef>

namespace gcsimd {
enum class SimdPath;    // gcsimd/simd.hpp: the instruction-set paths of the batched root
}

namespace LAMMPS_NS {
namespace JKRScaled {

  // The stable root s >= 1 of s^4 - 4 s = 3 Delta for Delta = delta / delta_C >= -1
  // (Delta < -1 is clamped to -1, s = 1). Accurate to a few units in the last place.
  double root(double Delta);

  // s[k] = root(Delta[k]) for k < n in one call, vectorised where the instruction set allows
  // (the table lookup needs a gather); every path gives root()'s result bit for bit. The pair
  // style gathers its contacts' Delta and solves them together: one root alone is a chain of
  // dependent operations (sqrt, table load, Newton division) that a vector of them hides.
  void roots(std::size_t n, const double *Delta, double *s);
  // the same on a given path (tests and benchmarks; an unavailable path falls back to generic)
  void roots(std::size_t n, const double *Delta, double *s, gcsimd::SimdPath path);

  // The same root by bisection (slow; for the table and for tests).
  double root_by_bisection(double Delta);

  // adhesive part 4 F_C (a/a_0)^(3/2) over F_C for a root s (doc/theory.md, eq. (1.4a));
  // T: double, or the lanes of marshall_lanes.h
  template <class T> inline __attribute__((always_inline)) T adhesive_over_fc(T s)
  {
    return 2.0 / 3.0 * s * s * s;
  }

  // F_ne / F_C for a root s (doc/theory.md, eq. (1.4a)): elastic s^6 / 9 minus the adhesive part
  template <class T> inline __attribute__((always_inline)) T force_over_fc(T s)
  {
    const T s3 = s * s * s;
    return s3 * s3 / 9.0 - adhesive_over_fc(s);
  }

}    // namespace JKRScaled
}    // namespace LAMMPS_NS

#endif
