// GRANULAR-CHARGED FMM core library (gcfmm): solid-harmonic expansions and translations.
// Formulas: doc/theory.md, section 3; storage layout: include/gcfmm/expansions.hpp.
//
// Structure: one recurrence for the solid harmonics (solid_harmonics<Kind, W>, W points at
// once in a lane-major layout) and one M2L kernel (m2l_row, one row n of the M2L double sum
// for kBatch interactions at once). Every operator is written once, for kBatch lanes; a
// single point or interaction is a batch of one.
#include "gcfmm/expansions.hpp"

#include "gcfmm/options.hpp"
#include "gcsimd/simd_paths.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace gcfmm {

namespace detail {
// The state the batched operators work on: order, recurrence tables and lane scratch.
struct LaneState {
  int p, S;               // order and (p+1)^2
  const double *inv_nm;   // regular recurrence table
  const double *nm1;      // irregular recurrence table
  double *harm, *mult, *acc;  // lane scratch: harmonics, gathered multipoles, accumulators
};

}  // namespace detail

namespace {

constexpr int kLanes = Operators::kBatch;
//! rows n <= kMaxFixedRow of the M2L sum are compiled with n known (outputs in registers)
constexpr int kMaxFixedRow = 16;

inline constexpr int idx(int n, int m) { return Operators::index(n, m); }

enum class Kind { Regular, Irregular };

// Solid harmonics X_n^m(r_v), n <= nmax, m >= 0, of W points r_v = (x, y, z)[v] at once;
// output X[idx(n, m) * W + v] (lane-major). Regular (doc/theory.md, eq. (3.2)):
//   Y_0^0 = 1, Y_n^n = -(x + iy) / (2n) Y_{n-1}^{n-1},
//   Y_n^m = ((2n-1) z Y_{n-1}^m - r^2 Y_{n-2}^m) / ((n+m)(n-m));
// irregular (eq. (3.3)):
//   T_0^0 = 1/r, T_n^n = -(2n-1) (x + iy) / r^2 T_{n-1}^{n-1},
//   T_n^m = ((2n-1) z T_{n-1}^m - (n-1+m)(n-1-m) T_{n-2}^m) / r^2.
// `tab` is inv_nm (regular) or nm1 (irregular), indexed [n * (p + 1) + m].
template <Kind K, int W>
GCSIMD_ALWAYS_INLINE void solid_harmonics(int nmax, int p, const double *tab, const double *x, const double *y, const double *z,
                     double *__restrict Xr, double *__restrict Xi) {
  double r2[W], ir2[W];
  for (int v = 0; v < W; ++v) {
    r2[v] = x[v] * x[v] + y[v] * y[v] + z[v] * z[v];
    if constexpr (K == Kind::Regular) {
      Xr[v] = 1.0;
    } else {
      ir2[v] = 1.0 / r2[v];
      Xr[v] = std::sqrt(ir2[v]);
    }
    Xi[v] = 0.0;
  }
  for (int n = 1; n <= nmax; ++n) {
    const double f = 2.0 * n - 1.0;
    const int dn = idx(n, n) * W, dp = idx(n - 1, n - 1) * W;
    for (int v = 0; v < W; ++v) {
      double c, d;  // the factor multiplying X_{n-1}^{n-1}: c + i d
      if constexpr (K == Kind::Regular) {
        const double h = -1.0 / (2.0 * n);
        c = h * x[v];
        d = h * y[v];
      } else {
        c = -f * x[v] * ir2[v];
        d = -f * y[v] * ir2[v];
      }
      const double a = Xr[dp + v], b = Xi[dp + v];
      Xr[dn + v] = c * a - d * b;
      Xi[dn + v] = c * b + d * a;
    }
    for (int m = 0; m < n; ++m) {
      const double t = tab[n * (p + 1) + m];
      const int i0 = idx(n, m) * W, i1 = idx(n - 1, m) * W;
      // X_n^m = (f z X_{n-1}^m - g X_{n-2}^m) s with (g, s) = (r^2, t) or (t, 1/r^2)
      if (m <= n - 2) {
        const int i2 = idx(n - 2, m) * W;
        for (int v = 0; v < W; ++v) {
          const double g = K == Kind::Regular ? r2[v] : t, s = K == Kind::Regular ? t : ir2[v];
          Xr[i0 + v] = (f * z[v] * Xr[i1 + v] - g * Xr[i2 + v]) * s;
          Xi[i0 + v] = (f * z[v] * Xi[i1 + v] - g * Xi[i2 + v]) * s;
        }
      } else {
        for (int v = 0; v < W; ++v) {
          const double s = K == Kind::Regular ? t : ir2[v];
          Xr[i0 + v] = f * z[v] * Xr[i1 + v] * s;
          Xi[i0 + v] = f * z[v] * Xi[i1 + v] * s;
        }
      }
    }
  }
}

// m < 0 from X_n^{-m} = (-1)^m conj(X_n^m) (doc/theory.md, eq. (3.4)), lane-major, n <= nmax
template <int W>
GCSIMD_ALWAYS_INLINE void fill_negative_m(int nmax, double *Xr, double *Xi) {
  for (int n = 1; n <= nmax; ++n)
    for (int m = 1; m <= n; ++m) {
      const double s = (m & 1) ? -1.0 : 1.0;
      const int ip = idx(n, m) * W, in = idx(n, -m) * W;
      for (int v = 0; v < W; ++v) {
        Xr[in + v] = s * Xr[ip + v];
        Xi[in + v] = -s * Xi[ip + v];
      }
    }
}

// One row n of the M2L double sum (doc/theory.md, eq. (3.11), without the sign (-1)^n) for
// kLanes interactions at once, lane-major:
//   A_n^m += sum_{k <= p-n, |l| <= k} M_k^l T_{n+k}^{m+l},  m = 0..n.
// NF >= 0: the row n = NF is known at compile time, so the n+1 outputs of all lanes stay in
// registers while (k, l) run over the sources; NF < 0: any row n <= kMaxOrder (high orders).
template <int NF>
GCSIMD_ALWAYS_INLINE void m2l_row(int n, int p, const double *__restrict Mr, const double *__restrict Mi, const double *__restrict Tr,
             const double *__restrict Ti, double *__restrict Ar, double *__restrict Ai) {
  constexpr int W = kLanes;
  constexpr int kRows = NF >= 0 ? NF + 1 : kMaxOrder + 1;
  const int N = NF >= 0 ? NF : n;
  double accr[kRows][W], acci[kRows][W];
  for (int m = 0; m <= N; ++m)
    for (int v = 0; v < W; ++v) {
      accr[m][v] = Ar[idx(N, m) * W + v];
      acci[m][v] = Ai[idx(N, m) * W + v];
    }
  for (int k = 0; k <= p - N; ++k)
    for (int l = -k; l <= k; ++l) {
      const double *__restrict mr = Mr + idx(k, l) * W, *__restrict mi = Mi + idx(k, l) * W;
      const double *__restrict tr = Tr + idx(N + k, l) * W, *__restrict ti = Ti + idx(N + k, l) * W;
      for (int m = 0; m <= N; ++m)
#pragma omp simd
        for (int v = 0; v < W; ++v) {
          accr[m][v] += mr[v] * tr[m * W + v] - mi[v] * ti[m * W + v];
          acci[m][v] += mr[v] * ti[m * W + v] + mi[v] * tr[m * W + v];
        }
    }
  for (int m = 0; m <= N; ++m)
    for (int v = 0; v < W; ++v) {
      Ar[idx(N, m) * W + v] = accr[m][v];
      Ai[idx(N, m) * W + v] = acci[m][v];
    }
}

// all rows n = N..p: compile-time rows up to kMaxFixedRow, the runtime row beyond
template <int N>
GCSIMD_ALWAYS_INLINE void m2l_rows(int p, const double *Mr, const double *Mi, const double *Tr, const double *Ti, double *Ar,
                     double *Ai) {
  if (N > p) return;
  m2l_row<N>(N, p, Mr, Mi, Tr, Ti, Ar, Ai);
  if constexpr (N < kMaxFixedRow)
    m2l_rows<N + 1>(p, Mr, Mi, Tr, Ti, Ar, Ai);
  else
    for (int n = N + 1; n <= p; ++n) m2l_row<-1>(n, p, Mr, Mi, Tr, Ti, Ar, Ai);
}

// coordinates of the points [j0, j0 + kLanes) relative to c, and the number of lanes in use;
// lanes past np get the point 0 (harmless for regular harmonics)
GCSIMD_ALWAYS_INLINE int gather_lanes(std::size_t j0, std::size_t np, const double *x, const double *y, const double *z,
                        const Vec3 &c, double *dx, double *dy, double *dz) {
  const int nl = static_cast<int>(std::min<std::size_t>(kLanes, np - j0));
  for (int v = 0; v < kLanes; ++v) {
    const bool in = v < nl;
    dx[v] = in ? x[j0 + v] - c.x : 0.0;
    dy[v] = in ? y[j0 + v] - c.y : 0.0;
    dz[v] = in ? z[j0 + v] - c.z : 0.0;
  }
  return nl;
}

using detail::LaneState;

GCSIMD_ALWAYS_INLINE void p2m_batch_body(const LaneState &st, std::size_t np, const double *x, const double *y, const double *z, const double *q,
                          const Vec3 &c, double *M) {
  constexpr int W = kLanes;
  const int p = st.p, S = st.S;
  double *Yr = st.harm, *Yi = st.harm + S * W;
  double *__restrict Ar = st.acc, *__restrict Ai = st.acc + S * W;
  std::fill(st.acc, st.acc + 2 * S * kLanes, 0.0);
  for (std::size_t j0 = 0; j0 < np; j0 += W) {
    double dx[W], dy[W], dz[W], qq[W];
    const int nl = gather_lanes(j0, np, x, y, z, c, dx, dy, dz);
    for (int v = 0; v < W; ++v) qq[v] = v < nl ? q[j0 + v] : 0.0;
    solid_harmonics<Kind::Regular, W>(p, p, st.inv_nm, dx, dy, dz, Yr, Yi);
    // eq. (3.9): M_n^m += q conj(Y_n^m)
    for (int n = 0; n <= p; ++n)
      for (int m = 0; m <= n; ++m) {
        const int i = idx(n, m) * W;
#pragma omp simd
        for (int v = 0; v < W; ++v) {
          Ar[i + v] += qq[v] * Yr[i + v];
          Ai[i + v] -= qq[v] * Yi[i + v];
        }
      }
  }
  for (int n = 0; n <= p; ++n)
    for (int m = 0; m <= n; ++m) {
      double sr = 0.0, si = 0.0;
      for (int v = 0; v < W; ++v) {
        sr += Ar[idx(n, m) * W + v];
        si += Ai[idx(n, m) * W + v];
      }
      M[idx(n, m)] += sr;
      M[S + idx(n, m)] += si;
    }
}

GCSIMD_ALWAYS_INLINE void l2p_batch_body(const LaneState &st, const double *L, const Vec3 &c, std::size_t np, const double *x, const double *y,
                          const double *z, double *pot, double *ex, double *ey, double *ez) {
  constexpr int W = kLanes;
  const int p = st.p, S = st.S;
  double *Yr = st.harm, *Yi = st.harm + S * W;
  const double *lr = L, *li = L + S;
  for (std::size_t j0 = 0; j0 < np; j0 += W) {
    double dx[W], dy[W], dz[W];
    const int nl = gather_lanes(j0, np, x, y, z, c, dx, dy, dz);
    solid_harmonics<Kind::Regular, W>(p, p, st.inv_nm, dx, dy, dz, Yr, Yi);
    double ph[W], a0[W], a1r[W], a1i[W];
    for (int v = 0; v < W; ++v) ph[v] = a0[v] = a1r[v] = a1i[v] = 0.0;
    // eq. (3.13): phi = sum_{n,m} L_n^m conj(Y_n^m) = sum_n [L_n^0 Y_n^0 + 2 sum_{m>0} Re(L_n^m conj(Y_n^m))]
    for (int n = 0; n <= p; ++n)
      for (int m = 0; m <= n; ++m) {
        const double w = m == 0 ? 1.0 : 2.0;
        const double Lr = w * lr[idx(n, m)], Li = w * li[idx(n, m)];
        const int i = idx(n, m) * W;
#pragma omp simd
        for (int v = 0; v < W; ++v) ph[v] += Lr * Yr[i + v] + Li * Yi[i + v];
      }
    // eq. (3.13): degree-1 coefficients re-centred at the point (L2L, eq. (3.12), to degree 1):
    // L'_1^m = sum_{k<=p-1,l} L_{1+k}^{m+l} conj(Y_k^l) for m = 0, 1; negative l from eq. (3.4)
    for (int k = 0; k <= p - 1; ++k)
      for (int l = -k; l <= k; ++l) {
        const int al = l < 0 ? -l : l;
        const double sg = (l < 0 && (al & 1)) ? -1.0 : 1.0;
        const int i = idx(k, al) * W;
        const double sr = sg, si = l < 0 ? -sg : sg;  // Y_k^l = (sr Re, si Im) of Y_k^|l|
        const double A0r = lr[idx(1 + k, l)], A0i = li[idx(1 + k, l)];
        const double A1r = lr[idx(1 + k, 1 + l)], A1i = li[idx(1 + k, 1 + l)];
#pragma omp simd
        for (int v = 0; v < W; ++v) {
          const double yr = sr * Yr[i + v], yi = si * Yi[i + v];
          a0[v] += A0r * yr + A0i * yi;
          a1r[v] += A1r * yr + A1i * yi;
          a1i[v] += A1i * yr - A1r * yi;
        }
      }
    // phi = phi0 + a0 dz - Re(L'_1^1) dx - Im(L'_1^1) dy + ...,  E = -grad phi
    for (int v = 0; v < nl; ++v) {
      pot[j0 + v] += ph[v];
      ex[j0 + v] += a1r[v];
      ey[j0 + v] += a1i[v];
      ez[j0 + v] -= a0[v];
    }
  }
}

GCSIMD_ALWAYS_INLINE void m2l_batch_body(const LaneState &st, std::size_t count, const double *const *Ms, const Vec3 *R, double *Lt) {
  constexpr int W = kLanes;
  const int p = st.p, S = st.S;
  double *__restrict Tr = st.harm, *__restrict Ti = st.harm + S * W;
  double *__restrict Mr = st.mult, *__restrict Mi = st.mult + S * W;
  double *__restrict Ar = st.acc, *__restrict Ai = st.acc + S * W;
  std::fill(st.acc, st.acc + 2 * S * kLanes, 0.0);
  for (std::size_t e0 = 0; e0 < count; e0 += W) {
    const int nl = static_cast<int>(std::min<std::size_t>(W, count - e0));
    // gather the multipoles (lane v = entry e0 + v; empty lanes get M = 0 and R = e_x)
    double x[W], y[W], z[W];
    for (int v = 0; v < W; ++v) {
      if (v < nl) {
        const double *m = Ms[e0 + v];
        for (int i = 0; i < S; ++i) {
          Mr[i * W + v] = m[i];
          Mi[i * W + v] = m[S + i];
        }
        x[v] = R[e0 + v].x;
        y[v] = R[e0 + v].y;
        z[v] = R[e0 + v].z;
      } else {
        for (int i = 0; i < S; ++i) Mr[i * W + v] = Mi[i * W + v] = 0.0;
        x[v] = 1.0;
        y[v] = z[v] = 0.0;
      }
    }
    solid_harmonics<Kind::Irregular, W>(p, p, st.nm1, x, y, z, Tr, Ti);
    fill_negative_m<W>(p, Tr, Ti);
    m2l_rows<0>(p, Mr, Mi, Tr, Ti, Ar, Ai);
  }
  // lane sums in a fixed order, and the sign (-1)^n of eq. (3.11)
  double *lr = Lt, *li = Lt + S;
  for (int n = 0; n <= p; ++n) {
    const double sgn = (n & 1) ? -1.0 : 1.0;
    for (int m = 0; m <= n; ++m) {
      double sr = 0.0, si = 0.0;
      for (int v = 0; v < W; ++v) {
        sr += Ar[idx(n, m) * W + v];
        si += Ai[idx(n, m) * W + v];
      }
      lr[idx(n, m)] += sgn * sr;
      li[idx(n, m)] += sgn * si;
    }
  }
}

GCSIMD_ALWAYS_INLINE void m2p_batch_body(const LaneState &st, const double *M, const Vec3 &c, std::size_t np,
                                       const double *x, const double *y, const double *z, double *pot, double *ex,
                                       double *ey, double *ez) {
  constexpr int W = kLanes;
  const int p = st.p, S = st.S;
  double *Tr = st.harm, *Ti = st.harm + S * W;
  const double *mr = M, *mi = M + S;
  for (std::size_t j0 = 0; j0 < np; j0 += W) {
    double dx[W], dy[W], dz[W];
    const int nl = gather_lanes(j0, np, x, y, z, c, dx, dy, dz);
    for (int v = nl; v < W; ++v) dx[v] = 1.0;  // unused lanes: any point away from 0 (T is singular there)
    solid_harmonics<Kind::Irregular, W>(p, p, st.nm1, dx, dy, dz, Tr, Ti);
    fill_negative_m<W>(p, Tr, Ti);
    // eq. (3.11) for n = 0 and n = 1 about the point: L_0^0 = sum_{k<=p,l} M_k^l T_k^l (= phi,
    // eq. (3.8)), L_1^m = -sum_{k<=p-1,l} M_k^l T_{1+k}^{m+l}, m = 0, 1
    double ph[W], l10[W], l11r[W], l11i[W];
    for (int v = 0; v < W; ++v) ph[v] = l10[v] = l11r[v] = l11i[v] = 0.0;
    for (int k = 0; k <= p; ++k)
      for (int l = -k; l <= k; ++l) {
        const double Mr = mr[idx(k, l)], Mi = mi[idx(k, l)];
        const int i0 = idx(k, l) * W;
#pragma omp simd
        for (int v = 0; v < W; ++v) ph[v] += Mr * Tr[i0 + v] - Mi * Ti[i0 + v];
        if (k == p) continue;
        const int i1 = idx(k + 1, l) * W, i2 = idx(k + 1, l + 1) * W;
#pragma omp simd
        for (int v = 0; v < W; ++v) {
          l10[v] += Mr * Tr[i1 + v] - Mi * Ti[i1 + v];
          l11r[v] += Mr * Tr[i2 + v] - Mi * Ti[i2 + v];
          l11i[v] += Mr * Ti[i2 + v] + Mi * Tr[i2 + v];
        }
      }
    // eq. (3.13) at r = 0 with L_1 = -(the sums): E = (Re L_1^1, Im L_1^1, -L_1^0)
    for (int v = 0; v < nl; ++v) {
      pot[j0 + v] += ph[v];
      ex[j0 + v] -= l11r[v];
      ey[j0 + v] -= l11i[v];
      ez[j0 + v] += l10[v];
    }
  }
}

// each batched operator compiled for every instruction-set path (gcsimd/simd_paths.hpp)
GCSIMD_DEFINE_PATHS(void, m2p_batch_path,
                        (const LaneState &st, const double *M, const Vec3 &c, std::size_t np, const double *x,
                         const double *y, const double *z, double *pot, double *ex, double *ey, double *ez),
                        m2p_batch_body, (st, M, c, np, x, y, z, pot, ex, ey, ez))
GCSIMD_DEFINE_PATHS(void, p2m_batch_path,
                        (const LaneState &st, std::size_t np, const double *x, const double *y, const double *z,
                         const double *q, const Vec3 &c, double *M),
                        p2m_batch_body, (st, np, x, y, z, q, c, M))
GCSIMD_DEFINE_PATHS(void, l2p_batch_path,
                        (const LaneState &st, const double *L, const Vec3 &c, std::size_t np, const double *x,
                         const double *y, const double *z, double *pot, double *ex, double *ey, double *ez),
                        l2p_batch_body, (st, L, c, np, x, y, z, pot, ex, ey, ez))
GCSIMD_DEFINE_PATHS(void, m2l_batch_path,
                        (const LaneState &st, std::size_t count, const double *const *Ms, const Vec3 *R,
                         double *Lt),
                        m2l_batch_body, (st, count, Ms, R, Lt))

}  // namespace

