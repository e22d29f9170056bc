// GRANULAR-CHARGED FMM core library (gcfmm), internal: the per-particle work of the exact far
// field (PeriodicFarField: anterpolation and interpolation) for many particles at once, on the
// instruction-set paths of gcsimd. Each particle is a SIMD lane that performs the operations of
// the scalar formulas in the same order, and the file is compiled without fused multiply-adds
// (GCSIMD_BITWISE_OPTIONS): every path gives the scalar result bit for bit.
#ifndef GCFMM_FAR_FIELD_BATCH_HPP
#define GCFMM_FAR_FIELD_BATCH_HPP

#include <cstddef>

#include "gcsimd/simd_paths.hpp"

namespace gcfmm {
namespace detail {

//! Largest number of Chebyshev nodes per direction (PeriodicFarField accepts up to 30).
constexpr int kFarFieldMaxNodes = 32;

/**
 * @brief The Lagrange weights of the p first-kind Chebyshev nodes t_i = cos(pi (2i+1) / 2p) at
 * t, with tab[i * p + k] = T_k(t_i): S_i(t) = 1/p + (2/p) sum_{k=1}^{p-1} T_k(t_i) T_k(t) (the
 * discrete orthogonality of the T_k; stable on [-1, 1] and slightly beyond), S_i' from
 * T_k' = k U_{k-1} and S_i'' from T_k'' = 4 T_{k-1}' + 2 t T_{k-1}'' - T_{k-2}''. T is double
 * (one point: PeriodicFarField's scalar paths) or a vector of them (one point per SIMD lane:
 * far_field_batch.cpp), with the same operations in the same order. ds and d2s may be null.
 */
template <class T>
GCSIMD_ALWAYS_INLINE void chebyshev_lagrange_weights(T t, int p, const double *tab, T *s, T *ds, T *d2s) {
  const T zero = T{}, one = T{} + 1.0;
  T tk[kFarFieldMaxNodes], dtk[kFarFieldMaxNodes], d2tk[kFarFieldMaxNodes];
  tk[0] = one;
  dtk[0] = d2tk[0] = zero;
  if (p > 1) {
    tk[1] = t;
    dtk[1] = one;
    d2tk[1] = zero;
  }
  T um1 = one, u = 2.0 * t;    // U_0, U_1
  for (int k = 2; k < p; ++k) {
    tk[k] = 2.0 * t * tk[k - 1] - tk[k - 2];
    dtk[k] = static_cast<double>(k) * u;
    if (d2s) d2tk[k] = 4.0 * dtk[k - 1] + 2.0 * t * d2tk[k - 1] - d2tk[k - 2];
    const T un = 2.0 * t * u - um1;
    um1 = u;
    u = un;
  }
  const double pd = p;
  for (int i = 0; i < p; ++i) {
    const double *ti = tab + static_cast<std::size_t>(i) * p;
    T a = T{} + 0.5, b = zero, c = zero;
    for (int k = 1; k < p; ++k) {
      a += ti[k] * tk[k];
      if (ds) b += ti[k] * dtk[k];
      if (d2s) c += ti[k] * d2tk[k];
    }
    s[i] = 2.0 * a / pd;
    if (ds) ds[i] = 2.0 * b / pd;
    if (d2s) d2s[i] = 2.0 * c / pd;
  }
}

//! The interpolant's value and derivatives in a box's coordinates, from one box's node values.
template <class T>
struct InterpolantDerivatives {
  T f, gx, gy, gz;                      // value and gradient
  T hxx, hxy, hxz, hyy, hyz, hzz;       // second derivatives (kHessian only)
};

/**
 * @brief Contracts the node values col of one box (p x p x pz, z fastest) with the weights of a
 * point and their derivatives (as chebyshev_lagrange_weights writes them): f = sum sx_a sy_b
 * sz_c col(a, b, c), its gradient and, with kHessian, its second derivatives. T is double (one
 * point) or a vector of them (one point per SIMD lane), with the same operations in the same
 * order; the second-derivative sums are separate accumulators, so they do not change the others.
 * Without kHessian d2sx, d2sy, d2sz are not read.
 */
template <bool kHessian, class T>
GCSIMD_ALWAYS_INLINE InterpolantDerivatives<T> contract_interpolant(int p, int pz, const double *col, const T *sx,
                                                                   const T *dsx, const T *d2sx, const T *sy,
                                                                   const T *dsy, const T *d2sy, const T *sz,
                                                                   const T *dsz, const T *d2sz) {
  T f{}, gx{}, gy{}, gz{}, hxx{}, hxy{}, hxz{}, hyy{}, hyz{}, hzz{};    // locals: kept in registers
  for (int a = 0; a < p; ++a) {
    T fa{}, fya{}, fyya{}, fza{}, fyza{}, fzza{};
    for (int bb = 0; bb < p; ++bb) {
      const double *src = col + static_cast<std::size_t>(a * p + bb) * pz;
      T v{}, vz{}, vzz{};
      for (int c = 0; c < pz; ++c) {
        v += sz[c] * src[c];
        vz += dsz[c] * src[c];
        if constexpr (kHessian) vzz += d2sz[c] * src[c];
      }
      fa += sy[bb] * v;
      fya += dsy[bb] * v;
      fza += sy[bb] * vz;
      if constexpr (kHessian) {
        fyya += d2sy[bb] * v;
        fyza += dsy[bb] * vz;
        fzza += sy[bb] * vzz;
      }
    }
    f += sx[a] * fa;
    gx += dsx[a] * fa;
    gy += sx[a] * fya;
    gz += sx[a] * fza;
    if constexpr (kHessian) {
      hxx += d2sx[a] * fa;
      hxy += dsx[a] * fya;
      hyy += sx[a] * fyya;
      hxz += dsx[a] * fza;
      hyz += sx[a] * fyza;
      hzz += sx[a] * fzza;
    }
  }
  return {f, gx, gy, gz, hxx, hxy, hxz, hyy, hyz, hzz};
}

/**
 * @brief Lagrange weights of the p first-kind Chebyshev nodes at n points t[k] in [-1, 1]:
 * s[i * stride + k] = S_i(t_k) and, if ds is not null, ds[i * stride + k] = S_i'(t_k), with
 * tab[i * p + k] = T_k(t_i) (chebyshev_lagrange_weights, one point per lane).
 */
void chebyshev_weights(gcsimd::SimdPath path, std::size_t n, const double *t, int p, const double *tab,
                       std::size_t stride, double *s, double *ds);

/**
 * @brief ADDS the node charges of m charges of one box to its column col (p x p x pz nodes,
 * z fastest): col[(a p + b) pz + c] += q_k sx_a sy_b sz_c for the x nodes a in [a0, a1), the
 * charges in their order k = 0 .. m-1 (weights as chebyshev_weights writes them, stride
 * `stride`; zero charges add nothing and are skipped).
 */
void anterpolate_box(gcsimd::SimdPath path, std::size_t m, const double *q, int p, int pz, int a0, int a1,
                     const double *sx, const double *sy, const double *sz, std::size_t stride, double *col);

/**
 * @brief Potential f and gradient (gx, gy, gz) in the box's coordinates (t in [-1, 1]) of the
 * interpolant of the node potentials col (one box) at m points of that box, from their
 * weights and derivatives (stride `stride`): f[k] = sum sx_a sy_b sz_c col(a, b, c).
 */
void interpolate_box(gcsimd::SimdPath path, std::size_t m, int p, int pz, const double *col, const double *sx,
                     const double *dsx, const double *sy, const double *dsy, const double *sz,
                     const double *dsz, std::size_t stride, double *f, double *gx, double *gy, double *gz);

}  // namespace detail
}  // namespace gcfmm

#endif
