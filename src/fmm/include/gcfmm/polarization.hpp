// GRANULAR-CHARGED FMM core library (gcfmm).
// Induced point dipoles of dielectric spheres, solved self-consistently (mutual induction):
//   p_i = alpha_i (E0_i + sum_j T_ij p_j)
// E0: the field of the charges and the applied field at particle i; T p: the field of the other
// dipoles (and of images, periodic copies). The solver only needs T p as an operator, so the same
// iteration runs on a direct sum (tests) or an FMM evaluation (doc/polarization.md, section 4).
#ifndef GCFMM_POLARIZATION_HPP
#define GCFMM_POLARIZATION_HPP

#include <cstddef>
#include <functional>

namespace gcfmm {

//! When to stop the induction solve.
struct PolarizationSettings {
  /// relative residual || alpha (E0 + T p) - p || / || alpha E0 || (2-norms over all components)
  double tolerance = 1e-6;
  int max_iterations = 200;  //!< operator applications before giving up
  /// solve_induced_dipoles_from(): a start whose residual is at most this is the solution
  /// without iterating (0: tolerance). Iterating to a tolerance below it keeps solutions that
  /// are extrapolated from the last two (errors ~3 x tolerance) acceptable starts.
  double accept_start = 0.0;
};

//! What the last solve did.
struct PolarizationReport {
  int iterations = 0;       //!< applications of the dipole-field operator
  double residual = 0.0;    //!< relative residual reached (PolarizationSettings::tolerance)
  bool converged = false;   //!< residual <= tolerance
};

/// field[3 i + a] = component a of the field at particle i of all dipoles p[3 j + b] (bare
/// units; not of particle i's own dipole at its own centre). Must be linear in p and symmetric
/// (sum_i u_i . (T v)_i = sum_i v_i . (T u)_i), as the dipole-dipole interaction is.
using DipoleFieldOperator = std::function<void(const double *p, double *field)>;

/** @brief Solve the induced dipoles by conjugate gradients on (alpha^-1 - T) p = E0,
 *  preconditioned by alpha (doc/polarization.md, eq. (4.2)). alpha[i] is the polarizability of
 *  particle i (bare units, gcfmm::polarizability); particles with alpha = 0 keep p = 0. All
 *  nonzero alpha must have one sign (the system is then definite for any physical packing).
 *  @param p in: the starting dipoles (a warm start: the last solve's); out: the solution.
 *  @throws std::invalid_argument if the nonzero alpha differ in sign or are not finite. */
PolarizationReport solve_induced_dipoles(std::size_t n, const double *alpha, const double *e0,
                                         const DipoleFieldOperator &field, double *p,
                                         const PolarizationSettings &settings);

/** @brief The same iteration started from the local field E0 + T p of the starting dipoles p
 *  (3 n), e.g. from one evaluation of the charges and the starting dipoles together, which
 *  saves an evaluation: E0 is not needed apart. The residual is measured against
 *  || alpha (E0 + T p_start) || (against || alpha E0 || for a cold start, p = 0). The operator
 *  applications counted in the report exclude the one that gave `local`. */
PolarizationReport solve_induced_dipoles_from(std::size_t n, const double *alpha, const double *local,
                                              const DipoleFieldOperator &field, double *p,
                                              const PolarizationSettings &settings);

}  // namespace gcfmm

#endif