Operators::Operators(int order, gcsimd::SimdPath path) : p_(order), S_((order + 1) * (order + 1)), path_(path) {
  if (order < 1) throw std::invalid_argument("gcfmm: expansion order must be >= 1");
  if (!gcsimd::simd_path_available(path))
    throw std::invalid_argument(std::string("gcfmm: SIMD path ") + gcsimd::simd_path_name(path) + " not available");
  if (order > kMaxOrder)
    throw std::invalid_argument("gcfmm: expansion order must be <= " + std::to_string(kMaxOrder));
  inv_nm_.assign(static_cast<std::size_t>((p_ + 1) * (p_ + 1)), 0.0);
  nm1_.assign(static_cast<std::size_t>((p_ + 1) * (p_ + 1)), 0.0);
  for (int n = 0; n <= p_; ++n)
    for (int m = 0; m <= n; ++m) {
      if (m < n) inv_nm_[n * (p_ + 1) + m] = 1.0 / (double(n + m) * double(n - m));
      nm1_[n * (p_ + 1) + m] = double(n - 1 + m) * double(n - 1 - m);
    }
  harm_re_.assign(S_, 0.0);
  harm_im_.assign(S_, 0.0);
  lane_harm_.assign(2 * static_cast<std::size_t>(S_) * kBatch, 0.0);
  lane_mult_.assign(2 * static_cast<std::size_t>(S_) * kBatch, 0.0);
  lane_acc_.assign(2 * static_cast<std::size_t>(S_) * kBatch, 0.0);
}

