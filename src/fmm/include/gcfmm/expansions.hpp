// GRANULAR-CHARGED FMM core library (gcfmm).
// Multipole and local expansions of the 1/r kernel in complex solid harmonics.
//
// Notation, normalisation and the operators: doc/theory.md, section 3 (regular and irregular
// solid harmonics, eqs. (3.2)-(3.4); addition theorems, eqs. (3.5)-(3.7); expansions, eq. (3.8);
// P2M, M2M, M2L, L2L, L2P, eqs. (3.9)-(3.13)).
// Storage: "full" layout, index n*n + n + m for m = -n..n, (p+1)^2 complex numbers stored as
// [re[0..S), im[0..S)], S = (p+1)^2, i.e. 2 S doubles per expansion. Operators accumulate only
// m >= 0; symmetrize() fills m < 0 from X_n^{-m} = (-1)^m conj(X_n^m) (doc/theory.md, eq. (3.4);
// true for M and L of real charges).
#ifndef GCFMM_EXPANSIONS_HPP
#define GCFMM_EXPANSIONS_HPP

#include <cstddef>
#include <vector>

#include "gcsimd/simd.hpp"
#include "gcfmm/types.hpp"

namespace gcfmm {

namespace detail {
struct LaneState;
}

//! Translation operators of order p. Holds precomputed coefficient tables (read-only after
//! construction) and scratch space written by every operator except regular(), irregular()
//! and symmetrize(): those operators are therefore non-const, and one instance must not be
//! used by two threads at once. No allocation after construction.
//!
//! All operators run on kBatch SIMD lanes (one point or one interaction per lane) through one
//! solid-harmonic recurrence and one M2L kernel; the single-point forms p2m(), m2l() and l2p()
//! are the batched ones with a batch of one.
class Operators {
 public:
  /** @param order expansion order p, 1 <= p <= kMaxOrder
   *  @param path  instruction-set path of the batched operators (gcsimd/simd.hpp, src/simd)
   *  @throws std::invalid_argument on a bad order or an unavailable path */
  explicit Operators(int order, gcsimd::SimdPath path = gcsimd::default_simd_path());
  int order() const { return p_; }
  gcsimd::SimdPath simd_path() const { return path_; }  //!< instruction-set path of the batched operators
  //! number of doubles of one expansion (2 (p+1)^2)
  std::size_t size() const { return 2 * static_cast<std::size_t>(S_); }
  //! position of coefficient (n, m) in the full layout
  static constexpr int index(int n, int m) { return n * n + n + m; }

  /** @brief Regular solid harmonics Y_n^m(r), n <= nmax (<= p), full layout of order nmax
   *  (doc/theory.md, eq. (3.2)). */
  void regular(const Vec3 &r, int nmax, double *re, double *im) const;
  /** @brief Irregular solid harmonics T_n^m(r), n <= nmax (<= p), full layout (doc/theory.md,
   *  eq. (3.3)); @pre r != 0. */
  void irregular(const Vec3 &r, int nmax, double *re, double *im) const;
  /** @brief Fill m < 0 of an expansion from its m >= 0 part (doc/theory.md, eq. (3.4)). */
  void symmetrize(double *a) const;

  /** P2M (doc/theory.md, eq. (3.9)): M_n^m += sum_j q_j conj(Y_n^m(y_j - c)), m >= 0 only.
   *  The same as p2m_batch(). */
  void p2m(std::size_t n, const double *x, const double *y, const double *z, const double *q,
           const Vec3 &c, double *M);
  /** Batched P2M over n particles, kBatch particles per SIMD lane (lane sums added at the end
   *  in a fixed order); m >= 0 only. */
  void p2m_batch(std::size_t n, const double *x, const double *y, const double *z, const double *q, const Vec3 &c,
                 double *M);
  /** M2M (doc/theory.md, eq. (3.10)): M_parent += shift of the (full) child multipole M_child;
   *  d = z_child - z_parent. M'_n^m = sum_{k<=n,l} conj(Y_k^l(d)) M_{n-k}^{m-l}; m >= 0 only.
   *  Exact (no truncation). */
  void m2m(const double *Mchild, const Vec3 &d, double *Mparent);
  /** M2L (doc/theory.md, eq. (3.11)): L_t += T(R) M_s with R = z_t - z_s (source image shift
   *  included); L_n^m = (-1)^n sum_{k<=p-n,l} M_k^l T_{n+k}^{m+l}(R); m >= 0 only.
   *  @pre |R| > r_s + r_t (MAC); M_s full layout. The same as m2l_batch() with one entry. */
  void m2l(const double *Ms, const Vec3 &R, double *Lt);
  /** Batched M2L: L_t += sum_{e < count} T(R[e]) M[e] (all entries act on one target).
   *  The entries are processed kBatch at a time, one per SIMD lane, so the arithmetic runs in
   *  lock-step over independent interactions (vectorises without reductions). The result
   *  depends only on the entry list, not on anything else. m >= 0 only. */
  void m2l_batch(std::size_t count, const double *const *M, const Vec3 *R, double *Lt);
  //! lanes of the batched operators
  static constexpr int kBatch = 8;

