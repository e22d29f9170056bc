// GRANULAR-CHARGED FMM core library (gcfmm): P2P kernel and direct reference sums.
#include "gcfmm/kernels.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "simd_paths.hpp"

#if GCFMM_X86_DISPATCH
#include <immintrin.h>
#endif

namespace gcfmm {

namespace {

// Portable kernel: exact 1/sqrt, vectorised by the compiler (omp simd reduction); compiled
// for each path of simd.hpp (p2p_loop_generic, _avx2, _avx512).
GCFMM_ALWAYS_INLINE void p2p_loop(std::size_t nt, const double *__restrict xt, const double *__restrict yt,
                        const double *__restrict zt, std::size_t ns, const double *__restrict xs,
                        const double *__restrict ys, const double *__restrict zs, const double *__restrict qs,
                        double sx, double sy, double sz, double *__restrict pot, double *__restrict ex,
                        double *__restrict ey, double *__restrict ez, double r2_min) {
  for (std::size_t i = 0; i < nt; ++i) {
    const double xi = xt[i] - sx, yi = yt[i] - sy, zi = zt[i] - sz;
    double p = 0.0, fx = 0.0, fy = 0.0, fz = 0.0;
#pragma omp simd reduction(+ : p, fx, fy, fz)
    for (std::size_t j = 0; j < ns; ++j) {
      const double dx = xi - xs[j], dy = yi - ys[j], dz = zi - zs[j];
      const double r2 = dx * dx + dy * dy + dz * dz;
      const double inv = r2 > r2_min ? 1.0 / std::sqrt(r2) : 0.0;
      const double qinv = qs[j] * inv;
      const double qinv3 = qinv * inv * inv;
      p += qinv;
      fx += dx * qinv3;
      fy += dy * qinv3;
      fz += dz * qinv3;
    }
    pot[i] += p;
    ex[i] += fx;
    ey[i] += fy;
    ez[i] += fz;
  }
}

#define GCFMM_P2P_PARAMS                                                                                    \
  (std::size_t nt, const double *xt, const double *yt, const double *zt, std::size_t ns, const double *xs,        \
   const double *ys, const double *zs, const double *qs, double sx, double sy, double sz, double *pot, double *ex, \
   double *ey, double *ez, double r2_min)
#define GCFMM_P2P_ARGS (nt, xt, yt, zt, ns, xs, ys, zs, qs, sx, sy, sz, pot, ex, ey, ez, r2_min)
GCFMM_DEFINE_SIMD_PATHS(void, p2p_loop, GCFMM_P2P_PARAMS, p2p_loop, GCFMM_P2P_ARGS)

#if GCFMM_X86_DISPATCH
// AVX-512 kernel, vectorised over 8 targets (masked tail) with the sources broadcast one by
// one: no horizontal reductions, and each lane (target) sees exactly the same sequence of
// operations wherever it sits, so a target's result depends only on its position and the
// source range. 1/sqrt(r2) comes from the 14-bit hardware estimate (vrsqrt14pd) refined by
// two Newton steps y <- y (3 - r2 y^2) / 2 (relative error 2^-14 -> 2^-28 -> ~1e-16),
// because vsqrtpd + vdivpd are much slower (doc/benchmarks.md, "P2P kernels").
GCFMM_TARGET_AVX512 void p2p_rsqrt_avx512(std::size_t nt, const double *__restrict xt, const double *__restrict yt,
                       const double *__restrict zt, std::size_t ns, const double *__restrict xs,
                       const double *__restrict ys, const double *__restrict zs, const double *__restrict qs,
                       double sx, double sy, double sz, double *__restrict pot, double *__restrict ex,
                       double *__restrict ey, double *__restrict ez, double r2_min) {
  const __m512d rmin2 = _mm512_set1_pd(r2_min);
  const __m512d half = _mm512_set1_pd(0.5), three_half = _mm512_set1_pd(1.5), zero = _mm512_setzero_pd();
  for (std::size_t i = 0; i < nt; i += 8) {
    const std::size_t left = nt - i;
    const __mmask8 m = left >= 8 ? static_cast<__mmask8>(0xFF) : static_cast<__mmask8>((1u << left) - 1u);
    const __m512d xi = _mm512_sub_pd(_mm512_maskz_loadu_pd(m, xt + i), _mm512_set1_pd(sx));
    const __m512d yi = _mm512_sub_pd(_mm512_maskz_loadu_pd(m, yt + i), _mm512_set1_pd(sy));
    const __m512d zi = _mm512_sub_pd(_mm512_maskz_loadu_pd(m, zt + i), _mm512_set1_pd(sz));
    __m512d p = zero, fx = zero, fy = zero, fz = zero;
    for (std::size_t j = 0; j < ns; ++j) {
      const __m512d dx = _mm512_sub_pd(xi, _mm512_set1_pd(xs[j]));
      const __m512d dy = _mm512_sub_pd(yi, _mm512_set1_pd(ys[j]));
      const __m512d dz = _mm512_sub_pd(zi, _mm512_set1_pd(zs[j]));
      const __m512d q = _mm512_set1_pd(qs[j]);
      const __m512d r2 = _mm512_fmadd_pd(dx, dx, _mm512_fmadd_pd(dy, dy, _mm512_mul_pd(dz, dz)));
      const __mmask8 nz = _mm512_cmp_pd_mask(r2, rmin2, _CMP_GT_OQ);  // drop the self term and coincident pairs
      __m512d y = _mm512_maskz_rsqrt14_pd(nz, r2);
      const __m512d hr2 = _mm512_mul_pd(half, r2);
      y = _mm512_mul_pd(y, _mm512_fnmadd_pd(hr2, _mm512_mul_pd(y, y), three_half));
      y = _mm512_mul_pd(y, _mm512_fnmadd_pd(hr2, _mm512_mul_pd(y, y), three_half));
      const __m512d qi = _mm512_mul_pd(q, y);
      const __m512d qi3 = _mm512_mul_pd(qi, _mm512_mul_pd(y, y));
      p = _mm512_add_pd(p, qi);
      fx = _mm512_fmadd_pd(dx, qi3, fx);
      fy = _mm512_fmadd_pd(dy, qi3, fy);
      fz = _mm512_fmadd_pd(dz, qi3, fz);
    }
    _mm512_mask_storeu_pd(pot + i, m, _mm512_add_pd(_mm512_maskz_loadu_pd(m, pot + i), p));
    _mm512_mask_storeu_pd(ex + i, m, _mm512_add_pd(_mm512_maskz_loadu_pd(m, ex + i), fx));
    _mm512_mask_storeu_pd(ey + i, m, _mm512_add_pd(_mm512_maskz_loadu_pd(m, ey + i), fy));
    _mm512_mask_storeu_pd(ez + i, m, _mm512_add_pd(_mm512_maskz_loadu_pd(m, ez + i), fz));
  }
}
// AVX2 kernel, the same structure as the AVX-512 one over 4 targets: 1/sqrt(r2) from the
// single-precision estimate (vrsqrtps, relative error <= 1.5 2^-12) refined by three Newton
// steps (2^-12 -> 2^-23 -> 2^-45 -> round-off), because vsqrtpd + vdivpd are slow
// (doc/benchmarks.md, "P2P kernels"). Lanes whose r2 is outside the normal single-precision
// range (below 1e-36 or above 1e36, where the estimate does not exist) take the exact
// 1/sqrt instead.
GCFMM_TARGET_AVX2 void p2p_rsqrt_avx2(std::size_t nt, const double *__restrict xt, const double *__restrict yt,
                                      const double *__restrict zt, std::size_t ns, const double *__restrict xs,
                                      const double *__restrict ys, const double *__restrict zs,
                                      const double *__restrict qs, double sx, double sy, double sz,
                                      double *__restrict pot, double *__restrict ex, double *__restrict ey,
                                      double *__restrict ez, double r2_min) {
  const __m256d rmin2 = _mm256_set1_pd(r2_min), half = _mm256_set1_pd(0.5), three_half = _mm256_set1_pd(1.5);
  const __m256d lo = _mm256_set1_pd(1e-36), hi = _mm256_set1_pd(1e36), one = _mm256_set1_pd(1.0);
  const __m256d zero = _mm256_setzero_pd();
  for (std::size_t i = 0; i < nt; i += 4) {
    const std::size_t left = nt - i;
    const long long all = -1;
    const __m256i m = _mm256_set_epi64x(left > 3 ? all : 0, left > 2 ? all : 0, left > 1 ? all : 0, all);
    const __m256d xi = _mm256_sub_pd(_mm256_maskload_pd(xt + i, m), _mm256_set1_pd(sx));
    const __m256d yi = _mm256_sub_pd(_mm256_maskload_pd(yt + i, m), _mm256_set1_pd(sy));
    const __m256d zi = _mm256_sub_pd(_mm256_maskload_pd(zt + i, m), _mm256_set1_pd(sz));
    __m256d p = zero, fx = zero, fy = zero, fz = zero;
    for (std::size_t j = 0; j < ns; ++j) {
      const __m256d dx = _mm256_sub_pd(xi, _mm256_set1_pd(xs[j]));
      const __m256d dy = _mm256_sub_pd(yi, _mm256_set1_pd(ys[j]));
      const __m256d dz = _mm256_sub_pd(zi, _mm256_set1_pd(zs[j]));
      const __m256d r2 = _mm256_fmadd_pd(dx, dx, _mm256_fmadd_pd(dy, dy, _mm256_mul_pd(dz, dz)));
      const __m256d keep = _mm256_cmp_pd(r2, rmin2, _CMP_GT_OQ);  // drop the self term and coincident pairs
      __m256d y = _mm256_cvtps_pd(_mm_rsqrt_ps(_mm256_cvtpd_ps(r2)));
      const __m256d hr2 = _mm256_mul_pd(half, r2);
      y = _mm256_mul_pd(y, _mm256_fnmadd_pd(hr2, _mm256_mul_pd(y, y), three_half));
      y = _mm256_mul_pd(y, _mm256_fnmadd_pd(hr2, _mm256_mul_pd(y, y), three_half));
      y = _mm256_mul_pd(y, _mm256_fnmadd_pd(hr2, _mm256_mul_pd(y, y), three_half));
      const __m256d out = _mm256_or_pd(_mm256_cmp_pd(r2, lo, _CMP_LT_OQ), _mm256_cmp_pd(r2, hi, _CMP_GT_OQ));
      if (_mm256_movemask_pd(_mm256_and_pd(out, keep))) y = _mm256_blendv_pd(y, _mm256_div_pd(one, _mm256_sqrt_pd(r2)), out);
      y = _mm256_and_pd(y, keep);
      const __m256d qi = _mm256_mul_pd(_mm256_set1_pd(qs[j]), y);
      const __m256d qi3 = _mm256_mul_pd(qi, _mm256_mul_pd(y, y));
      p = _mm256_add_pd(p, qi);
      fx = _mm256_fmadd_pd(dx, qi3, fx);
      fy = _mm256_fmadd_pd(dy, qi3, fy);
      fz = _mm256_fmadd_pd(dz, qi3, fz);
    }
    _mm256_maskstore_pd(pot + i, m, _mm256_add_pd(_mm256_maskload_pd(pot + i, m), p));
    _mm256_maskstore_pd(ex + i, m, _mm256_add_pd(_mm256_maskload_pd(ex + i, m), fx));
    _mm256_maskstore_pd(ey + i, m, _mm256_add_pd(_mm256_maskload_pd(ey + i, m), fy));
    _mm256_maskstore_pd(ez + i, m, _mm256_add_pd(_mm256_maskload_pd(ez + i, m), fz));
  }
}
#endif

// the P2P kernel of a path: the loop for Generic, the rsqrt kernels for AVX2 and AVX-512
p2p_loop_fn p2p_kernel(SimdPath path) {
#if GCFMM_X86_DISPATCH
  if (path == SimdPath::AVX512) return p2p_rsqrt_avx512;
  if (path == SimdPath::AVX2) return p2p_rsqrt_avx2;
#endif
  return p2p_loop_for(path);
}

}  // namespace

void p2p_with(SimdPath path, std::size_t nt, const double *xt, const double *yt, const double *zt, std::size_t ns,
              const double *xs, const double *ys, const double *zs, const double *qs, double sx, double sy, double sz,
              double *pot, double *ex, double *ey, double *ez, double r2_min) {
  if (!simd_path_available(path))
    throw std::invalid_argument(std::string("gcfmm: SIMD path ") + simd_path_name(path) + " not available");
  p2p_kernel(path) GCFMM_P2P_ARGS;
}

void p2p(std::size_t nt, const double *xt, const double *yt, const double *zt, std::size_t ns, const double *xs,
         const double *ys, const double *zs, const double *qs, double sx, double sy, double sz, double *pot,
         double *ex, double *ey, double *ez, double r2_min) {
  static const p2p_loop_fn kernel = p2p_kernel(default_simd_path());
  kernel GCFMM_P2P_ARGS;
}

void direct_free(std::size_t n, const double *x, const double *y, const double *z, const double *q,
                 double *pot, double *ex, double *ey, double *ez) {
  for (std::size_t i = 0; i < n; ++i) pot[i] = ex[i] = ey[i] = ez[i] = 0.0;
  p2p(n, x, y, z, n, x, y, z, q, 0.0, 0.0, 0.0, pot, ex, ey, ez);
}

void direct_images(std::size_t n, const double *x, const double *y, const double *z, const double *q,
                   double lx, double ly, int images, double *pot, double *ex, double *ey, double *ez) {
  if (images < 0) throw std::invalid_argument("gcfmm: direct_images needs images >= 0");
  if (!(lx > 0.0 && ly > 0.0)) throw std::invalid_argument("gcfmm: direct_images needs lx, ly > 0");
  for (std::size_t i = 0; i < n; ++i) pot[i] = ex[i] = ey[i] = ez[i] = 0.0;
  for (int nx = -images; nx <= images; ++nx)
    for (int ny = -images; ny <= images; ++ny)
      p2p(n, x, y, z, n, x, y, z, q, nx * lx, ny * ly, 0.0, pot, ex, ey, ez);
}

}  // namespace gcfmm
