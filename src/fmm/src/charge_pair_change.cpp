// GRANULAR-CHARGED FMM core library (gcfmm): the change of charge pairs' terms between two
// separations (charge_pair_change.hpp). Compiled with -ffp-contract=off (src/fmm/CMakeLists.txt):
// a fused multiply-add rounds once where the scalar code rounds twice, and the callers rely on
// every path giving the scalar result; and with -fno-math-errno -fno-trapping-math, without
// which GCC keeps the division of inverse_distance() behind a branch and vectorises only the
// AVX-512 path (masked division).
#include "gcfmm/charge_pair_change.hpp"

#include <cmath>

#include "gcfmm/dipole_kernels.hpp"
#include "gcsimd/simd_paths.hpp"

namespace gcfmm {

namespace {

// exact 1/|d| (vsqrtpd, vdivpd where vectorised), 0 for d = 0 (charge_terms then adds nothing);
// computed for every lane (inf for d = 0) and then selected
GCSIMD_ALWAYS_INLINE double inverse_distance(double r2) {
  const double inv = 1.0 / std::sqrt(r2);
  return r2 > 0.0 ? inv : 0.0;
}

GCSIMD_ALWAYS_INLINE void change_loop(std::size_t n, const double *__restrict nx, const double *__restrict ny,
                                     const double *__restrict nz, const double *__restrict tx,
                                     const double *__restrict ty, const double *__restrict tz,
                                     double *__restrict ex, double *__restrict ey, double *__restrict ez,
                                     double *__restrict pot, double *__restrict r2now, double *__restrict r2then) {
#pragma omp simd
  for (std::size_t k = 0; k < n; ++k) {
    const double rn2 = nx[k] * nx[k] + ny[k] * ny[k] + nz[k] * nz[k];
    const double rt2 = tx[k] * tx[k] + ty[k] * ty[k] + tz[k] * tz[k];
    FieldTerms<double> a, b;
    charge_terms<false>(1.0, nx[k], ny[k], nz[k], inverse_distance(rn2), a);
    charge_terms<false>(1.0, tx[k], ty[k], tz[k], inverse_distance(rt2), b);
    ex[k] = a.ex - b.ex;
    ey[k] = a.ey - b.ey;
    ez[k] = a.ez - b.ez;
    pot[k] = a.pot - b.pot;
    r2now[k] = rn2;
    r2then[k] = rt2;
  }
}

GCSIMD_ALWAYS_INLINE void terms_loop(std::size_t n, const double *__restrict dx, const double *__restrict dy,
                                     const double *__restrict dz, double *__restrict ex, double *__restrict ey,
                                     double *__restrict ez, double *__restrict pot, double *__restrict r2) {
#pragma omp simd
  for (std::size_t k = 0; k < n; ++k) {
    const double d2 = dx[k] * dx[k] + dy[k] * dy[k] + dz[k] * dz[k];
    FieldTerms<double> a;
    charge_terms<false>(1.0, dx[k], dy[k], dz[k], inverse_distance(d2), a);
    ex[k] = a.ex;
    ey[k] = a.ey;
    ez[k] = a.ez;
    pot[k] = a.pot;
    r2[k] = d2;
  }
}

#define GCFMM_TERMS_PARAMS                                                                       \
  (std::size_t n, const double *dx, const double *dy, const double *dz, double *ex, double *ey,     \
   double *ez, double *pot, double *r2)
#define GCFMM_TERMS_ARGS (n, dx, dy, dz, ex, ey, ez, pot, r2)

GCSIMD_DEFINE_PATHS(void, terms_kernel, GCFMM_TERMS_PARAMS, terms_loop, GCFMM_TERMS_ARGS)

#define GCFMM_CHANGE_PARAMS                                                                      \
  (std::size_t n, const double *nx, const double *ny, const double *nz, const double *tx,          \
   const double *ty, const double *tz, double *ex, double *ey, double *ez, double *pot, double *r2now, \
   double *r2then)
#define GCFMM_CHANGE_ARGS (n, nx, ny, nz, tx, ty, tz, ex, ey, ez, pot, r2now, r2then)

GCSIMD_DEFINE_PATHS(void, change_kernel, GCFMM_CHANGE_PARAMS, change_loop, GCFMM_CHANGE_ARGS)

}  // namespace

void charge_pair_change(std::size_t n, Separations now, Separations then, ChargePairChange out,
                        gcsimd::SimdPath path) {
  change_kernel_for(path)(n, now.x, now.y, now.z, then.x, then.y, then.z, out.ex, out.ey, out.ez, out.pot,
                          out.r2now, out.r2then);
}

void charge_terms_at(std::size_t n, Separations at, ChargeTerms out, gcsimd::SimdPath path) {
  terms_kernel_for(path)(n, at.x, at.y, at.z, out.ex, out.ey, out.ez, out.pot, out.r2);
}

}  // namespace gcfmm
