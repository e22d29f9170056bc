// GRANULAR-CHARGED FMM core library (gcfmm).
// Point charges and point dipoles in the bare 1/r kernel, and the grounded plane's images:
// stateless inline kernels, the one home of these equations (doc/polarization.md, section 1).
//   charge q at s, target at t, d = t - s, r = |d|:
//     pot = q / r      E_a = q d_a / r^3      dE_a/dt_b = q (delta_ab / r^3 - 3 d_a d_b / r^5)
//   dipole p at s:
//     pot = p.d / r^3             E_a = 3 (p.d) d_a / r^5 - p_a / r^3
//     dE_a/dt_b = 3 (p_a d_b + p_b d_a + (p.d) delta_ab) / r^5 - 15 (p.d) d_a d_b / r^7
// The force on a particle with charge q and dipole p in a field E with gradient G is
// F_a = q E_a + sum_b G_ab p_b; G is symmetric (E is curl free), so G p = (p . grad) E.
#ifndef GCFMM_DIPOLE_KERNELS_HPP
#define GCFMM_DIPOLE_KERNELS_HPP

#include <cmath>

#include "gcfmm/types.hpp"

namespace gcfmm {

//! Symmetric 3 x 3 tensor (the field gradient dE_a/dx_b).
struct SymTensor {
  double xx = 0.0, xy = 0.0, xz = 0.0, yy = 0.0, yz = 0.0, zz = 0.0;
};

//! G v for a symmetric tensor G.
inline Vec3 apply(const SymTensor &g, const Vec3 &v)
{
  return {g.xx * v.x + g.xy * v.y + g.xz * v.z, g.xy * v.x + g.yy * v.y + g.yz * v.z,
          g.xz * v.x + g.yz * v.y + g.zz * v.z};
}

//! Potential, field and field gradient at one target.
struct PointField {
  double pot = 0.0;
  Vec3 e;
  SymTensor g;
};

//! Potential, field and field gradient accumulated in any arithmetic type T (double, or a
//! SIMD register type with GCC's vector operators: the P2P kernels of src/kernels.cpp).
template <class T>
struct FieldTerms {
  T pot{}, ex{}, ey{}, ez{}, gxx{}, gxy{}, gxz{}, gyy{}, gyz{}, gzz{};
};

/** @brief The terms of a charge q at a target displaced by d = target - source, given
 *  rinv = 1 / |d| (rinv = 0 adds nothing: the kernels' way of dropping a pair). The gradient
 *  only with kGradient. */
template <bool kGradient, class T>
inline void charge_terms(T q, T dx, T dy, T dz, T rinv, FieldTerms<T> &f)
{
  const T rinv2 = rinv * rinv, q3 = q * rinv * rinv2;
  f.pot += q * rinv;
  f.ex += q3 * dx;
  f.ey += q3 * dy;
  f.ez += q3 * dz;
  if (kGradient) {
    const T q5 = 3.0 * q3 * rinv2;
    f.gxx += q3 - q5 * dx * dx;
    f.gyy += q3 - q5 * dy * dy;
    f.gzz += q3 - q5 * dz * dz;
    f.gxy -= q5 * dx * dy;
    f.gxz -= q5 * dx * dz;
    f.gyz -= q5 * dy * dz;
  }
}

/** @brief The terms of a point dipole p at a target displaced by d, given rinv = 1 / |d|
 *  (0: nothing). */
template <bool kGradient, class T>
inline void dipole_terms(T px, T py, T pz, T dx, T dy, T dz, T rinv, FieldTerms<T> &f)
{
  const T rinv2 = rinv * rinv, r3 = rinv * rinv2, r5 = r3 * rinv2;
  const T pd = px * dx + py * dy + pz * dz;
  f.pot += pd * r3;
  const T a = 3.0 * pd * r5;
  f.ex += a * dx - px * r3;
  f.ey += a * dy - py * r3;
  f.ez += a * dz - pz * r3;
  if (kGradient) {
    const T b = 3.0 * r5, c = 15.0 * pd * r5 * rinv2;
    f.gxx += b * (2.0 * px * dx + pd) - c * dx * dx;
    f.gyy += b * (2.0 * py * dy + pd) - c * dy * dy;
    f.gzz += b * (2.0 * pz * dz + pd) - c * dz * dz;
    f.gxy += b * (px * dy + py * dx) - c * dx * dy;
    f.gxz += b * (px * dz + pz * dx) - c * dx * dz;
    f.gyz += b * (py * dz + pz * dy) - c * dy * dz;
  }
}

//! FieldTerms<double> added to a PointField
inline void add_terms(const FieldTerms<double> &t, PointField &f)
{
  f.pot += t.pot;
  f.e = f.e + Vec3{t.ex, t.ey, t.ez};
  f.g.xx += t.gxx;
  f.g.xy += t.gxy;
  f.g.xz += t.gxz;
  f.g.yy += t.gyy;
  f.g.yz += t.gyz;
  f.g.zz += t.gzz;
}

/** @brief Add the potential, field and field gradient of a charge q at a target displaced by
 *  d = target - source (d != 0). */
inline void add_charge(double q, const Vec3 &d, PointField &f)
{
  FieldTerms<double> t;
  charge_terms<true>(q, d.x, d.y, d.z, 1.0 / std::sqrt(norm2(d)), t);
  add_terms(t, f);
}

/** @brief Add the potential, field and field gradient of a point dipole p at a target
 *  displaced by d = target - source (d != 0). */
inline void add_dipole(const Vec3 &p, const Vec3 &d, PointField &f)
{
  FieldTerms<double> t;
  dipole_terms<true>(p.x, p.y, p.z, d.x, d.y, d.z, 1.0 / std::sqrt(norm2(d)), t);
  add_terms(t, f);
}

//! Force F = q E + G p on a particle with charge q and dipole p in the field f.
inline Vec3 point_force(double q, const Vec3 &p, const PointField &f)
{
  const Vec3 gp = apply(f.g, p);
  return {q * f.e.x + gp.x, q * f.e.y + gp.y, q * f.e.z + gp.z};
}

/** @brief Particle i's term of the electrostatic energy of charges, induced dipoles and a
 *  uniform applied field (doc/polarization.md, eqs. (3.4)-(3.5)):
 *  U_i = 1/2 q phi - q E_a . (r - r_0) - 1/2 p . E_a, with phi the potential of the charges
 *  and dipoles (and their images) at the particle, E_a the applied field and r_0 the point of
 *  zero applied potential. Summed over the particles it is U = 1/2 sum q phi_q - sum q E_a . r
 *  - 1/2 sum p . E0 (3.4) by reciprocity (sum q phi_p = -sum p . E_q), the energy whose
 *  gradient is minus the forces q E + G p once p solves (3.3). */
inline double polarizable_energy_term(double q, double phi, const Vec3 &applied, const Vec3 &r_minus_r0,
                                      const Vec3 &p)
{
  return 0.5 * q * phi - q * dot(applied, r_minus_r0) - 0.5 * dot(p, applied);
}

// ---- a grounded conducting plane z = z0 (doc/polarization.md, section 2) ---------------------
// The field above it is that of the sources plus their mirror images: a charge q at r has the
// image -q at the mirror point, a dipole p = (px, py, pz) the image (-px, -py, pz).

inline Vec3 mirror_point(const Vec3 &r, double z0) { return {r.x, r.y, 2.0 * z0 - r.z}; }
inline double image_charge(double q) { return -q; }
inline Vec3 image_dipole(const Vec3 &p) { return {-p.x, -p.y, p.z}; }

// ---- dielectric spheres (doc/polarization.md, section 3) -------------------------------------

/** @brief Clausius-Mossotti factor beta = (eps_p - eps_m) / (eps_p + 2 eps_m) of a sphere of
 *  relative permittivity eps_p in a medium eps_m (both > 0): -1/2 < beta < 1. */
inline double clausius_mossotti(double eps_p, double eps_m)
{
  return (eps_p - eps_m) / (eps_p + 2.0 * eps_m);
}

/** @brief Polarizability in the bare kernel's units: a sphere of radius a in the field E
 *  (bare units, the field of the medium's charges divided by the caller's Coulomb constant)
 *  carries the point dipole p = alpha E with alpha = beta a^3 (the SI dipole
 *  4 pi eps0 eps_m a^3 beta E_SI in units of charge x length, when the caller's Coulomb
 *  constant is 1 / (4 pi eps0 eps_m)). */
inline double polarizability(double beta, double radius) { return beta * radius * radius * radius; }

}  // namespace gcfmm

#endif
