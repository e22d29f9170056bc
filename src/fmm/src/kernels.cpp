// GRANULAR-CHARGED FMM core library (gcfmm): P2P kernel and direct reference sums.
#include "gcfmm/kernels.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "gcfmm/dipole_kernels.hpp"
#include "gcsimd/simd_paths.hpp"

#if GCSIMD_X86_DISPATCH
#include <immintrin.h>
#endif

namespace gcfmm {

namespace {

// Portable kernel (the Generic path, and every path where the x86 kernels below do not exist):
// exact 1/sqrt, vectorised over the sources by the compiler (omp simd reduction). Its sums run
// in another order than those of the x86 kernels (over sources, not over targets), so it is
// the reference they are tested against (test_p2p), not an instance of their loop.
GCSIMD_ALWAYS_INLINE void p2p_loop(std::size_t nt, const double *__restrict xt, const double *__restrict yt,
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
using p2p_loop_fn = void(*) GCFMM_P2P_PARAMS;

#if GCSIMD_X86_DISPATCH
// The x86 kernels (AVX2, AVX-512): one loop, vectorised over the W targets of a register
// (masked tail) with the sources broadcast one by one: no horizontal reductions, and each lane
// (target) sees exactly the same sequence of operations wherever it sits, so a target's result
// depends only on its position and the source range. 1/sqrt(r2) comes from a hardware estimate
// refined by Newton steps y <- y (3 - r2 y^2) / 2, because vsqrtpd + vdivpd are much slower
// (doc/benchmarks.md, "P2P kernels"); the estimate is the only difference between the two ISAs
// (Reg::rsqrt). The loop is a template over the register traits; the kernels that instantiate
// it carry the ISA's target attribute and `flatten`, which inlines the traits (compiled for
// that ISA) into them.
// GCC notes that vectors passed by value change the ABI of a function compiled without the
// ISA; the loop and its traits are only ever inlined into the kernel of their ISA (flatten),
// so no such call exists
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
template <class Reg, int Steps>
inline void p2p_rsqrt(std::size_t nt, const double *__restrict xt, const double *__restrict yt,
                      const double *__restrict zt, std::size_t ns, const double *__restrict xs,
                      const double *__restrict ys, const double *__restrict zs, const double *__restrict qs,
                      double sx, double sy, double sz, double *__restrict pot, double *__restrict ex,
                      double *__restrict ey, double *__restrict ez, double r2_min) {
  using V = typename Reg::V;
  const V rmin2 = Reg::set1(r2_min), zero = Reg::set1(0.0);
  for (std::size_t i = 0; i < nt; i += Reg::kWidth) {
    const typename Reg::Mask m = Reg::tail(nt - i);
    const V xi = Reg::sub(Reg::load(m, xt + i), Reg::set1(sx));
    const V yi = Reg::sub(Reg::load(m, yt + i), Reg::set1(sy));
    const V zi = Reg::sub(Reg::load(m, zt + i), Reg::set1(sz));
    V p = zero, fx = zero, fy = zero, fz = zero;
    for (std::size_t j = 0; j < ns; ++j) {
      const V dx = Reg::sub(xi, Reg::set1(xs[j]));
      const V dy = Reg::sub(yi, Reg::set1(ys[j]));
      const V dz = Reg::sub(zi, Reg::set1(zs[j]));
      const V r2 = Reg::fmadd(dx, dx, Reg::fmadd(dy, dy, Reg::mul(dz, dz)));
      const V y = Reg::template rsqrt<Steps>(r2, rmin2);    // 0 for the self term and coincident pairs
      const V qi = Reg::mul(Reg::set1(qs[j]), y);
      const V qi3 = Reg::mul(qi, Reg::mul(y, y));
      p = Reg::add(p, qi);
      fx = Reg::fmadd(dx, qi3, fx);
      fy = Reg::fmadd(dy, qi3, fy);
      fz = Reg::fmadd(dz, qi3, fz);
    }
    Reg::add_store(m, pot + i, p);
    Reg::add_store(m, ex + i, fx);
    Reg::add_store(m, ey + i, fy);
    Reg::add_store(m, ez + i, fz);
  }
}

// one Newton step for 1/sqrt(r2), hr2 = r2 / 2: y (3/2 - hr2 y^2), its relative error squared
#define GCFMM_NEWTON(fnmadd, mul, y, hr2, three_half) y = mul(y, fnmadd(hr2, mul(y, y), three_half))

// AVX-512, 8 targets: the 14-bit estimate (vrsqrt14pd, zero where the pair is dropped) and two
// Newton steps (2^-14 -> 2^-28 -> ~1e-16), or one where the accuracy allows (p2p_kernel_within)
struct Avx512 {
  using V = __m512d;
  using Mask = __mmask8;
  static constexpr std::size_t kWidth = 8;
  static constexpr int kFullSteps = 2;    // Newton steps to round-off
  GCSIMD_TARGET_AVX512 static Mask tail(std::size_t left) {
    return left >= 8 ? static_cast<__mmask8>(0xFF) : static_cast<__mmask8>((1u << left) - 1u);
  }
  GCSIMD_TARGET_AVX512 static V set1(double v) { return _mm512_set1_pd(v); }
  GCSIMD_TARGET_AVX512 static V load(Mask m, const double *p) { return _mm512_maskz_loadu_pd(m, p); }
  GCSIMD_TARGET_AVX512 static void add_store(Mask m, double *p, V v) {
    _mm512_mask_storeu_pd(p, m, _mm512_add_pd(_mm512_maskz_loadu_pd(m, p), v));
  }
  GCSIMD_TARGET_AVX512 static V add(V a, V b) { return _mm512_add_pd(a, b); }
  GCSIMD_TARGET_AVX512 static V sub(V a, V b) { return _mm512_sub_pd(a, b); }
  GCSIMD_TARGET_AVX512 static V mul(V a, V b) { return _mm512_mul_pd(a, b); }
  GCSIMD_TARGET_AVX512 static V fmadd(V a, V b, V c) { return _mm512_fmadd_pd(a, b, c); }
  template <int Steps>
  GCSIMD_TARGET_AVX512 static V rsqrt(V r2, V rmin2) {
    static_assert(Steps == 1 || Steps == 2, "AVX-512 P2P: 1 or 2 Newton steps");
    const __m512d half = _mm512_set1_pd(0.5), three_half = _mm512_set1_pd(1.5);
    const __mmask8 keep = _mm512_cmp_pd_mask(r2, rmin2, _CMP_GT_OQ);
    __m512d y = _mm512_maskz_rsqrt14_pd(keep, r2);
    const __m512d hr2 = _mm512_mul_pd(half, r2);
    GCFMM_NEWTON(_mm512_fnmadd_pd, _mm512_mul_pd, y, hr2, three_half);
    if constexpr (Steps == 2) GCFMM_NEWTON(_mm512_fnmadd_pd, _mm512_mul_pd, y, hr2, three_half);
    return y;
  }
};

// AVX2, 4 targets: the single-precision estimate (vrsqrtps, relative error <= 1.5 2^-12) and
// three Newton steps (2^-12 -> 2^-23 -> 2^-45 -> round-off), or fewer where the accuracy allows
// (p2p_kernel_within). Lanes whose r2 is outside the normal single-precision range (below
// 1e-36 or above 1e36, where the estimate does not exist) take the exact 1/sqrt instead.
struct Avx2 {
  using V = __m256d;
  using Mask = __m256i;
  static constexpr std::size_t kWidth = 4;
  static constexpr int kFullSteps = 3;    // Newton steps to round-off
  GCSIMD_TARGET_AVX2 static Mask tail(std::size_t left) {
    const long long all = -1;
    return _mm256_set_epi64x(left > 3 ? all : 0, left > 2 ? all : 0, left > 1 ? all : 0, all);
  }
  GCSIMD_TARGET_AVX2 static V set1(double v) { return _mm256_set1_pd(v); }
  GCSIMD_TARGET_AVX2 static V load(Mask m, const double *p) { return _mm256_maskload_pd(p, m); }
  GCSIMD_TARGET_AVX2 static void add_store(Mask m, double *p, V v) {
    _mm256_maskstore_pd(p, m, _mm256_add_pd(_mm256_maskload_pd(p, m), v));
  }
  GCSIMD_TARGET_AVX2 static V add(V a, V b) { return _mm256_add_pd(a, b); }
  GCSIMD_TARGET_AVX2 static V sub(V a, V b) { return _mm256_sub_pd(a, b); }
  GCSIMD_TARGET_AVX2 static V mul(V a, V b) { return _mm256_mul_pd(a, b); }
  GCSIMD_TARGET_AVX2 static V fmadd(V a, V b, V c) { return _mm256_fmadd_pd(a, b, c); }
  template <int Steps>
  GCSIMD_TARGET_AVX2 static V rsqrt(V r2, V rmin2) {
    static_assert(Steps >= 1 && Steps <= 3, "AVX2 P2P: 1 to 3 Newton steps");
    const __m256d half = _mm256_set1_pd(0.5), three_half = _mm256_set1_pd(1.5);
    const __m256d lo = _mm256_set1_pd(1e-36), hi = _mm256_set1_pd(1e36), one = _mm256_set1_pd(1.0);
    const __m256d keep = _mm256_cmp_pd(r2, rmin2, _CMP_GT_OQ);
    __m256d y = _mm256_cvtps_pd(_mm_rsqrt_ps(_mm256_cvtpd_ps(r2)));
    const __m256d hr2 = _mm256_mul_pd(half, r2);
    GCFMM_NEWTON(_mm256_fnmadd_pd, _mm256_mul_pd, y, hr2, three_half);
    if constexpr (Steps >= 2) GCFMM_NEWTON(_mm256_fnmadd_pd, _mm256_mul_pd, y, hr2, three_half);
    if constexpr (Steps >= 3) GCFMM_NEWTON(_mm256_fnmadd_pd, _mm256_mul_pd, y, hr2, three_half);
    const __m256d out = _mm256_or_pd(_mm256_cmp_pd(r2, lo, _CMP_LT_OQ), _mm256_cmp_pd(r2, hi, _CMP_GT_OQ));
    if (_mm256_movemask_pd(_mm256_and_pd(out, keep))) y = _mm256_blendv_pd(y, _mm256_div_pd(one, _mm256_sqrt_pd(r2)), out);
    return _mm256_and_pd(y, keep);
  }
};
#undef GCFMM_NEWTON

__attribute__((flatten)) GCSIMD_TARGET_AVX512 void p2p_rsqrt_avx512 GCFMM_P2P_PARAMS {
  p2p_rsqrt<Avx512, Avx512::kFullSteps> GCFMM_P2P_ARGS;
}
__attribute__((flatten)) GCSIMD_TARGET_AVX512 void p2p_rsqrt_avx512_newton1 GCFMM_P2P_PARAMS {
  p2p_rsqrt<Avx512, 1> GCFMM_P2P_ARGS;
}
__attribute__((flatten)) GCSIMD_TARGET_AVX2 void p2p_rsqrt_avx2 GCFMM_P2P_PARAMS {
  p2p_rsqrt<Avx2, Avx2::kFullSteps> GCFMM_P2P_ARGS;
}
__attribute__((flatten)) GCSIMD_TARGET_AVX2 void p2p_rsqrt_avx2_newton2 GCFMM_P2P_PARAMS {
  p2p_rsqrt<Avx2, 2> GCFMM_P2P_ARGS;
}
__attribute__((flatten)) GCSIMD_TARGET_AVX2 void p2p_rsqrt_avx2_newton1 GCFMM_P2P_PARAMS {
  p2p_rsqrt<Avx2, 1> GCFMM_P2P_ARGS;
}
#pragma GCC diagnostic pop
#endif

// the portable kernel (above)
void p2p_loop_generic GCFMM_P2P_PARAMS { p2p_loop GCFMM_P2P_ARGS; }

// the P2P kernel of a path: the loop for Generic, the rsqrt kernels for AVX2 and AVX-512
p2p_loop_fn p2p_kernel(gcsimd::SimdPath path) {
#if GCSIMD_X86_DISPATCH
  if (path == gcsimd::SimdPath::AVX512) return p2p_rsqrt_avx512;
  if (path == gcsimd::SimdPath::AVX2) return p2p_rsqrt_avx2;
#endif
  (void) path;
  return p2p_loop_generic;
}

// The largest relative error of one pair's field term of the reduced kernels (its potential
// term has a third of it). One Newton step from an estimate of relative error e leaves
// 1.5 e^2 + e^3 / 2, and the field term carries y^3, three times the error of y. vrsqrt14pd:
// e <= 2^-14, so 5.6e-9 after one step (1.7e-8 in the field term); vrsqrtps: e <= 1.5 2^-12
// (with 2^-25 from rounding r2 to single precision), so 2.0e-7 after one step (6.0e-7) and
// 6.1e-14 after two (1.8e-13). Rounded up; test_p2p measures them.
constexpr double kAvx512Newton1TermError = 2e-8;
constexpr double kAvx2Newton1TermError = 7e-7;
constexpr double kAvx2Newton2TermError = 2e-13;

}  // namespace

P2PKernel p2p_kernel_within(double max_term_error, gcsimd::SimdPath path) {
  if (!gcsimd::simd_path_available(path))
    throw std::invalid_argument(std::string("gcfmm: SIMD path ") + gcsimd::simd_path_name(path) + " not available");
#if GCSIMD_X86_DISPATCH
  if (path == gcsimd::SimdPath::AVX512)
    return max_term_error >= kAvx512Newton1TermError ? P2PKernel{p2p_rsqrt_avx512_newton1, kAvx512Newton1TermError}
                                                     : P2PKernel{p2p_rsqrt_avx512, 0.0};
  if (path == gcsimd::SimdPath::AVX2) {
    if (max_term_error >= kAvx2Newton1TermError) return {p2p_rsqrt_avx2_newton1, kAvx2Newton1TermError};
    if (max_term_error >= kAvx2Newton2TermError) return {p2p_rsqrt_avx2_newton2, kAvx2Newton2TermError};
  }
#endif
  return {p2p_kernel(path), 0.0};
}

void p2p_with(gcsimd::SimdPath path, std::size_t nt, const double *xt, const double *yt, const double *zt, std::size_t ns,
              const double *xs, const double *ys, const double *zs, const double *qs, double sx, double sy, double sz,
              double *pot, double *ex, double *ey, double *ez, double r2_min) {
  p2p_kernel_within(0.0, path).run GCFMM_P2P_ARGS;    // full precision; throws if not available
}

void p2p(std::size_t nt, const double *xt, const double *yt, const double *zt, std::size_t ns, const double *xs,
         const double *ys, const double *zs, const double *qs, double sx, double sy, double sz, double *pot,
         double *ex, double *ey, double *ez, double r2_min) {
  static const p2p_loop_fn kernel = p2p_kernel(gcsimd::default_simd_path());
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

namespace {

// P2P of charges and dipoles (p2p_dipoles): the terms of dipole_kernels.hpp, only those the
// sources carry (kCharges, kDipoles) and the gradient only with kGradient.
#define GCFMM_P2PD_PARAMS                                                                                  \
  (std::size_t nt, const double *xt, const double *yt, const double *zt, std::size_t ns, const double *xs,       \
   const double *ys, const double *zs, const double *qs, const double *pxs, const double *pys, const double *pzs, \
   double sx, double sy, double sz, double *pot, double *ex, double *ey, double *ez, double *g6, double r2_min)
#define GCFMM_P2PD_ARGS (nt, xt, yt, zt, ns, xs, ys, zs, qs, pxs, pys, pzs, sx, sy, sz, pot, ex, ey, ez, g6, r2_min)
using p2p_dipoles_fn = void(*) GCFMM_P2PD_PARAMS;

// the gradient of target i, 6 values, added
template <class F>
inline void add_gradient(double *g, const F &f) {
  g[0] += f.gxx;
  g[1] += f.gxy;
  g[2] += f.gxz;
  g[3] += f.gyy;
  g[4] += f.gyz;
  g[5] += f.gzz;
}

// Portable: vectorised over the sources by the compiler (omp simd), exact 1/sqrt; a pair at or
// inside r2_min gets rinv = 0 (adds nothing) and a harmless distance.
template <bool kCharges, bool kDipoles, bool kGradient>
inline void p2p_dipoles_loop GCFMM_P2PD_PARAMS {
  for (std::size_t i = 0; i < nt; ++i) {
    const double tx = xt[i] - sx, ty = yt[i] - sy, tz = zt[i] - sz;
    double ap = 0, ax = 0, ay = 0, az = 0, gxx = 0, gxy = 0, gxz = 0, gyy = 0, gyz = 0, gzz = 0;
#pragma omp simd reduction(+ : ap, ax, ay, az, gxx, gxy, gxz, gyy, gyz, gzz)
    for (std::size_t j = 0; j < ns; ++j) {
      const double dx = tx - xs[j], dy = ty - ys[j], dz = tz - zs[j];
      const double r2 = dx * dx + dy * dy + dz * dz;
      const bool keep = r2 > r2_min;
      const double rinv = keep ? 1.0 / std::sqrt(keep ? r2 : 1.0) : 0.0;
      FieldTerms<double> f;
      if (kCharges) charge_terms<kGradient>(qs[j], dx, dy, dz, rinv, f);
      if (kDipoles) dipole_terms<kGradient>(pxs[j], pys[j], pzs[j], dx, dy, dz, rinv, f);
      ap += f.pot;
      ax += f.ex;
      ay += f.ey;
      az += f.ez;
      gxx += f.gxx;
      gxy += f.gxy;
      gxz += f.gxz;
      gyy += f.gyy;
      gyz += f.gyz;
      gzz += f.gzz;
    }
    pot[i] += ap;
    ex[i] += ax;
    ey[i] += ay;
    ez[i] += az;
    if (kGradient) add_gradient(g6 + 6 * i, FieldTerms<double>{0, 0, 0, 0, gxx, gxy, gxz, gyy, gyz, gzz});
  }
}

#if GCSIMD_X86_DISPATCH
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
// FieldTerms<__m512d>: the register types' may_alias attribute does not carry into the template
// argument, which is harmless here (the members are only used as values)
#pragma GCC diagnostic ignored "-Wignored-attributes"
// x86: vectorised over the targets of a register, the sources broadcast one by one, 1/sqrt from
// the hardware estimate and Newton steps (Reg::rsqrt: 0 for dropped pairs), as p2p_rsqrt; the
// terms run on the register type through GCC's vector operators
template <class Reg, bool kCharges, bool kDipoles, bool kGradient>
inline void p2p_dipoles_rsqrt GCFMM_P2PD_PARAMS {
  using V = typename Reg::V;
  const V rmin2 = Reg::set1(r2_min);
  for (std::size_t i = 0; i < nt; i += Reg::kWidth) {
    const typename Reg::Mask m = Reg::tail(nt - i);
    const V xi = Reg::load(m, xt + i) - Reg::set1(sx);
    const V yi = Reg::load(m, yt + i) - Reg::set1(sy);
    const V zi = Reg::load(m, zt + i) - Reg::set1(sz);
    FieldTerms<V> f;
    for (std::size_t j = 0; j < ns; ++j) {
      const V dx = xi - Reg::set1(xs[j]), dy = yi - Reg::set1(ys[j]), dz = zi - Reg::set1(zs[j]);
      const V rinv = Reg::template rsqrt<Reg::kFullSteps>(dx * dx + dy * dy + dz * dz, rmin2);
      if (kCharges) charge_terms<kGradient>(Reg::set1(qs[j]), dx, dy, dz, rinv, f);
      if (kDipoles) dipole_terms<kGradient>(Reg::set1(pxs[j]), Reg::set1(pys[j]), Reg::set1(pzs[j]), dx, dy, dz, rinv, f);
    }
    Reg::add_store(m, pot + i, f.pot);
    Reg::add_store(m, ex + i, f.ex);
    Reg::add_store(m, ey + i, f.ey);
    Reg::add_store(m, ez + i, f.ez);
    if (kGradient) {
      double g[6][Reg::kWidth];
      const V *parts[6] = {&f.gxx, &f.gxy, &f.gxz, &f.gyy, &f.gyz, &f.gzz};
      for (int c = 0; c < 6; ++c) std::memcpy(g[c], parts[c], sizeof(V));
      const std::size_t lanes = std::min<std::size_t>(Reg::kWidth, nt - i);
      for (std::size_t l = 0; l < lanes; ++l)
        for (int c = 0; c < 6; ++c) g6[6 * (i + l) + c] += g[c][l];
    }
  }
}
#pragma GCC diagnostic pop
#endif

// the instance of what the sources carry
#define GCFMM_P2PD_CHOOSE(KERNEL)                                        \
  if (g6) {                                                              \
    if (charges && dipoles) KERNEL(true, true, true);                    \
    else if (charges) KERNEL(true, false, true);                         \
    else if (dipoles) KERNEL(false, true, true);                         \
  } else {                                                               \
    if (charges && dipoles) KERNEL(true, true, false);                   \
    else if (charges) KERNEL(true, false, false);                        \
    else if (dipoles) KERNEL(false, true, false);                        \
  }

#define GCFMM_P2PD_GENERIC(C, D, G) p2p_dipoles_loop<C, D, G> GCFMM_P2PD_ARGS
void p2p_dipoles_generic(std::size_t nt, const double *xt, const double *yt, const double *zt, std::size_t ns,
                         const double *xs, const double *ys, const double *zs, const double *qs, const double *pxs,
                         const double *pys, const double *pzs, double sx, double sy, double sz, double *pot,
                         double *ex, double *ey, double *ez, double *g6, double r2_min, bool charges, bool dipoles) {
  GCFMM_P2PD_CHOOSE(GCFMM_P2PD_GENERIC)
}
#if GCSIMD_X86_DISPATCH
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
#define GCFMM_P2PD_AVX512(C, D, G) p2p_dipoles_rsqrt<Avx512, C, D, G> GCFMM_P2PD_ARGS
#define GCFMM_P2PD_AVX2(C, D, G) p2p_dipoles_rsqrt<Avx2, C, D, G> GCFMM_P2PD_ARGS
__attribute__((flatten)) GCSIMD_TARGET_AVX512 void p2p_dipoles_avx512(
    std::size_t nt, const double *xt, const double *yt, const double *zt, std::size_t ns, const double *xs,
    const double *ys, const double *zs, const double *qs, const double *pxs, const double *pys, const double *pzs,
    double sx, double sy, double sz, double *pot, double *ex, double *ey, double *ez, double *g6, double r2_min,
    bool charges, bool dipoles) {
  GCFMM_P2PD_CHOOSE(GCFMM_P2PD_AVX512)
}
__attribute__((flatten)) GCSIMD_TARGET_AVX2 void p2p_dipoles_avx2(
    std::size_t nt, const double *xt, const double *yt, const double *zt, std::size_t ns, const double *xs,
    const double *ys, const double *zs, const double *qs, const double *pxs, const double *pys, const double *pzs,
    double sx, double sy, double sz, double *pot, double *ex, double *ey, double *ez, double *g6, double r2_min,
    bool charges, bool dipoles) {
  GCFMM_P2PD_CHOOSE(GCFMM_P2PD_AVX2)
}
#pragma GCC diagnostic pop
#endif

}  // namespace

void p2p_dipoles(std::size_t nt, const double *xt, const double *yt, const double *zt, std::size_t ns,
                 const double *xs, const double *ys, const double *zs, const double *qs, const double *pxs,
                 const double *pys, const double *pzs, double sx, double sy, double sz, double *pot, double *ex,
                 double *ey, double *ez, double *g6, double r2_min) {
  // what this source range carries: a range without dipoles (or charges) skips their terms
  bool charges = false, dipoles = false;
  for (std::size_t j = 0; j < ns; ++j) {
    charges = charges || qs[j] != 0.0;
    dipoles = dipoles || pxs[j] != 0.0 || pys[j] != 0.0 || pzs[j] != 0.0;
  }
  if (!dipoles && !g6) {  // charges only: the P2P of evaluate()
    p2p(nt, xt, yt, zt, ns, xs, ys, zs, qs, sx, sy, sz, pot, ex, ey, ez, r2_min);
    return;
  }
  using Kernel = void (*)(std::size_t, const double *, const double *, const double *, std::size_t, const double *,
                         const double *, const double *, const double *, const double *, const double *,
                         const double *, double, double, double, double *, double *, double *, double *, double *,
                         double, bool, bool);
  static const Kernel kernel = [] {
#if GCSIMD_X86_DISPATCH
    const gcsimd::SimdPath p = gcsimd::default_simd_path();
    if (p == gcsimd::SimdPath::AVX512) return static_cast<Kernel>(p2p_dipoles_avx512);
    if (p == gcsimd::SimdPath::AVX2) return static_cast<Kernel>(p2p_dipoles_avx2);
#endif
    return static_cast<Kernel>(p2p_dipoles_generic);
  }();
  kernel(nt, xt, yt, zt, ns, xs, ys, zs, qs, pxs, pys, pzs, sx, sy, sz, pot, ex, ey, ez, g6, r2_min, charges, dipoles);
}

}  // namespace gcfmm
