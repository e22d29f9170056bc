// GRANULAR-CHARGED FMM core library (gcfmm): solid-harmonic expansions and translations.
// Formulas and layout: see include/gcfmm/expansions.hpp and src/fmm/README.md.
#include "gcfmm/expansions.hpp"

#include "gcfmm/options.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace gcfmm {

namespace {
inline int idx(int n, int m) { return n * n + n + m; }
}  // namespace

Operators::Operators(int order) : p_(order), S_((order + 1) * (order + 1)) {
  if (order < 1) throw std::invalid_argument("gcfmm: expansion order must be >= 1");
  inv_nm_.assign(static_cast<std::size_t>((p_ + 1) * (p_ + 1)), 0.0);
  nm1_.assign(static_cast<std::size_t>((p_ + 1) * (p_ + 1)), 0.0);
  for (int n = 0; n <= p_; ++n)
    for (int m = 0; m <= n; ++m) {
      if (m < n) inv_nm_[n * (p_ + 1) + m] = 1.0 / (double(n + m) * double(n - m));
      nm1_[n * (p_ + 1) + m] = double(n - 1 + m) * double(n - 1 - m);
    }
  wr_.assign(S_, 0.0);
  wi_.assign(S_, 0.0);
  xr_.assign(S_, 0.0);
  xi_.assign(S_, 0.0);
  bt_.assign(2 * static_cast<std::size_t>(S_) * kBatch, 0.0);
  bm_.assign(2 * static_cast<std::size_t>(S_) * kBatch, 0.0);
  ba_.assign(2 * static_cast<std::size_t>(S_) * kBatch, 0.0);
}

void Operators::regular(const Vec3 &r, int nmax, double *re, double *im) const {
  const double x = r.x, y = r.y, z = r.z, r2 = x * x + y * y + z * z;
  re[0] = 1.0;
  im[0] = 0.0;
  for (int n = 1; n <= nmax; ++n) {
    // Y_n^n = -(x+iy)/(2n) Y_{n-1}^{n-1}
    const double c = -x / (2.0 * n), d = -y / (2.0 * n);
    const double a = re[idx(n - 1, n - 1)], b = im[idx(n - 1, n - 1)];
    re[idx(n, n)] = c * a - d * b;
    im[idx(n, n)] = c * b + d * a;
    const double f = (2.0 * n - 1.0) * z;
    for (int m = 0; m < n; ++m) {
      double vr = f * re[idx(n - 1, m)], vi = f * im[idx(n - 1, m)];
      if (m <= n - 2) {
        vr -= r2 * re[idx(n - 2, m)];
        vi -= r2 * im[idx(n - 2, m)];
      }
      const double s = inv_nm_[n * (p_ + 1) + m];
      re[idx(n, m)] = vr * s;
      im[idx(n, m)] = vi * s;
    }
  }
  for (int n = 1; n <= nmax; ++n)
    for (int m = 1; m <= n; ++m) {
      const double s = (m & 1) ? -1.0 : 1.0;
      re[idx(n, -m)] = s * re[idx(n, m)];
      im[idx(n, -m)] = -s * im[idx(n, m)];
    }
}

void Operators::irregular(const Vec3 &r, int nmax, double *re, double *im) const {
  const double x = r.x, y = r.y, z = r.z, r2 = x * x + y * y + z * z;
  const double ir2 = 1.0 / r2;
  re[0] = std::sqrt(ir2);
  im[0] = 0.0;
  for (int n = 1; n <= nmax; ++n) {
    // T_n^n = -(2n-1)(x+iy)/r^2 T_{n-1}^{n-1}
    const double c = -(2.0 * n - 1.0) * x * ir2, d = -(2.0 * n - 1.0) * y * ir2;
    const double a = re[idx(n - 1, n - 1)], b = im[idx(n - 1, n - 1)];
    re[idx(n, n)] = c * a - d * b;
    im[idx(n, n)] = c * b + d * a;
    const double f = (2.0 * n - 1.0) * z;
    for (int m = 0; m < n; ++m) {
      double vr = f * re[idx(n - 1, m)], vi = f * im[idx(n - 1, m)];
      if (m <= n - 2) {
        const double g = nm1_[n * (p_ + 1) + m];
        vr -= g * re[idx(n - 2, m)];
        vi -= g * im[idx(n - 2, m)];
      }
      re[idx(n, m)] = vr * ir2;
      im[idx(n, m)] = vi * ir2;
    }
  }
  for (int n = 1; n <= nmax; ++n)
    for (int m = 1; m <= n; ++m) {
      const double s = (m & 1) ? -1.0 : 1.0;
      re[idx(n, -m)] = s * re[idx(n, m)];
      im[idx(n, -m)] = -s * im[idx(n, m)];
    }
}