// the lane state of this instance, for the batched operators of the chosen path
LaneState Operators::lanes() {
  return LaneState{p_, S_, inv_nm_.data(), nm1_.data(), lane_harm_.data(), lane_mult_.data(), lane_acc_.data()};
}

void Operators::regular(const Vec3 &r, int nmax, double *re, double *im) const {
  solid_harmonics<Kind::Regular, 1>(nmax, p_, inv_nm_.data(), &r.x, &r.y, &r.z, re, im);
  fill_negative_m<1>(nmax, re, im);
}

void Operators::irregular(const Vec3 &r, int nmax, double *re, double *im) const {
  solid_harmonics<Kind::Irregular, 1>(nmax, p_, nm1_.data(), &r.x, &r.y, &r.z, re, im);
  fill_negative_m<1>(nmax, re, im);
}

void Operators::symmetrize(double *a) const {
  double *re = a, *im = a + S_;
  for (int n = 0; n <= p_; ++n) im[idx(n, 0)] = 0.0;  // exact for real charges; removes round-off
  fill_negative_m<1>(p_, re, im);
}

void Operators::p2m(std::size_t np, const double *x, const double *y, const double *z, const double *q,
                    const Vec3 &c, double *M) {
  p2m_batch(np, x, y, z, q, c, M);
}

