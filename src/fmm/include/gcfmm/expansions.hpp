// GRANULAR-CHARGED FMM core library (gcfmm).
// Multipole and local expansions of the 1/r kernel in complex solid harmonics.
//
// Notation (see src/fmm/README.md for the derivation): regular and irregular solid harmonics
//   Y_n^m(r) = r^n P_n^m(cos t) e^{i m phi} / (n+m)!  (up to the sign fixed by the recurrences)
//   T_n^m(r) = (n-m)! P_n^m(cos t) e^{i m phi} / r^{n+1}
// defined by the recurrences (W. Dehnen, Comput. Astrophys. Cosmol. 1:1 (2014), app. A)
//   Y_0^0 = 1,   Y_n^n = -(x+iy)/(2n) Y_{n-1}^{n-1},
//   Y_n^m = ((2n-1) z Y_{n-1}^m - r^2 Y_{n-2}^m) / ((n+m)(n-m)),
//   T_0^0 = 1/r, T_n^n = -(2n-1)(x+iy)/r^2 T_{n-1}^{n-1},
//   T_n^m = ((2n-1) z T_{n-1}^m - (n-1+m)(n-1-m) T_{n-2}^m) / r^2,
//   X_n^{-m} = (-1)^m conj(X_n^m),
// which satisfy 1/|x-y| = sum_{n,m} conj(Y_n^m(y)) T_n^m(x) for |y| < |x| and the addition
// theorems Y_n^m(a+b) = sum_{k,l} Y_k^l(a) Y_{n-k}^{m-l}(b),
//          T_n^m(x-y) = sum_{k,l} conj(Y_k^l(y)) T_{n+k}^{m+l}(x)   (|y| < |x|).
//
// Expansions (z_s, z_t: expansion centres)
//   multipole: phi(x) = sum_{n<=p,m} M_n^m T_n^m(x - z_s),       M_n^m = sum_j q_j conj(Y_n^m(y_j - z_s))
//   local:     phi(x) = sum_{n<=p,m} L_n^m conj(Y_n^m(x - z_t))
// Storage: "full" layout, index n*n + n + m for m = -n..n, (p+1)^2 complex numbers stored as
// [re[0..S), im[0..S)], S = (p+1)^2, i.e. 2 S doubles per expansion. Operators accumulate only
// m >= 0; symmetrize() fills m < 0 from X_n^{-m} = (-1)^m conj(X_n^m) (true for M and L of
// real charges).
#ifndef GCFMM_EXPANSIONS_HPP
#define GCFMM_EXPANSIONS_HPP

#include <cstddef>
#include <vector>

#include "gcfmm/types.hpp"

namespace gcfmm {

//! Translation operators of order p. Holds precomputed coefficient tables and scratch space
//! (so one instance must not be used by two threads at once). No allocation after construction.
class Operators {
 public:
  explicit Operators(int order);
  int order() const { return p_; }
  //! number of doubles of one expansion (2 (p+1)^2)
  std::size_t size() const { return 2 * static_cast<std::size_t>(S_); }

  /** @brief Regular solid harmonics Y_n^m(r), n <= nmax (<= p), full layout of order nmax. */
  void regular(const Vec3 &r, int nmax, double *re, double *im) const;
  /** @brief Irregular solid harmonics T_n^m(r), n <= nmax (<= p), full layout; @pre r != 0. */
  void irregular(const Vec3 &r, int nmax, double *re, double *im) const;
  /** @brief Fill m < 0 of an expansion from its m >= 0 part. */
  void symmetrize(double *a) const;

  /** P2M: M_n^m += sum_j q_j conj(Y_n^m(y_j - c)), m >= 0 only. */
  void p2m(std::size_t n, const double *x, const double *y, const double *z, const double *q,
           const Vec3 &c, double *M) const;
  /** Batched P2M over n particles, kBatch particles per SIMD lane (lane sums added at the end
   *  in a fixed order): same expansion as p2m() up to round-off; m >= 0 only. */
  void p2m_batch(std::size_t n, const double *x, const double *y, const double *z, const double *q, const Vec3 &c,
                 double *M) const;
  /** M2M: M_parent += shift of the (full) child multipole M_child; d = z_child - z_parent.
   *  M'_n^m = sum_{k<=n,l} conj(Y_k^l(d)) M_{n-k}^{m-l}; m >= 0 only. Exact (no truncation). */
  void m2m(const double *Mchild, const Vec3 &d, double *Mparent) const;
  /** M2L: L_t += T(R) M_s with R = z_t - z_s (source image shift included);
   *  L_n^m = (-1)^n sum_{k<=p-n,l} M_k^l T_{n+k}^{m+l}(R); m >= 0 only.
   *  @pre |R| > r_s + r_t (MAC); M_s full layout. */
  void m2l(const double *Ms, const Vec3 &R, double *Lt) const;
  /** Batched M2L: L_t += sum_{e < count} T(R[e]) M[e] (all entries act on one target).
   *  The entries are processed kBatch at a time, one per SIMD lane, so the arithmetic runs in
   *  lock-step over independent interactions (vectorises without reductions). The result
   *  depends only on the entry list, not on anything else. m >= 0 only. */
  void m2l_batch(std::size_t count, const double *const *M, const Vec3 *R, double *Lt) const;
  //! lanes of m2l_batch
  static constexpr int kBatch = 8;

  /** L2L: L_child += shift of the (full) parent local expansion; b = z_child - z_parent.
   *  L'_n^m = sum_{k<=p-n,l} L_{n+k}^{m+l} conj(Y_k^l(b)); m >= 0 only. Exact for degree p. */
  void l2l(const double *Lparent, const Vec3 &b, double *Lchild) const;
  /** L2P: potential and field E = -grad phi of the (full) local expansion at r = x - z_t, added. */
  void l2p(const double *L, const Vec3 &r, double &pot, double &ex, double &ey, double &ez) const;
  /** Batched L2P: adds the potential and field of the (full) local expansion about c at the n
   *  points (x, y, z)[0..n), kBatch points per SIMD lane. Lanes never mix, so each point's
   *  result depends only on its own position (not on n or its place in the batch). */
  void l2p_batch(const double *L, const Vec3 &c, std::size_t n, const double *x, const double *y, const double *z,
                 double *pot, double *ex, double *ey, double *ez) const;
  /** M2P (for tests): potential of the (full) multipole at r = x - z_s. */
  double m2p_potential(const double *M, const Vec3 &r) const;

 private:
  int p_;
  int S_;
  std::vector<double> inv_nm_;  // 1/((n+m)(n-m)) at [n*(p+1)+m]
  std::vector<double> nm1_;     // (n-1+m)(n-1-m)
  mutable std::vector<double> wr_, wi_, xr_, xi_;  // scratch harmonics
  mutable std::vector<double> bt_, bm_, ba_;         // m2l_batch scratch: T, M, accumulators
};

}  // namespace gcfmm

#endif