void Operators::symmetrize(double *a) const {
  double *re = a, *im = a + S_;
  for (int n = 0; n <= p_; ++n) {
    im[idx(n, 0)] = 0.0;  // exact for real charges; removes round-off
    for (int m = 1; m <= n; ++m) {
      const double s = (m & 1) ? -1.0 : 1.0;
      re[idx(n, -m)] = s * re[idx(n, m)];
      im[idx(n, -m)] = -s * im[idx(n, m)];
    }
  }
}

void Operators::p2m(std::size_t np, const double *x, const double *y, const double *z, const double *q,
                    const Vec3 &c, double *M) const {
  double *Mr = M, *Mi = M + S_;
  double *yr = wr_.data(), *yi = wi_.data();
  const int p = p_;
  for (std::size_t j = 0; j < np; ++j) {
    const double qj = q[j];
    if (qj == 0.0) continue;
    const double dx = x[j] - c.x, dy = y[j] - c.y, dz = z[j] - c.z, r2 = dx * dx + dy * dy + dz * dz;
    // m >= 0 part of the regular harmonics (same recurrence as regular())
    yr[0] = 1.0;
    yi[0] = 0.0;
    for (int n = 1; n <= p; ++n) {
      const double cc = -dx / (2.0 * n), dd = -dy / (2.0 * n);
      const double a = yr[idx(n - 1, n - 1)], b = yi[idx(n - 1, n - 1)];
      yr[idx(n, n)] = cc * a - dd * b;
      yi[idx(n, n)] = cc * b + dd * a;
      const double f = (2.0 * n - 1.0) * dz;
      for (int m = 0; m < n; ++m) {
        double vr = f * yr[idx(n - 1, m)], vi = f * yi[idx(n - 1, m)];
        if (m <= n - 2) {
          vr -= r2 * yr[idx(n - 2, m)];
          vi -= r2 * yi[idx(n - 2, m)];
        }
        const double s = inv_nm_[n * (p + 1) + m];
        yr[idx(n, m)] = vr * s;
        yi[idx(n, m)] = vi * s;
      }
    }
    for (int n = 0; n <= p; ++n)
      for (int m = 0; m <= n; ++m) {
        Mr[idx(n, m)] += qj * yr[idx(n, m)];
        Mi[idx(n, m)] -= qj * yi[idx(n, m)];
      }
  }
}

