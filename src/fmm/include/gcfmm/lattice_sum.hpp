// GRANULAR-CHARGED FMM core library (gcfmm).
// 2D-periodic (x, y periodic; z open) lattice sums of the bare 1/r kernel: the periodic
// Green's function G (doc/theory.md, eqs. (4.2)-(4.4)) and the far kernel R of all image
// cells beyond the near block (eq. (4.5)). The far-field operator built on R is in
// far_field.hpp. No LAMMPS headers; only std.
//
// Notation (Gaussian units, the caller multiplies by its Coulomb constant):
//   cell periods lx, ly; area A = lx * ly; image shift n = (nx lx, ny ly, 0);
//   potential pot(r) = sum_j q_j K(r - r_j), field E = -grad pot.
// See doc/fmm-far-field.md for the derivations, error control and measured costs.
#ifndef GCFMM_LATTICE_SUM_HPP
#define GCFMM_LATTICE_SUM_HPP

namespace gcfmm {

/**
 * @brief Full 2D-periodic Green's function of the 1/r kernel and its gradient.
 *
 * G(d) = sum over all images n of 1/|d + n|, made convergent by dropping the divergent
 * k = 0 Fourier term 2 pi / (A k). Equivalently (both forms are implemented and agree to
 * round-off):
 *
 *   G(d) = -2 pi |dz| / A + (2 pi / A) sum_{k != 0} cos(k.rho) exp(-|k| |dz|) / |k|        (Fourier)
 *        = sum_n erfc(alpha r_n) / r_n
 *          + (pi / A) sum_{k != 0} cos(k.rho) / |k| [ e^{k dz} erfc(k/2alpha + alpha dz)
 *                                                   + e^{-k dz} erfc(k/2alpha - alpha dz) ]
 *          - (2 pi / A) [ dz erf(alpha dz) + exp(-alpha^2 dz^2) / (alpha sqrt(pi)) ]      (2D Ewald)
 *
 * with rho = (dx, dy), k = 2 pi (mx / lx, my / ly). The constant: G is the symmetric
 * square-shell limit
 *
 *   G(d) = lim_{M -> inf} [ sum_{max(|nx|,|ny|) <= M} 1/|d + n|  -  C_M ],
 *   C_M  = (4 / A) [ a asinh(b / a) + b asinh(a / b) ],  a = (M + 1/2) lx,  b = (M + 1/2) ly,
 *
 * i.e. the lattice sum minus the integral of 1/|rho| over the (2M+1) lx x (2M+1) ly rectangle
 * of the summed cells, divided by A (checked numerically in unittest/fmm/test_lattice_sum.cpp).
 * The gradient needs no constant: it is the square-shell limit of the field sum.
 * Far above a unit charge grad_z G -> -2 pi sign(dz) / A (the field 2 pi / A of a sheet).
 *
 * @param dx,dy,dz separation (any value; reduced modulo the periods internally)
 * @param lx,ly    periods (> 0)
 * @param g        out: G (may be null)
 * @param gx,gy,gz out: gradient of G (each may be null)
 * @pre d is not on a lattice point (dz != 0 or rho not a lattice vector)
 */
void periodic_green(double dx, double dy, double dz, double lx, double ly, double *g, double *gx,
                    double *gy, double *gz);

/**
 * @brief The pure Fourier form of periodic_green (see above), truncated where exp(-|k||dz|)
 * < 1e-17. Fast for |dz| >~ min(lx, ly) / 2; cost grows like 1/dz^2.
 * @throws std::invalid_argument if |dz| < 0.01 min(lx, ly).
 */
void periodic_green_fourier(double dx, double dy, double dz, double lx, double ly, double *g,
                            double *gx, double *gy, double *gz);

/**
 * @brief The 2D Ewald form of periodic_green with splitting parameter alpha * min(lx, ly)
 * = 4, real space summed over 3 x 3 cells and reciprocal space to |k| <= 13 alpha.
 * Accurate to round-off for |dz| <= min(lx, ly); periodic_green uses it below
 * green_switch_height(lx, ly) and the Fourier form above.
 */
void periodic_green_ewald(double dx, double dy, double dz, double lx, double ly, double *g,
                          double *gx, double *gy, double *gz);

/// @brief |dz| at which periodic_green switches from the Ewald to the Fourier form.
double green_switch_height(double lx, double ly);

/**
 * @brief Exact far-field kernel R(d) = G(d) - sum_{max(|nx|,|ny|) <= images} 1/|d + n|
 * (and its gradient): the potential of all images beyond `images` shells, in the constant
 * convention of periodic_green. @pre images >= 0, d not on an excluded lattice point.
 */
void far_kernel(double dx, double dy, double dz, double lx, double ly, int images, double *r,
                double *rx, double *ry, double *rz);

}  // namespace gcfmm

#endif
