// GRANULAR-CHARGED FMM core library (gcfmm): P2P kernel and direct reference sums.
#include "gcfmm/kernels.hpp"

#include <cmath>
#include <stdexcept>

namespace gcfmm {

void p2p(std::size_t nt, const double *__restrict xt, const double *__restrict yt, const double *__restrict zt,
         std::size_t ns, const double *__restrict xs, const double *__restrict ys, const double *__restrict zs,
         const double *__restrict qs, double sx, double sy, double sz, double *__restrict pot,
         double *__restrict ex, double *__restrict ey, double *__restrict ez) {
  for (std::size_t i = 0; i < nt; ++i) {
    const double xi = xt[i] - sx, yi = yt[i] - sy, zi = zt[i] - sz;
    double p = 0.0, fx = 0.0, fy = 0.0, fz = 0.0;
#pragma omp simd reduction(+ : p, fx, fy, fz)
    for (std::size_t j = 0; j < ns; ++j) {
      const double dx = xi - xs[j], dy = yi - ys[j], dz = zi - zs[j];
      const double r2 = dx * dx + dy * dy + dz * dz;
      const double inv = r2 > 0.0 ? 1.0 / std::sqrt(r2) : 0.0;
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
