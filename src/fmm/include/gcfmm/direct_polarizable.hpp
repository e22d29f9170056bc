// GRANULAR-CHARGED FMM core library (gcfmm).
// O(N^2) reference for charged, polarizable particles: charges, induced dipoles (solved by
// solve_induced_dipoles), a uniform applied field, a grounded plane (by images) and a block of
// periodic copies in x and y (no far field beyond it). The reference the FMM's dipole
// evaluation is tested against, and the closed forms of doc/polarization.md are tested on.
#ifndef GCFMM_DIRECT_POLARIZABLE_HPP
#define GCFMM_DIRECT_POLARIZABLE_HPP

#include <cstddef>
#include <vector>

#include "gcfmm/dipole_kernels.hpp"
#include "gcfmm/polarization.hpp"
#include "gcfmm/types.hpp"

namespace gcfmm {

//! Particles and their surroundings (bare units; arrays of length n; alpha null: no dipoles).
struct PolarizableSystem {
  std::size_t n = 0;
  const double *x = nullptr, *y = nullptr, *z = nullptr;
  const double *q = nullptr;       //!< charges
  const double *alpha = nullptr;   //!< polarizabilities (gcfmm::polarizability); null: none
  Vec3 applied_field;              //!< uniform applied field (bare units)
  bool electrode = false;          //!< a grounded plane at z = electrode_z below every particle
  double electrode_z = 0.0;
  double lx = 0.0, ly = 0.0;       //!< periods in x and y (with images > 0)
  int images = 0;                  //!< copies (i lx, j ly) with max(|i|, |j|) <= images
};

//! A system of n particles at (x, y, z) with charges q and polarizabilities alpha (null: no
//! dipoles), the surroundings at their defaults (no field, no electrode, no copies).
inline PolarizableSystem particles_of(std::size_t n, const double *x, const double *y, const double *z,
                                      const double *q, const double *alpha = nullptr) {
  PolarizableSystem s;
  s.n = n;
  s.x = x;
  s.y = y;
  s.z = z;
  s.q = q;
  s.alpha = alpha;
  return s;
}

//! The solution: per particle dipole, potential, field, field gradient, force; total energy.
struct PolarizableResult {
  std::vector<Vec3> dipole;
  std::vector<PointField> field;   //!< total: charges, dipoles, images, applied field
  std::vector<Vec3> force;         //!< q E + G p (doc/polarization.md, eq. (1.3))
  /// U = 1/2 sum q_i phi_q(i) + sum q_i phi_applied(r_i) - 1/2 sum p_i . E0_i (eq. (3.4)),
  /// phi_applied = -E_applied . (r - (0, 0, electrode_z)) (zero on the electrode; without one,
  /// zero at the origin); E0: the field of the charges and the applied field.
  double energy = 0.0;
  PolarizationReport report;
};

/** @brief Solve the induced dipoles and evaluate fields, forces and energy by direct sums.
 *  @param start starting dipoles (warm start; size n), or null for zero.
 *  @throws std::invalid_argument if a particle is at or below the electrode. */
PolarizableResult solve_polarizable_direct(const PolarizableSystem &sys,
                                           const PolarizationSettings &settings,
                                           const std::vector<Vec3> *start = nullptr);

}  // namespace gcfmm

#endif
