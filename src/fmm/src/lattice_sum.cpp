// GRANULAR-CHARGED FMM core library (gcfmm).
// 2D-periodic Green's function (2D Ewald / Fourier forms, doc/theory.md, eqs. (4.2)-(4.4))
// and the far kernel R (eq. (4.5)). Conventions: include/gcfmm/lattice_sum.hpp.
#include "gcfmm/lattice_sum.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "gcfmm/types.hpp"

namespace gcfmm {

namespace {

constexpr double kTwoOverSqrtPi = 1.12837916709551257390;  // 2 / sqrt(pi)
constexpr double kEwaldAlphaL = 4.0;   // alpha * min(lx, ly): erfc(1.5 * 4) = 2e-17 beyond 3x3 cells
constexpr double kEwaldKmax = 13.0;    // |k| <= 13 alpha: erfc(6.5) = 4e-20
constexpr double kFourierDecay = 40.0; // keep terms with |k||dz| <= 40: e^-40 = 4e-18
constexpr double kSwitch = 0.75;       // Fourier form for |dz| >= 0.75 min(lx, ly)

// cos(m theta), sin(m theta) for m = 0 .. mmax by complex multiplication
void trig_table(double theta, int mmax, std::vector<double> &c, std::vector<double> &s) {
  c.resize(mmax + 1);
  s.resize(mmax + 1);
  const double c1 = std::cos(theta), s1 = std::sin(theta);
  c[0] = 1.0;
  s[0] = 0.0;
  for (int m = 1; m <= mmax; ++m) {
    // re-seed every 16 steps to keep the recurrence error at a few ulp
    if (m % 16 == 0) {
      c[m] = std::cos(m * theta);
      s[m] = std::sin(m * theta);
    } else {
      c[m] = c[m - 1] * c1 - s[m - 1] * s1;
      s[m] = s[m - 1] * c1 + c[m - 1] * s1;
    }
  }
}

// Reciprocal-space sum shared by the Fourier and Ewald forms: over k = 2 pi (mx/lx, my/ly) != 0
// with |k| <= kmax, of p(k) cos(k.rho) and its x, y derivatives, and of q(k) cos(k.rho), where
// radial(k, p, q) gives the profile p and its z-derivative term q. The sum runs over the
// quadrant mx, my >= 0: cos(kx x + ky y) summed over the sign choices of (kx, ky) is
// 4 cos(kx x) cos(ky y) (2 if one component is zero).
template <class Radial>
void reciprocal_sum(double dx, double dy, double lx, double ly, double kmax, Radial radial,
                    double &s0, double &sx0, double &sy0, double &sz) {
  const double bx = 2.0 * kPi / lx, by = 2.0 * kPi / ly;
  const int mx = static_cast<int>(kmax / bx), my = static_cast<int>(kmax / by);
  thread_local std::vector<double> cx, sx, cy, sy;
  trig_table(bx * dx, mx, cx, sx);
  trig_table(by * dy, my, cy, sy);
  s0 = sx0 = sy0 = sz = 0.0;
  const double kmax2 = kmax * kmax;
  for (int ix = 0; ix <= mx; ++ix) {
    const double kx = bx * ix;
    const double wx = ix ? 2.0 : 1.0;
    for (int iy = 0; iy <= my; ++iy) {
      if (ix == 0 && iy == 0) continue;
      const double ky = by * iy;
      const double k2 = kx * kx + ky * ky;
      if (k2 > kmax2) break;
      double p, q;
      radial(std::sqrt(k2), p, q);
      const double w = wx * (iy ? 2.0 : 1.0);
      const double cc = cx[ix] * cy[iy];
      s0 += w * cc * p;
      sx0 -= w * kx * sx[ix] * cy[iy] * p;
      sy0 -= w * ky * cx[ix] * sy[iy] * p;
      sz += w * cc * q;
    }
  }
}

inline double reduce(double d, double l) { return d - l * std::nearbyint(d / l); }

void set_out(double *p, double v) {
  if (p) *p = v;
}

void check_periods(double lx, double ly) {
  if (!(lx > 0.0) || !(ly > 0.0) || !std::isfinite(lx) || !std::isfinite(ly))
    throw std::invalid_argument("gcfmm::periodic_green: periods must be positive and finite");
}

}  // namespace

double green_switch_height(double lx, double ly) { return kSwitch * std::min(lx, ly); }

void periodic_green_fourier(double dx, double dy, double dz, double lx, double ly, double *g,
                            double *gx, double *gy, double *gz) {
  check_periods(lx, ly);
  if (!(std::fabs(dz) >= 0.01 * std::min(lx, ly)))
    throw std::invalid_argument(
        "gcfmm::periodic_green_fourier: needs |dz| >= 0.01 min(lx, ly) (use periodic_green)");
  dx = reduce(dx, lx);
  dy = reduce(dy, ly);
  const double az = std::fabs(dz), sg = dz > 0 ? 1.0 : -1.0;
  const double area = lx * ly;
  const double kmax = kFourierDecay / az;
  double sg0, sgx, sgy, sgz;
  reciprocal_sum(dx, dy, lx, ly, kmax,
                 [az](double k, double &p, double &q) {
                   q = std::exp(-k * az);
                   p = q / k;
                 },
                 sg0, sgx, sgy, sgz);
  const double f = 2.0 * kPi / area;
  set_out(g, f * (sg0 - az));
  set_out(gx, f * sgx);
  set_out(gy, f * sgy);
  set_out(gz, -f * sg * (1.0 + sgz));
}

namespace {

// 2D Ewald sum. Real space over the images n in the rectangle [nx0, nx1] x [ny0, ny1]
// (relative to the unreduced d); images with max(|nx|,|ny|) <= excl carry
// erfc(alpha r)/r - 1/r = -erf(alpha r)/r instead (excl < 0: none), which removes the
// near block analytically (finite at r = 0). The rectangle must contain every image with
// r < 1.5 min(lx, ly).
void ewald_sum(double dx, double dy, double dz, double lx, double ly, int nx0, int nx1, int ny0,
               int ny1, int excl, double *g, double *gx, double *gy, double *gz) {
  const double area = lx * ly;
  const double alpha = kEwaldAlphaL / std::min(lx, ly);
  const double a2 = alpha * alpha;
  double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
  for (int nx = nx0; nx <= nx1; ++nx)
    for (int ny = ny0; ny <= ny1; ++ny) {
      const double ux = dx + nx * lx, uy = dy + ny * ly;
      const double r2 = ux * ux + uy * uy + dz * dz;
      const double r = std::sqrt(r2);
      const bool near = std::max(std::abs(nx), std::abs(ny)) <= excl;
      double e, dr;  // value and (1/r) d/dr
      if (!near) {
        e = std::erfc(alpha * r) / r;
        // d/dr [erfc(a r)/r] = -erfc(a r)/r^2 - (2a/sqrt(pi)) exp(-a^2 r^2)/r
        dr = -(e + kTwoOverSqrtPi * alpha * std::exp(-a2 * r2)) / r2;
      } else if (alpha * r > 1e-2) {
        e = -std::erf(alpha * r) / r;
        dr = -(e + kTwoOverSqrtPi * alpha * std::exp(-a2 * r2)) / r2;
      } else {
        // series of -erf(x)/x = -(2/sqrt(pi)) (1 - x^2/3 + x^4/10 - x^6/42), x = alpha r
        const double x2 = a2 * r2;
        e = -kTwoOverSqrtPi * alpha * (1.0 - x2 / 3.0 + x2 * x2 / 10.0 - x2 * x2 * x2 / 42.0);
        dr = -kTwoOverSqrtPi * alpha * a2 * (-2.0 / 3.0 + 0.4 * x2 - x2 * x2 / 7.0);
      }
      s0 += e;
      s1 += dr * ux;
      s2 += dr * uy;
      s3 += dr * dz;
    }
  dx = reduce(dx, lx);
  dy = reduce(dy, ly);
  // reciprocal space, k != 0
  const double az = std::fabs(dz), sg = dz >= 0 ? 1.0 : -1.0;
  const double kmax = kEwaldKmax * alpha;
  double r0, rx, ry, rz;
  reciprocal_sum(dx, dy, lx, ly, kmax,
                 [az, alpha, sg](double k, double &p, double &q) {
                   const double up = k / (2.0 * alpha) + alpha * az, um = k / (2.0 * alpha) - alpha * az;
                   const double ep = std::exp(k * az) * std::erfc(up);
                   const double em = std::exp(-k * az) * std::erfc(um);
                   p = (ep + em) / k;
                   // d/dz of the profile: the Gaussian terms of the two erfc derivatives cancel
                   q = sg * (ep - em);
                 },
                 r0, rx, ry, rz);
  const double pa = kPi / area;
  const double ez = std::erf(alpha * az);
  set_out(g, s0 + pa * r0 - 2.0 * pa * (az * ez + std::exp(-a2 * dz * dz) / (alpha * std::sqrt(kPi))));
  set_out(gx, s1 + pa * rx);
  set_out(gy, s2 + pa * ry);
  set_out(gz, s3 + pa * rz - 2.0 * pa * sg * ez);
}

}  // namespace

void periodic_green_ewald(double dx, double dy, double dz, double lx, double ly, double *g,
                          double *gx, double *gy, double *gz) {
  check_periods(lx, ly);
  ewald_sum(reduce(dx, lx), reduce(dy, ly), dz, lx, ly, -1, 1, -1, 1, -1, g, gx, gy, gz);
}

void periodic_green(double dx, double dy, double dz, double lx, double ly, double *g, double *gx,
                    double *gy, double *gz) {
  if (std::fabs(dz) >= green_switch_height(lx, ly))
    periodic_green_fourier(dx, dy, dz, lx, ly, g, gx, gy, gz);
  else
    periodic_green_ewald(dx, dy, dz, lx, ly, g, gx, gy, gz);
}

void far_kernel(double dx, double dy, double dz, double lx, double ly, int images, double *r,
                double *rx, double *ry, double *rz) {
  if (images < 0) throw std::invalid_argument("gcfmm::far_kernel: images must be >= 0");
  check_periods(lx, ly);
  if (std::fabs(dz) < green_switch_height(lx, ly)) {
    // Ewald with the near block removed inside the real-space sum (smooth at d = 0)
    const int cx = -static_cast<int>(std::nearbyint(dx / lx));
    const int cy = -static_cast<int>(std::nearbyint(dy / ly));
    ewald_sum(dx, dy, dz, lx, ly, std::min(-images, cx - 1), std::max(images, cx + 1),
              std::min(-images, cy - 1), std::max(images, cy + 1), images, r, rx, ry, rz);
    return;
  }
  double g = 0, gx = 0, gy = 0, gz = 0;
  periodic_green_fourier(dx, dy, dz, lx, ly, &g, &gx, &gy, &gz);
  for (int nx = -images; nx <= images; ++nx)
    for (int ny = -images; ny <= images; ++ny) {
      const double ux = dx + nx * lx, uy = dy + ny * ly;
      const double r2 = ux * ux + uy * uy + dz * dz;
      const double ir = 1.0 / std::sqrt(r2);
      const double ir3 = ir * ir * ir;
      g -= ir;
      gx += ux * ir3;  // grad(1/r) = -u / r^3, subtracted
      gy += uy * ir3;
      gz += dz * ir3;
    }
  set_out(r, g);
  set_out(rx, gx);
  set_out(ry, gy);
  set_out(rz, gz);
}

}  // namespace gcfmm
