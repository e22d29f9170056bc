// GRANULAR-CHARGED FMM core library (gcfmm).
// The "average field" approximation of the far field of Chen, Li, Liu, Makse, Soft Matter 12
// (2016) 1836, Appendix, eq. (13) (doc/theory.md, eqs. (4.7)-(4.8)): the image cells beyond
// the near block are replaced by a uniform charge density filling the bed height,
// integrated in closed form.
// No LAMMPS headers; only std.
#ifndef GCFMM_AVERAGE_FIELD_HPP
#define GCFMM_AVERAGE_FIELD_HPP

#include <cstddef>

#include "gcfmm/types.hpp"

namespace gcfmm {

/**
 * @brief Potential and field (bare 1/r kernel, E = -grad pot) at a target of a uniformly
 * charged cuboid [x1,x2] x [y1,y2] x [z1,z2] of unit density, in closed form.
 *
 * pot = [[[ F ]]] summed over the 8 corners with signs, u = x_corner - tx (etc.), r = |(u,v,w)|,
 *   F = v w ln(u+r) + w u ln(v+r) + u v ln(w+r)
 *       - u^2/2 atan(v w / (u r)) - v^2/2 atan(w u / (v r)) - w^2/2 atan(u v / (w r)),
 * E_x = [[[ v ln(w+r) + w ln(v+r) - u atan(v w / (u r)) ]]] (cyclic for E_y, E_z).
 * Valid for targets inside, on or outside the cuboid (logarithms evaluated without
 * cancellation, vanishing coefficients drop their terms).
 * @param e may be null (potential only)
 */
void cuboid_field(double x1, double x2, double y1, double y2, double z1, double z2, double tx, double ty,
                  double tz, double *pot, double e[3]);

/**
 * @brief The average far field (doc/theory.md, eq. (4.7)): a uniform charge density
 * rho = sum(q) / (lx ly (bed_zhi - bed_zlo)) filling bed_zlo <= z <= bed_zhi everywhere
 * OUTSIDE the (2 images + 1) lx x (2 images + 1) ly block centred on the primary cell
 * [x0, x0+lx) x [y0, y0+ly), integrated analytically. ADDS potential and field for targets
 * in [begin, end).
 *
 * Field = (infinite slab: E_z = 2 pi rho (2 clamp(z, bed_zlo, bed_zhi) - bed_zlo - bed_zhi),
 * no in-plane part) - (cuboid of the block). Far above the bed E_z tends to
 * 2 pi rho (bed_zhi - bed_zlo) = 2 pi sum(q) / A, minus the block's share.
 *
 * Potential convention (the potential of an infinite layer diverges): the slab enters with
 * the k = 0 term of periodic_green smeared over the bed, -2 pi rho int |z - z'| dz', and the
 * block is subtracted with its true 1/r potential. This is the same constant as the exact far
 * field of PeriodicFarField (G minus the near block), so the two potentials are comparable.
 *
 * The bed height H_p = bed_zhi - bed_zlo enters twice: the density is sum(q) / (A H_p) (so the
 * total charge per cell is exact whatever H_p) and the charge is spread over that height;
 * above and below the bed the slab part does not depend on H_p, inside it the slab field
 * varies linearly across H_p, and the block part depends on it through its geometry.
 *
 * @param n, q          all particles' charges (only sum(q) is used); x, y, z are the targets'
 *                      positions (read for i in [begin, end))
 * @param images        number of near shells (>= 0): block side (2 images + 1) lx
 * @throws std::invalid_argument if bed_zhi <= bed_zlo, images < 0 or a period is not positive
 */
void average_far_field(std::size_t n, const double *x, const double *y, const double *z, const double *q,
                       double x0, double y0, double lx, double ly, int images, double bed_zlo, double bed_zhi,
                       std::size_t begin, std::size_t end, double *pot, double *ex, double *ey, double *ez);

/**
 * @brief average_far_field() given the total charge per cell qsum = sum(q) of the sources
 * directly, at targets (x, y, z)[begin, end) that need not be the sources (StaticSourceField:
 * the sleeping charges' far field at the awake particles). The same formula; ADDS.
 */
void average_far_field_of_charge(double qsum, const double *x, const double *y, const double *z, double x0,
                                 double y0, double lx, double ly, int images, double bed_zlo, double bed_zhi,
                                 std::size_t begin, std::size_t end, double *pot, double *ex, double *ey,
                                 double *ez);

}  // namespace gcfmm

#endif
