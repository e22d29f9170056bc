// GRANULAR-CHARGED FMM core library (gcfmm): solid-harmonic expansions and translations.
// Formulas and layout: see include/gcfmm/expansions.hpp and src/fmm/README.md.
#include "gcfmm/expansions.hpp"

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

void Operators::m2l(const double *Ms, const Vec3 &R, double *Lt) const {
  double *tr = wr_.data(), *ti = wi_.data();
  irregular(R, p_, tr, ti);
  const double *mr = Ms, *mi = Ms + S_;
  double *lr = Lt, *li = Lt + S_;
  const int p = p_;
  for (int n = 0; n <= p; ++n) {
    const double sgn = (n & 1) ? -1.0 : 1.0;
    for (int m = 0; m <= n; ++m) {
      double ar = 0.0, ai = 0.0;
      for (int k = 0; k <= p - n; ++k) {
        const double *Mr = mr + idx(k, 0), *Mi = mi + idx(k, 0);
        const double *Tr = tr + idx(n + k, m), *Ti = ti + idx(n + k, m);
#pragma omp simd reduction(+ : ar, ai)
        for (int l = -k; l <= k; ++l) {
          ar += Mr[l] * Tr[l] - Mi[l] * Ti[l];
          ai += Mr[l] * Ti[l] + Mi[l] * Tr[l];
        }
      }
      lr[idx(n, m)] += sgn * ar;
      li[idx(n, m)] += sgn * ai;
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