void Operators::m2p_batch(const double *M, const Vec3 &c, std::size_t np, const double *x, const double *y,
                          const double *z, double *pot, double *ex, double *ey, double *ez) {
  m2p_batch_path_for(path_)(lanes(), M, c, np, x, y, z, pot, ex, ey, ez);
}

void Operators::p2m_batch(std::size_t np, const double *x, const double *y, const double *z, const double *q,
                          const Vec3 &c, double *M) {
  p2m_batch_path_for(path_)(lanes(), np, x, y, z, q, c, M);
}

void Operators::l2p(const double *L, const Vec3 &r, double &pot, double &ex, double &ey, double &ez) {
  l2p_batch(L, Vec3{}, 1, &r.x, &r.y, &r.z, &pot, &ex, &ey, &ez);
}

void Operators::l2p_batch(const double *L, const Vec3 &c, std::size_t np, const double *x, const double *y,
                          const double *z, double *pot, double *ex, double *ey, double *ez) {
  l2p_batch_path_for(path_)(lanes(), L, c, np, x, y, z, pot, ex, ey, ez);
}

void Operators::m2m(const double *Mc, const Vec3 &d, double *Mp) {
  double *yr = harm_re_.data(), *yi = harm_im_.data();
  regular(d, p_, yr, yi);
  const double *cr = Mc, *ci = Mc + S_;
  double *pr = Mp, *pi = Mp + S_;
  // eq. (3.10): M'_n^m = sum_{k<=n,l} conj(Y_k^l(d)) M_{n-k}^{m-l}
  for (int n = 0; n <= p_; ++n)
    for (int m = 0; m <= n; ++m) {
      double ar = 0.0, ai = 0.0;
      for (int k = 0; k <= n; ++k) {
        const int lo = std::max(-k, m - (n - k)), hi = std::min(k, m + (n - k));
        const int by = idx(k, 0), bm = idx(n - k, m);
        for (int l = lo; l <= hi; ++l) {
          const double Yr = yr[by + l], Yi = yi[by + l], Ar = cr[bm - l], Ai = ci[bm - l];
          ar += Yr * Ar + Yi * Ai;
          ai += Yr * Ai - Yi * Ar;
        }
      }
      pr[idx(n, m)] += ar;
      pi[idx(n, m)] += ai;
    }
}

