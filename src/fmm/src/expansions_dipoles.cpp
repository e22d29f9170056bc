// GRANULAR-CHARGED FMM core library (gcfmm): the operators of point dipoles and of the field
// gradient (doc/polarization.md, section 5), single point at a time over the solid harmonics of
// expansions.cpp (doc/theory.md, section 3).
#include "gcfmm/expansions.hpp"

#include <algorithm>

namespace gcfmm {

void Operators::p2m_dipoles(std::size_t np, const double *x, const double *y, const double *z, const double *px,
                            const double *py, const double *pz, const Vec3 &c, double *M) {
  double *yr = harm_re_.data(), *yi = harm_im_.data();
  double *mr = M, *mi = M + S_;
  for (std::size_t j = 0; j < np; ++j) {
    regular(Vec3{x[j] - c.x, y[j] - c.y, z[j] - c.z}, p_ - 1, yr, yi);
    // Y_1^l(p): l = -1, 0, 1 (eq. (3.2), (3.4))
    const double y1r[3] = {0.5 * px[j], pz[j], -0.5 * px[j]};
    const double y1i[3] = {-0.5 * py[j], 0.0, -0.5 * py[j]};
    // eq. (5.1): M_n^m += conj(sum_l Y_{n-1}^{m-l}(d) Y_1^l(p))
    for (int n = 1; n <= p_; ++n)
      for (int m = 0; m <= n; ++m) {
        double ar = 0.0, ai = 0.0;
        for (int l = -1; l <= 1; ++l) {
          const int k = m - l;
          if (k < -(n - 1) || k > n - 1) continue;
          const double Ar = yr[index(n - 1, k)], Ai = yi[index(n - 1, k)];
          ar += Ar * y1r[l + 1] - Ai * y1i[l + 1];
          ai += Ar * y1i[l + 1] + Ai * y1r[l + 1];
        }
        mr[index(n, m)] += ar;
        mi[index(n, m)] -= ai;
      }
  }
}

void Operators::l2p_gradient(const double *L, const Vec3 &r, double &pot, double &ex, double &ey, double &ez,
                             double *g6) {
  double *yr = harm_re_.data(), *yi = harm_im_.data();
  regular(r, p_, yr, yi);
  const double *pr = L, *pi = L + S_;
  // eq. (3.12) for n <= 2 only: L'_n^m = sum_{k<=p-n,l} L_{n+k}^{m+l} conj(Y_k^l(r))
  double cr[9] = {}, ci[9] = {};
  for (int n = 0; n <= std::min(2, p_); ++n)
    for (int m = 0; m <= n; ++m) {
      double ar = 0.0, ai = 0.0;
      for (int k = 0; k <= p_ - n; ++k)
        for (int l = -k; l <= k; ++l) {
          if (m + l < -(n + k) || m + l > n + k) continue;
          const double Ar = pr[index(n + k, m + l)], Ai = pi[index(n + k, m + l)];
          const double Yr = yr[index(k, l)], Yi = yi[index(k, l)];
          ar += Ar * Yr + Ai * Yi;
          ai += Ai * Yr - Ar * Yi;
        }
      cr[index(n, m)] = ar;
      ci[index(n, m)] = ai;
    }
  pot += cr[index(0, 0)];
  ex += cr[index(1, 1)];
  ey += ci[index(1, 1)];
  ez -= cr[index(1, 0)];
  if (p_ < 2) return;
  // eq. (5.2): Hessian H of phi from the degree-2 terms, G = -H
  const double l20 = cr[index(2, 0)], a1 = cr[index(2, 1)], b1 = ci[index(2, 1)], a2 = cr[index(2, 2)],
               b2 = ci[index(2, 2)];
  g6[0] -= -0.5 * l20 + 0.5 * a2;  // xx
  g6[1] -= 0.5 * b2;               // xy
  g6[2] -= -a1;                    // xz
  g6[3] -= -0.5 * l20 - 0.5 * a2;  // yy
  g6[4] -= -b1;                    // yz
  g6[5] -= l20;                    // zz
}

double Operators::m2p_potential(const double *M, const Vec3 &r) {
  double *tr = harm_re_.data(), *ti = harm_im_.data();
  irregular(r, p_, tr, ti);
  // eq. (3.8): phi = sum_{n,m} M_n^m T_n^m (real part)
  double s = 0.0;
  for (int i = 0; i < S_; ++i) s += M[i] * tr[i] - M[S_ + i] * ti[i];
  return s;
}

}  // namespace gcfmm