namespace {

constexpr int kMaxFixedOrder = 16;
constexpr int kLanes = Operators::kBatch;

// One row n of the batched M2L sum with n known at compile time: the n+1 outputs (m = 0..n)
// of all lanes stay in registers while (k, l) run over the sources.
template <int N>
inline void m2l_row(int p, const double *__restrict Mr, const double *__restrict Mi, const double *__restrict Tr,
                    const double *__restrict Ti, double *__restrict Ar, double *__restrict Ai) {
  constexpr int W = kLanes;
  double accr[N + 1][W], acci[N + 1][W];
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

template <int N>
inline void m2l_rows_from(int p, const double *Mr, const double *Mi, const double *Tr, const double *Ti, double *Ar,
                          double *Ai) {
  if (N > p) return;
  m2l_row<N>(p, Mr, Mi, Tr, Ti, Ar, Ai);
  if constexpr (N < kMaxFixedOrder) m2l_rows_from<N + 1>(p, Mr, Mi, Tr, Ti, Ar, Ai);
}

inline void m2l_rows(int p, const double *Mr, const double *Mi, const double *Tr, const double *Ti, double *Ar,
                     double *Ai) {
  m2l_rows_from<0>(p, Mr, Mi, Tr, Ti, Ar, Ai);
}

}  // namespace

namespace {
// regular harmonics (m >= 0 only) of kLanes points at once, lane-major layout [idx][lane]
inline void regular_lanes(int p, const double *inv_nm, const double *x, const double *y, const double *z,
                          double *__restrict Yr, double *__restrict Yi) {
  constexpr int W = kLanes;
  double r2[W];
  for (int v = 0; v < W; ++v) {
    r2[v] = x[v] * x[v] + y[v] * y[v] + z[v] * z[v];
    Yr[v] = 1.0;
    Yi[v] = 0.0;
  }
  for (int n = 1; n <= p; ++n) {
    const double h = -1.0 / (2.0 * n), f = 2.0 * n - 1.0;
    const int dn = idx(n, n) * W, dp = idx(n - 1, n - 1) * W;
    for (int v = 0; v < W; ++v) {
      const double c = h * x[v], d = h * y[v], a = Yr[dp + v], b = Yi[dp + v];
      Yr[dn + v] = c * a - d * b;
      Yi[dn + v] = c * b + d * a;
    }
    for (int m = 0; m < n; ++m) {
      const double s = inv_nm[n * (p + 1) + m];
      const int i0 = idx(n, m) * W, i1 = idx(n - 1, m) * W;
      if (m <= n - 2) {
        const int i2 = idx(n - 2, m) * W;
        for (int v = 0; v < W; ++v) {
          Yr[i0 + v] = (f * z[v] * Yr[i1 + v] - r2[v] * Yr[i2 + v]) * s;
          Yi[i0 + v] = (f * z[v] * Yi[i1 + v] - r2[v] * Yi[i2 + v]) * s;
        }
      } else {
        for (int v = 0; v < W; ++v) {
          Yr[i0 + v] = f * z[v] * Yr[i1 + v] * s;
          Yi[i0 + v] = f * z[v] * Yi[i1 + v] * s;
        }
      }
    }
  }
}
}  // namespace

void Operators::p2m_batch(std::size_t np, const double *x, const double *y, const double *z, const double *q,
                          const Vec3 &c, double *M) const {
  constexpr int W = kBatch;
  const int p = p_, S = S_;
  double *Yr = bt_.data(), *Yi = bt_.data() + S * W;
  double *__restrict Ar = ba_.data(), *__restrict Ai = ba_.data() + S * W;
  std::fill(ba_.begin(), ba_.end(), 0.0);
  for (std::size_t j0 = 0; j0 < np; j0 += W) {
    const int nl = static_cast<int>(std::min<std::size_t>(W, np - j0));
    double dx[W], dy[W], dz[W], qq[W];
    for (int v = 0; v < W; ++v) {
      const bool in = v < nl;
      dx[v] = in ? x[j0 + v] - c.x : 0.0;
      dy[v] = in ? y[j0 + v] - c.y : 0.0;
      dz[v] = in ? z[j0 + v] - c.z : 0.0;
      qq[v] = in ? q[j0 + v] : 0.0;
    }
    regular_lanes(p, inv_nm_.data(), dx, dy, dz, Yr, Yi);
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

void Operators::l2p_batch(const double *L, const Vec3 &c, std::size_t np, const double *x, const double *y,
                          const double *z, double *pot, double *ex, double *ey, double *ez) const {
  constexpr int W = kBatch;
  const int p = p_, S = S_;
  double *Yr = bt_.data(), *Yi = bt_.data() + S * W;
  const double *lr = L, *li = L + S;
  for (std::size_t j0 = 0; j0 < np; j0 += W) {
    const int nl = static_cast<int>(std::min<std::size_t>(W, np - j0));
    double dx[W], dy[W], dz[W];
    for (int v = 0; v < W; ++v) {
      const bool in = v < nl;
      dx[v] = in ? x[j0 + v] - c.x : 0.0;
      dy[v] = in ? y[j0 + v] - c.y : 0.0;
      dz[v] = in ? z[j0 + v] - c.z : 0.0;
    }
    regular_lanes(p, inv_nm_.data(), dx, dy, dz, Yr, Yi);
    double ph[W], a0[W], a1r[W], a1i[W];
    for (int v = 0; v < W; ++v) ph[v] = a0[v] = a1r[v] = a1i[v] = 0.0;
    // potential: sum_{n,m} L_n^m conj(Y_n^m) = sum_n [L_n^0 Y_n^0 + 2 sum_{m>0} Re(L_n^m conj(Y_n^m))]
    for (int n = 0; n <= p; ++n)
      for (int m = 0; m <= n; ++m) {
        const double w = m == 0 ? 1.0 : 2.0;
        const double Lr = w * lr[idx(n, m)], Li = w * li[idx(n, m)];
        const int i = idx(n, m) * W;
#pragma omp simd
        for (int v = 0; v < W; ++v) ph[v] += Lr * Yr[i + v] + Li * Yi[i + v];
      }
    // degree-1 coefficients re-centred at the point: L'_1^m = sum_{k<=p-1,l} L_{1+k}^{m+l} conj(Y_k^l)
    // for m = 0, 1; negative l from Y_k^{-l} = (-1)^l conj(Y_k^l)
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
    for (int v = 0; v < nl; ++v) {
      pot[j0 + v] += ph[v];
      ex[j0 + v] += a1r[v];
      ey[j0 + v] += a1i[v];
      ez[j0 + v] -= a0[v];
    }
  }
}

void Operators::m2m(const double *Mc, const Vec3 &d, double *Mp) const {
  double *yr = wr_.data(), *yi = wi_.data();
  regular(d, p_, yr, yi);
  const double *cr = Mc, *ci = Mc + S_;
  double *pr = Mp, *pi = Mp + S_;
  for (int n = 0; n <= p_; ++n)
    for (int m = 0; m <= n; ++m) {
      double ar = 0.0, ai = 0.0;
      for (int k = 0; k <= n; ++k) {
        const int lo = std::max(-k, m - (n - k)), hi = std::min(k, m + (n - k));
        const int by = idx(k, 0), bm = idx(n - k, m);
        for (int l = lo; l <= hi; ++l) {
          // conj(Y_k^l) * M_{n-k}^{m-l}
          const double Yr = yr[by + l], Yi = yi[by + l], Ar = cr[bm - l], Ai = ci[bm - l];
          ar += Yr * Ar + Yi * Ai;
          ai += Yr * Ai - Yi * Ar;
        }
      }
      pr[idx(n, m)] += ar;
      pi[idx(n, m)] += ai;
    }
}

namespace {

// M2L summation with the order P known at compile time, so that every loop has a constant
// trip count and the compiler unrolls and vectorises it (about 3-5x faster than the generic
// loop for p <= 12 on the machines measured). Same arithmetic, in the same order, as
// m2l_sum_generic below.
template <int P>
void m2l_sum_fixed(const double *__restrict mr, const double *__restrict mi, const double *__restrict tr,
                   const double *__restrict ti, double *__restrict lr, double *__restrict li) {
  for (int n = 0; n <= P; ++n) {
    const double sgn = (n & 1) ? -1.0 : 1.0;
    // one accumulator per (k, m): independent dependency chains of length 2k+1 keep the
    // floating-point pipelines busy (a single chain per m is latency bound for small n)
    double Ar[P + 1][P + 1], Ai[P + 1][P + 1];
    for (int k = 0; k <= P - n; ++k) {
      for (int m = 0; m <= n; ++m) Ar[k][m] = Ai[k][m] = 0.0;
      for (int l = -k; l <= k; ++l) {
        const double ar = mr[idx(k, l)], ai = mi[idx(k, l)];
        const double *Tr = tr + idx(n + k, l), *Ti = ti + idx(n + k, l);
        for (int m = 0; m <= n; ++m) {
          Ar[k][m] += ar * Tr[m] - ai * Ti[m];
          Ai[k][m] += ar * Ti[m] + ai * Tr[m];
        }
      }
    }
    for (int m = 0; m <= n; ++m) {
      double sr = 0.0, si = 0.0;
      for (int k = 0; k <= P - n; ++k) {
        sr += Ar[k][m];
        si += Ai[k][m];
      }
      lr[idx(n, m)] += sgn * sr;
      li[idx(n, m)] += sgn * si;
    }
  }
}

void m2l_sum_generic(int p, const double *__restrict mr, const double *__restrict mi, const double *__restrict tr,
                     const double *__restrict ti, double *__restrict lr, double *__restrict li) {
  double Ar[kMaxOrder + 1], Ai[kMaxOrder + 1];
  for (int n = 0; n <= p; ++n) {
    const double sgn = (n & 1) ? -1.0 : 1.0;
    for (int m = 0; m <= n; ++m) Ar[m] = Ai[m] = 0.0;
    for (int k = 0; k <= p - n; ++k) {
      for (int l = -k; l <= k; ++l) {
        const double ar = mr[idx(k, l)], ai = mi[idx(k, l)];
        const double *Tr = tr + idx(n + k, l), *Ti = ti + idx(n + k, l);
        for (int m = 0; m <= n; ++m) {
          Ar[m] += ar * Tr[m] - ai * Ti[m];
          Ai[m] += ar * Ti[m] + ai * Tr[m];
        }
      }
    }
    for (int m = 0; m <= n; ++m) {
      lr[idx(n, m)] += sgn * Ar[m];
      li[idx(n, m)] += sgn * Ai[m];
    }
  }
}

}  // namespace

void Operators::m2l(const double *Ms, const Vec3 &R, double *Lt) const {
  double *tr = wr_.data(), *ti = wi_.data();
  irregular(R, p_, tr, ti);
  const double *mr = Ms, *mi = Ms + S_;
  double *lr = Lt, *li = Lt + S_;
  // L_n^m += (-1)^n sum_{k <= p-n, l} M_k^l T_{n+k}^{m+l}; the innermost loop runs over the
  // target index m = 0..n (contiguous in T), accumulated in registers.
  switch (p_) {
    case 1: m2l_sum_fixed<1>(mr, mi, tr, ti, lr, li); break;
    case 2: m2l_sum_fixed<2>(mr, mi, tr, ti, lr, li); break;
    case 3: m2l_sum_fixed<3>(mr, mi, tr, ti, lr, li); break;
    case 4: m2l_sum_fixed<4>(mr, mi, tr, ti, lr, li); break;
    case 5: m2l_sum_fixed<5>(mr, mi, tr, ti, lr, li); break;
    case 6: m2l_sum_fixed<6>(mr, mi, tr, ti, lr, li); break;
    case 7: m2l_sum_fixed<7>(mr, mi, tr, ti, lr, li); break;
    case 8: m2l_sum_fixed<8>(mr, mi, tr, ti, lr, li); break;
    case 9: m2l_sum_fixed<9>(mr, mi, tr, ti, lr, li); break;
    case 10: m2l_sum_fixed<10>(mr, mi, tr, ti, lr, li); break;
    case 11: m2l_sum_fixed<11>(mr, mi, tr, ti, lr, li); break;
    case 12: m2l_sum_fixed<12>(mr, mi, tr, ti, lr, li); break;
    default: m2l_sum_generic(p_, mr, mi, tr, ti, lr, li); break;
  }
}


void Operators::m2l_batch(std::size_t count, const double *const *Ms, const Vec3 *R, double *Lt) const {
  constexpr int W = kBatch;
  const int p = p_, S = S_;
  double *__restrict Tr = bt_.data(), *__restrict Ti = bt_.data() + S * W;
  double *__restrict Mr = bm_.data(), *__restrict Mi = bm_.data() + S * W;
  double *__restrict Ar = ba_.data(), *__restrict Ai = ba_.data() + S * W;
  std::fill(ba_.begin(), ba_.end(), 0.0);
  for (std::size_t e0 = 0; e0 < count; e0 += W) {
    const int nl = static_cast<int>(std::min<std::size_t>(W, count - e0));
    // gather the multipoles (lane v = entry e0 + v; empty lanes get M = 0) and the vectors
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
    // irregular harmonics of the W vectors, same recurrence as irregular()
    double ir2[W];
    for (int v = 0; v < W; ++v) {
      ir2[v] = 1.0 / (x[v] * x[v] + y[v] * y[v] + z[v] * z[v]);
      Tr[v] = std::sqrt(ir2[v]);
      Ti[v] = 0.0;
    }
    for (int n = 1; n <= p; ++n) {
      const double f = 2.0 * n - 1.0;
      const int dn = idx(n, n) * W, dp = idx(n - 1, n - 1) * W;
      for (int v = 0; v < W; ++v) {
        const double c = -f * x[v] * ir2[v], d = -f * y[v] * ir2[v];
        const double a = Tr[dp + v], b = Ti[dp + v];
        Tr[dn + v] = c * a - d * b;
        Ti[dn + v] = c * b + d * a;
      }
      for (int m = 0; m < n; ++m) {
        const int i0 = idx(n, m) * W, i1 = idx(n - 1, m) * W;
        if (m <= n - 2) {
          const int i2 = idx(n - 2, m) * W;
          const double g = nm1_[n * (p + 1) + m];
          for (int v = 0; v < W; ++v) {
            Tr[i0 + v] = (f * z[v] * Tr[i1 + v] - g * Tr[i2 + v]) * ir2[v];
            Ti[i0 + v] = (f * z[v] * Ti[i1 + v] - g * Ti[i2 + v]) * ir2[v];
          }
        } else {
          for (int v = 0; v < W; ++v) {
            Tr[i0 + v] = f * z[v] * Tr[i1 + v] * ir2[v];
            Ti[i0 + v] = f * z[v] * Ti[i1 + v] * ir2[v];
          }
        }
      }
      for (int m = 1; m <= n; ++m) {
        const double s = (m & 1) ? -1.0 : 1.0;
        const int ip = idx(n, m) * W, in = idx(n, -m) * W;
        for (int v = 0; v < W; ++v) {
          Tr[in + v] = s * Tr[ip + v];
          Ti[in + v] = -s * Ti[ip + v];
        }
      }
    }
    // A_n^m += sum_{k <= p-n, l} M_k^l T_{n+k}^{m+l}, lane by lane
    if (p <= kMaxFixedOrder)
      m2l_rows(p, Mr, Mi, Tr, Ti, Ar, Ai);
    else
      for (int n = 0; n <= p; ++n)
        for (int k = 0; k <= p - n; ++k)
          for (int l = -k; l <= k; ++l) {
            const double *__restrict mr = Mr + idx(k, l) * W, *__restrict mi = Mi + idx(k, l) * W;
            for (int m = 0; m <= n; ++m) {
              const double *__restrict tr = Tr + idx(n + k, m + l) * W, *__restrict ti = Ti + idx(n + k, m + l) * W;
              double *__restrict ar = Ar + idx(n, m) * W, *__restrict ai = Ai + idx(n, m) * W;
#pragma omp simd
              for (int v = 0; v < W; ++v) {
                ar[v] += mr[v] * tr[v] - mi[v] * ti[v];
                ai[v] += mr[v] * ti[v] + mi[v] * tr[v];
              }
            }
          }
  }
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

void Operators::l2l(const double *Lp, const Vec3 &b, double *Lc) const {
  double *yr = wr_.data(), *yi = wi_.data();
  regular(b, p_, yr, yi);
  const double *pr = Lp, *pi = Lp + S_;
  double *cr = Lc, *ci = Lc + S_;
  const int p = p_;
  for (int n = 0; n <= p; ++n)
    for (int m = 0; m <= n; ++m) {
      double ar = 0.0, ai = 0.0;
      for (int k = 0; k <= p - n; ++k) {
        const double *Yr = yr + idx(k, 0), *Yi = yi + idx(k, 0);
        const double *Ar = pr + idx(n + k, m), *Ai = pi + idx(n + k, m);
#pragma omp simd reduction(+ : ar, ai)
        for (int l = -k; l <= k; ++l) {
          // L_{n+k}^{m+l} conj(Y_k^l)
          ar += Ar[l] * Yr[l] + Ai[l] * Yi[l];
          ai += Ai[l] * Yr[l] - Ar[l] * Yi[l];
        }
      }
      cr[idx(n, m)] += ar;
      ci[idx(n, m)] += ai;
    }
}

void Operators::l2p(const double *L, const Vec3 &r, double &pot, double &ex, double &ey, double &ez) const {
  double *yr = wr_.data(), *yi = wi_.data();
  regular(r, p_, yr, yi);
  const double *lr = L, *li = L + S_;
  const int p = p_;
  double ph = 0.0;
  for (int i = 0; i < S_; ++i) ph += lr[i] * yr[i] + li[i] * yi[i];
  // degree-1 coefficients of the local expansion re-centred at r: L'_1^m, m = 0, 1
  double a0 = 0.0, a1r = 0.0, a1i = 0.0;
  for (int k = 0; k <= p - 1; ++k) {
    const double *Yr = yr + idx(k, 0), *Yi = yi + idx(k, 0);
    const double *A0r = lr + idx(1 + k, 0), *A0i = li + idx(1 + k, 0);
    const double *A1r = lr + idx(1 + k, 1), *A1i = li + idx(1 + k, 1);
    for (int l = -k; l <= k; ++l) {
      a0 += A0r[l] * Yr[l] + A0i[l] * Yi[l];
      a1r += A1r[l] * Yr[l] + A1i[l] * Yi[l];
      a1i += A1i[l] * Yr[l] - A1r[l] * Yi[l];
    }
  }
  // phi = phi0 + a0 dz - Re(L'_1^1) dx - Im(L'_1^1) dy + ...,  E = -grad phi
  pot += ph;
  ex += a1r;
  ey += a1i;
  ez -= a0;
}

double Operators::m2p_potential(const double *M, const Vec3 &r) const {
  double *tr = wr_.data(), *ti = wi_.data();
  irregular(r, p_, tr, ti);
  double s = 0.0;
  for (int i = 0; i < S_; ++i) s += M[i] * tr[i] - M[S_ + i] * ti[i];
  return s;
}

}  // namespace gcfmm
