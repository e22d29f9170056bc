// GRANULAR-CHARGED FMM core library (gcfmm).
// Particle-particle (P2P) kernel of the bare 1/r interaction and O(N^2) reference sums.
//   pot_i += sum_j q_j / |r_i - r_j - s|,   E_i += sum_j q_j (r_i - r_j - s) / |r_i - r_j - s|^3
// (s: image shift of the sources). Pairs at zero distance contribute nothing (self term).
#ifndef GCFMM_KERNELS_HPP
#define GCFMM_KERNELS_HPP

#include <cstddef>

#include "gcsimd/simd.hpp"

namespace gcfmm {

/** @brief Vectorised P2P (doc/theory.md, eq. (3.1)): add the potential and field of sources
 *  (xs, ys, zs, qs)[0..ns), shifted by (sx, sy, sz), at targets (xt, yt, zt)[0..nt).
 *  Structure-of-arrays inputs. Pairs with |r_i - r_j - s|^2 <= r2_min are skipped (the self
 *  term, and coincident pairs; the solver passes its coincidence radius squared). The result
 *  for each target depends only on its own position and the source range (not on the other
 *  targets). */
void p2p(std::size_t nt, const double *xt, const double *yt, const double *zt, std::size_t ns,
         const double *xs, const double *ys, const double *zs, const double *qs, double sx, double sy,
         double sz, double *pot, double *ex, double *ey, double *ez, double r2_min = 0.0);

/** @brief p2p() on a given instruction-set path (tests and benchmarks; p2p() uses
 *  gcsimd::default_simd_path()). @throws std::invalid_argument if the path is not available. */
void p2p_with(gcsimd::SimdPath path, std::size_t nt, const double *xt, const double *yt, const double *zt, std::size_t ns,
              const double *xs, const double *ys, const double *zs, const double *qs, double sx, double sy, double sz,
              double *pot, double *ex, double *ey, double *ez, double r2_min = 0.0);

//! A P2P kernel with the arguments of p2p(), and the largest relative error it makes in one
//! pair's field term (its potential term has a third of it; 0: round-off only).
struct P2PKernel {
  using Function = void (*)(std::size_t nt, const double *xt, const double *yt, const double *zt, std::size_t ns,
                            const double *xs, const double *ys, const double *zs, const double *qs, double sx,
                            double sy, double sz, double *pot, double *ex, double *ey, double *ez, double r2_min);
  Function run = nullptr;
  double term_error = 0.0;
};

/** @brief The fastest P2P kernel of a path whose term error is at most max_term_error: on
 *  AVX-512 and AVX2 fewer Newton steps after the hardware estimate of 1/sqrt(r2); 0 (or a
 *  bound finer than the reduced kernels reach) gives the full-precision kernel of p2p_with().
 *  The solver asks for p2p_term_tolerance() of its options (options.hpp).
 *  @throws std::invalid_argument if the path is not available. */
P2PKernel p2p_kernel_within(double max_term_error, gcsimd::SimdPath path = gcsimd::default_simd_path());

/** @brief P2P of charges and point dipoles (doc/polarization.md, eq. (1.1)-(1.2)): add the
 *  potential, field and, if g6 is not null, the field gradient (6 per target: xx, xy, xz, yy,
 *  yz, zz) of sources (xs, ys, zs) with charges qs and dipoles (pxs, pys, pzs), shifted by
 *  (sx, sy, sz), at targets (xt, yt, zt)[0..nt). Pairs with |r_i - r_j - s|^2 <= r2_min are
 *  skipped, as in p2p(). The terms are those of dipole_kernels.hpp (vectorised over the sources). */
void p2p_dipoles(std::size_t nt, const double *xt, const double *yt, const double *zt, std::size_t ns,
                 const double *xs, const double *ys, const double *zs, const double *qs, const double *pxs,
                 const double *pys, const double *pzs, double sx, double sy, double sz, double *pot, double *ex,
                 double *ey, double *ez, double *g6, double r2_min = 0.0);

/** @brief O(N^2) free-space reference: pot_i = sum_{j != i} q_j / r_ij and E_i = -grad pot_i
 *  (outputs are overwritten). Coincident pairs are skipped. */
void direct_free(std::size_t n, const double *x, const double *y, const double *z, const double *q,
                 double *pot, double *ex, double *ey, double *ez);

/** @brief O(N^2 (2 images + 1)^2) reference over the own cell and all image cells
 *  (nx lx, ny ly, 0) with max(|nx|,|ny|) <= images; the self term is dropped only for the
 *  unshifted copy (outputs are overwritten). No far field. */
void direct_images(std::size_t n, const double *x, const double *y, const double *z, const double *q,
                   double lx, double ly, int images, double *pot, double *ex, double *ey, double *ez);

}  // namespace gcfmm

#endif
