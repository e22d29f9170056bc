// GRANULAR-CHARGED FMM core library (gcfmm).
// Conjugate gradients for the induced dipoles (polarization.hpp; doc/polarization.md, sec. 4).
#include "gcfmm/polarization.hpp"

#include <cmath>
#include <stdexcept>
#include <vector>

namespace gcfmm {

namespace {

double dot(const std::vector<double> &a, const std::vector<double> &b)
{
  double s = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) s += a[k] * b[k];
  return s;
}

}  // namespace

namespace {

// the sign of the nonzero alpha (0 if none); throws on mixed signs or non-finite values
double polarizability_sign(std::size_t n, const double *alpha)
{
  // A = sign (alpha^-1 - T) is symmetric positive definite when every alpha has the sign
  // `sign` and the packing is below the polarization catastrophe (2 |alpha| / d^3 < 1 for a
  // pair, which spheres of beta < 1 satisfy at contact: 2 beta a^3 / (2 a)^3 <= 1/4).
  double sign = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(alpha[i]))
      throw std::invalid_argument("gcfmm: polarizability of particle " + std::to_string(i) +
                                  " is not finite");
    if (alpha[i] == 0.0) continue;
    const double s = alpha[i] > 0.0 ? 1.0 : -1.0;
    if (sign == 0.0) sign = s;
    if (s != sign)
      throw std::invalid_argument("gcfmm: polarizabilities of both signs (eps_p above and below "
                                  "eps_m) cannot be solved together");
  }
  return sign;
}

}  // namespace

PolarizationReport solve_induced_dipoles(std::size_t n, const double *alpha, const double *e0,
                                         const DipoleFieldOperator &field, double *p,
                                         const PolarizationSettings &settings)
{
  polarizability_sign(n, alpha);  // the checks before any work
  const std::size_t m = 3 * n;
  std::vector<double> local(m, 0.0), x(m);
  bool warm = false;
  for (std::size_t k = 0; k < m; ++k) {
    x[k] = alpha[k / 3] == 0.0 ? 0.0 : p[k];
    warm = warm || x[k] != 0.0;
  }
  if (warm) field(x.data(), local.data());
  for (std::size_t k = 0; k < m; ++k) local[k] += e0[k];
  PolarizationReport rep = solve_induced_dipoles_from(n, alpha, local.data(), field, x.data(), settings);
  rep.iterations += warm ? 1 : 0;
  for (std::size_t k = 0; k < m; ++k) p[k] = x[k];
  return rep;
}

PolarizationReport solve_induced_dipoles_from(std::size_t n, const double *alpha, const double *local,
                                              const DipoleFieldOperator &field, double *p,
                                              const PolarizationSettings &settings)
{
  const double sign = polarizability_sign(n, alpha);
  const std::size_t m = 3 * n;
  PolarizationReport rep;
  std::vector<double> x(m), r(m), z(m), d(m), ad(m), tmp(m);
  // r = b - A x = sign (E0 + T x - x / alpha): the local field of the start gives it directly
  double bnorm = 0.0;
  for (std::size_t k = 0; k < m; ++k) {
    const double a = alpha[k / 3];
    x[k] = a == 0.0 ? 0.0 : p[k];
    r[k] = a == 0.0 ? 0.0 : sign * (local[k] - x[k] / a);
    z[k] = std::fabs(a) * r[k];
    bnorm += a * a * local[k] * local[k];
  }
  bnorm = std::sqrt(bnorm);
  if (bnorm == 0.0) {
    for (std::size_t k = 0; k < m; ++k) p[k] = 0.0;
    rep.converged = true;
    return rep;
  }
  auto apply = [&](const std::vector<double> &v, std::vector<double> &out) {
    field(v.data(), tmp.data());
    ++rep.iterations;
    for (std::size_t k = 0; k < m; ++k) {
      const double a = alpha[k / 3];
      out[k] = a == 0.0 ? 0.0 : sign * (v[k] / a - tmp[k]);
    }
  };
  // the residual measure: || alpha r || / || alpha (E0 + T x_start) || (preconditioned residual)
  auto residual = [&]() { return std::sqrt(dot(z, z)) / bnorm; };
  rep.residual = residual();
  const double accept = settings.accept_start > 0.0 ? settings.accept_start : settings.tolerance;
  if (rep.residual <= accept) {
    rep.converged = true;
    for (std::size_t k = 0; k < m; ++k) p[k] = x[k];
    return rep;
  }
  d = z;
  double rz = dot(r, z);
  while (rep.residual > settings.tolerance && rep.iterations < settings.max_iterations) {
    apply(d, ad);
    const double dad = dot(d, ad);
    if (!(dad > 0.0)) break;   // not definite (a packing beyond the catastrophe): not converged
    const double step = rz / dad;
    for (std::size_t k = 0; k < m; ++k) {
      x[k] += step * d[k];
      r[k] -= step * ad[k];
      z[k] = std::fabs(alpha[k / 3]) * r[k];
    }
    rep.residual = residual();
    const double rz_new = dot(r, z);
    const double beta = rz_new / rz;
    rz = rz_new;
    for (std::size_t k = 0; k < m; ++k) d[k] = z[k] + beta * d[k];
  }
  rep.converged = rep.residual <= settings.tolerance;
  for (std::size_t k = 0; k < m; ++k) p[k] = x[k];
  return rep;
}

}  // namespace gcfmm
