// GRANULAR-CHARGED FMM core library (gcfmm).
// The average far field (doc/theory.md, eqs. (4.7)-(4.8)): closed forms of a uniformly
// charged slab and cuboid.
// Conventions: include/gcfmm/average_field.hpp and doc/fmm-far-field.md.
#include "gcfmm/average_field.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace gcfmm {

namespace {

// ln(a + r) with r = sqrt(a^2 + s2), s2 = b^2 + c^2 >= 0, without cancellation for a < 0
inline double log_plus(double a, double r, double s2) {
  if (a >= 0) return std::log(a + r);
  return std::log(s2 / (r - a));
}

// c * ln(a + r), zero when the coefficient vanishes (the log may be singular there)
inline double clog(double c, double a, double r, double s2) { return c == 0.0 ? 0.0 : c * log_plus(a, r, s2); }

// c * atan(num / (den r)), zero when c vanishes (den = 0 goes with c = 0 below)
inline double catan(double c, double num, double den, double r) {
  return c == 0.0 ? 0.0 : c * std::atan(num / (den * r));
}

}  // namespace

void cuboid_field(double x1, double x2, double y1, double y2, double z1, double z2, double tx, double ty,
                  double tz, double *pot, double e[3]) {
  const double us[2] = {x1 - tx, x2 - tx}, vs[2] = {y1 - ty, y2 - ty}, ws[2] = {z1 - tz, z2 - tz};
  double p = 0, fx = 0, fy = 0, fz = 0;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k) {
        // corner sign: + at the upper ends: (-1)^(3 - i - j - k)
        const double sg = ((i + j + k) % 2 == 1) ? 1.0 : -1.0;
        const double u = us[i], v = vs[j], w = ws[k];
        const double u2 = u * u, v2 = v * v, w2 = w * w;
        const double r = std::sqrt(u2 + v2 + w2);
        if (r == 0.0) continue;  // a corner at the target contributes nothing
        if (pot) {
          p += sg * (clog(v * w, u, r, v2 + w2) + clog(w * u, v, r, w2 + u2) + clog(u * v, w, r, u2 + v2) -
                     catan(0.5 * u2, v * w, u, r) - catan(0.5 * v2, w * u, v, r) - catan(0.5 * w2, u * v, w, r));
        }
        if (e) {
          fx += sg * (clog(v, w, r, u2 + v2) + clog(w, v, r, w2 + u2) - catan(u, v * w, u, r));
          fy += sg * (clog(u, w, r, u2 + v2) + clog(w, u, r, v2 + w2) - catan(v, w * u, v, r));
          fz += sg * (clog(u, v, r, w2 + u2) + clog(v, u, r, v2 + w2) - catan(w, u * v, w, r));
        }
      }
  if (pot) *pot = p;
  if (e) {
    e[0] = fx;
    e[1] = fy;
    e[2] = fz;
  }
}

void average_far_field(std::size_t n, const double *x, const double *y, const double *z, const double *q,
                       double x0, double y0, double lx, double ly, int images, double bed_zlo, double bed_zhi,
                       std::size_t begin, std::size_t end, double *pot, double *ex, double *ey, double *ez) {
  if (end > n || begin > end) throw std::invalid_argument("gcfmm::average_far_field: bad target range");
  double qsum = 0;
  for (std::size_t j = 0; j < n; ++j) qsum += q[j];
  average_far_field_of_charge(qsum, x, y, z, x0, y0, lx, ly, images, bed_zlo, bed_zhi, begin, end, pot, ex, ey, ez);
}

void average_far_field_of_charge(double qsum, const double *x, const double *y, const double *z, double x0,
                                 double y0, double lx, double ly, int images, double bed_zlo, double bed_zhi,
                                 std::size_t begin, std::size_t end, double *pot, double *ex, double *ey,
                                 double *ez) {
  if (!(lx > 0) || !(ly > 0)) throw std::invalid_argument("gcfmm::average_far_field: periods must be positive");
  if (images < 0) throw std::invalid_argument("gcfmm::average_far_field: images must be >= 0");
  if (!(bed_zhi > bed_zlo))
    throw std::invalid_argument("gcfmm::average_far_field: need bed_zhi > bed_zlo (the bed height H_p)");
  if (begin > end) throw std::invalid_argument("gcfmm::average_far_field: bad target range");
  if (qsum == 0.0) return;
  const double h = bed_zhi - bed_zlo;
  const double rho = qsum / (lx * ly * h);
  const double bx1 = x0 - images * lx, bx2 = x0 + (images + 1) * lx;
  const double by1 = y0 - images * ly, by2 = y0 + (images + 1) * ly;
  for (std::size_t i = begin; i < end; ++i) {
    const double t = z[i];
    // infinite slab, G convention: pot = -2 pi rho int |t - z'| dz'
    const double c = std::min(std::max(t, bed_zlo), bed_zhi);
    const double esz = 2 * kPi * rho * (2 * c - bed_zlo - bed_zhi);
    double psl;
    if (t >= bed_zhi)
      psl = -2 * kPi * rho * h * (t - 0.5 * (bed_zlo + bed_zhi));
    else if (t <= bed_zlo)
      psl = -2 * kPi * rho * h * (0.5 * (bed_zlo + bed_zhi) - t);
    else
      psl = -kPi * rho * ((t - bed_zlo) * (t - bed_zlo) + (bed_zhi - t) * (bed_zhi - t));
    double pb, eb[3];
    cuboid_field(bx1, bx2, by1, by2, bed_zlo, bed_zhi, x[i], y[i], t, pot ? &pb : nullptr, eb);
    if (pot) pot[i] += psl - rho * pb;
    ex[i] -= rho * eb[0];
    ey[i] -= rho * eb[1];
    ez[i] += esz - rho * eb[2];
  }
}

}  // namespace gcfmm
