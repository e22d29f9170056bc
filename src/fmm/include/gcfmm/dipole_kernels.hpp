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

/** @brief Add the potential and field (not the gradient) of a charge q at a target displaced by
 *  d = target - source (d != 0); returns 1 / r^2 for add_charge(). */
inline double add_charge_field(double q, const Vec3 &d, double &pot, Vec3 &e)
{
  const double r2 = norm2(d), rinv = 1.0 / std::sqrt(r2), rinv2 = rinv * rinv;
  const double q3 = q * rinv * rinv2;
  pot += q * rinv;
  e.x += q3 * d.x;
  e.y += q3 * d.y;
  e.z += q3 * d.z;
  return rinv2;
}

/** @brief Add the potential, field and field gradient of a charge q at a target displaced by
 *  d = target - source (d != 0). */
inline void add_charge(double q, const Vec3 &d, PointField &f)
{
  const double rinv2 = add_charge_field(q, d, f.pot, f.e);
  const double q3 = q * rinv2 * std::sqrt(rinv2), q5 = 3.0 * q3 * rinv2;
  f.g.xx += q3 - q5 * d.x * d.x;
  f.g.yy += q3 - q5 * d.y * d.y;
  f.g.zz += q3 - q5 * d.z * d.z;
  f.g.xy -= q5 * d.x * d.y;
  f.g.xz -= q5 * d.x * d.z;
  f.g.yz -= q5 * d.y * d.z;
}

/** @brief Add the potential and field (not the gradient) of a point dipole p at a target
 *  displaced by d = target - source (d != 0); returns 1 / r^2 for add_dipole(). */
inline double add_dipole_field(const Vec3 &p, const Vec3 &d, double &pot, Vec3 &e)
{
  const double r2 = norm2(d), rinv = 1.0 / std::sqrt(r2), rinv2 = rinv * rinv;
  const double r3 = rinv * rinv2, r5 = r3 * rinv2;
  const double pd = dot(p, d);
  pot += pd * r3;
  const double a = 3.0 * pd * r5;
  e.x += a * d.x - p.x * r3;
  e.y += a * d.y - p.y * r3;
  e.z += a * d.z - p.z * r3;
  return rinv2;
}

/** @brief Add the potential, field and field gradient of a point dipole p at a target
 *  displaced by d = target - source (d != 0). */
inline void add_dipole(const Vec3 &p, const Vec3 &d, PointField &f)
{
  const double rinv2 = add_dipole_field(p, d, f.pot, f.e);
  const double r5 = rinv2 * rinv2 * std::sqrt(rinv2), r7 = r5 * rinv2;
  const double pd = dot(p, d);
  const double b = 3.0 * r5, c = 15.0 * pd * r7;
  f.g.xx += b * (2.0 * p.x * d.x + pd) - c * d.x * d.x;
  f.g.yy += b * (2.0 * p.y * d.y + pd) - c * d.y * d.y;
  f.g.zz += b * (2.0 * p.z * d.z + pd) - c * d.z * d.z;
  f.g.xy += b * (p.x * d.y + p.y * d.x) - c * d.x * d.y;
  f.g.xz += b * (p.x * d.z + p.z * d.x) - c * d.x * d.z;
  f.g.yz += b * (p.y * d.z + p.z * d.y) - c * d.y * d.z;
}

//! Force F = q E + G p on a particle with charge q and dipole p in the field f.
inline Vec3 point_force(double q, const Vec3 &p, const PointField &f)
{
  const Vec3 gp = apply(f.g, p);
  return {q * f.e.x + gp.x, q * f.e.y + gp.y, q * f.e.z + gp.z};
}

/** @brief Particle i's term of the electrostatic energy of charges, induced dipoles and a
 *  uniform applied field (doc/polarization.md, eq. (3.4)):
 *  U_i = 1/2 q phi_q - q E_a . (r - r_0) - 1/2 p . E0, with phi_q the potential of the
 *  (other) charges and their images at the particle, E_a the applied field, r_0 the point of
 *  zero applied potential and E0 the field of the charges and the applied field. Summed over
 *  the particles it is the energy whose gradient is minus the forces q E + G p, once p solves
 *  (3.3). */
inline double polarizable_energy_term(double q, double phi_q, const Vec3 &applied, const Vec3 &r_minus_r0,
                                      const Vec3 &p, const Vec3 &e0)
{
  return 0.5 * q * phi_q - q * dot(applied, r_minus_r0) - 0.5 * dot(p, e0);
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