void Operators::m2l(const double *Ms, const Vec3 &R, double *Lt) { m2l_batch(1, &Ms, &R, Lt); }

void Operators::m2l_batch(std::size_t count, const double *const *Ms, const Vec3 *R, double *Lt) {
  m2l_batch_path_for(path_)(lanes(), count, Ms, R, Lt);
}

void Operators::l2l(const double *Lp, const Vec3 &b, double *Lc) {
  double *yr = harm_re_.data(), *yi = harm_im_.data();
  regular(b, p_, yr, yi);
  const double *pr = Lp, *pi = Lp + S_;
  double *cr = Lc, *ci = Lc + S_;
  const int p = p_;
  // eq. (3.12): L'_n^m = sum_{k<=p-n,l} L_{n+k}^{m+l} conj(Y_k^l(b))
  for (int n = 0; n <= p; ++n)
    for (int m = 0; m <= n; ++m) {
      double ar = 0.0, ai = 0.0;
      for (int k = 0; k <= p - n; ++k) {
        const double *Yr = yr + idx(k, 0), *Yi = yi + idx(k, 0);
        const double *Ar = pr + idx(n + k, m), *Ai = pi + idx(n + k, m);
#pragma omp simd reduction(+ : ar, ai)
        for (int l = -k; l <= k; ++l) {
          ar += Ar[l] * Yr[l] + Ai[l] * Yi[l];
          ai += Ai[l] * Yr[l] - Ar[l] * Yi[l];
        }
      }
      cr[idx(n, m)] += ar;
      ci[idx(n, m)] += ai;
    }
}

}  // namespace gcfmm