  /** L2L (doc/theory.md, eq. (3.12)): L_child += shift of the (full) parent local expansion;
   *  b = z_child - z_parent. L'_n^m = sum_{k<=p-n,l} L_{n+k}^{m+l} conj(Y_k^l(b)); m >= 0 only.
   *  Exact for degree p. */
  void l2l(const double *Lparent, const Vec3 &b, double *Lchild);
  /** L2P (doc/theory.md, eq. (3.13)): potential and field E = -grad phi of the (full) local
   *  expansion at r = x - z_t, added. The same as l2p_batch() with one point. */
  void l2p(const double *L, const Vec3 &r, double &pot, double &ex, double &ey, double &ez);
  /** Batched L2P: adds the potential and field of the (full) local expansion about c at the n
   *  points (x, y, z)[0..n), kBatch points per SIMD lane. Lanes never mix, so each point's
   *  result depends only on its own position (not on n or its place in the batch). */
  void l2p_batch(const double *L, const Vec3 &c, std::size_t n, const double *x, const double *y, const double *z,
                 double *pot, double *ex, double *ey, double *ez);
  /** P2M of point dipoles (doc/polarization.md, eq. (5.1)): M_n^m += sum_j conj(p_j . grad
   *  Y_n^m(y_j - c)) = sum_j sum_l conj(Y_{n-1}^{m-l}(y_j - c) Y_1^l(p_j)) (the addition theorem
   *  (3.6) to first order), m >= 0 only. The multipole of a dipole has no monopole. */
  void p2m_dipoles(std::size_t n, const double *x, const double *y, const double *z, const double *px,
                   const double *py, const double *pz, const Vec3 &c, double *M);
  /** L2P with the field gradient (doc/polarization.md, eq. (5.2)): the (full) local expansion
   *  re-centred at r = x - z_t to degree 2 by (3.12); adds the potential, the field
   *  E = (Re L'_1^1, Im L'_1^1, -L'_1^0) and the gradient G_ab = dE_a/dx_b from L'_2^m.
   *  gxx, gxy, gxz, gyy, gyz, gzz: the six components of the symmetric G. */
  void l2p_gradient(const double *L, const Vec3 &r, double &pot, double &ex, double &ey, double &ez,
                    double *g6);
  /** M2P (for tests): potential of the (full) multipole at r = x - z_s (doc/theory.md, eq. (3.8)). */
  double m2p_potential(const double *M, const Vec3 &r);
  /** Batched M2P: adds the potential and field E = -grad phi of the (full) multipole about c
   *  at the n points (x, y, z)[0..n), kBatch points per SIMD lane; it is M2L (doc/theory.md,
   *  eq. (3.11)) to a local expansion about the point itself, of which only L_0^0 (the
   *  potential, eq. (3.8)) and L_1^m (the field, eq. (3.13) at r = 0) are formed: O(p^2) per
   *  point, with the same truncation (n + k <= p) as M2L + L2P. Lanes never mix.
   *  @pre every point outside the multipole's sphere (convergence: r_s < theta |x - c|). */
  void m2p_batch(const double *M, const Vec3 &c, std::size_t n, const double *x, const double *y, const double *z,
                 double *pot, double *ex, double *ey, double *ez);

 private:
  detail::LaneState lanes();
  int p_;
  int S_;
  gcsimd::SimdPath path_;
  std::vector<double> inv_nm_;  //!< 1/((n+m)(n-m)) at [n*(p+1)+m] (regular recurrence)
  std::vector<double> nm1_;     //!< (n-1+m)(n-1-m) at [n*(p+1)+m] (irregular recurrence)
  std::vector<double> harm_re_, harm_im_;  //!< scratch: harmonics of one vector (M2M, L2L, M2P)
  std::vector<double> lane_harm_;  //!< scratch: harmonics of kBatch points/vectors, lane-major
  std::vector<double> lane_mult_;  //!< scratch: kBatch gathered multipoles (M2L), lane-major
  std::vector<double> lane_acc_;   //!< scratch: kBatch accumulated expansions, lane-major
};

}  // namespace gcfmm

#endif
