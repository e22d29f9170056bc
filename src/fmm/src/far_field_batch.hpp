// GRANULAR-CHARGED FMM core library (gcfmm), internal: the per-particle work of the exact far
// field (PeriodicFarField: anterpolation and interpolation) for many particles at once, on the
// instruction-set paths of gcsimd. Each particle is a SIMD lane that performs the operations of
// the scalar formulas in the same order, and the file is compiled without fused multiply-adds
// (GCSIMD_BITWISE_OPTIONS): every path gives the scalar result bit for bit.
#ifndef GCFMM_FAR_FIELD_BATCH_HPP
#define GCFMM_FAR_FIELD_BATCH_HPP

#include <cstddef>

#include "gcsimd/simd.hpp"

namespace gcfmm {
namespace detail {

//! Largest number of Chebyshev nodes per direction (PeriodicFarField accepts up to 30).
constexpr int kFarFieldMaxNodes = 32;

/**
 * @brief Lagrange weights of the p first-kind Chebyshev nodes at n points t[k] in [-1, 1]:
 * s[i * stride + k] = S_i(t_k) and, if ds is not null, ds[i * stride + k] = S_i'(t_k), with
 * tab[i * p + k] = T_k(t_i) (the formula of PeriodicFarField::interp_weights, bit for bit).
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
