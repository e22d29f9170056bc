// GRANULAR-CHARGED FMM core library (gcfmm).
// The change of a charge pair's field between two separations, for many pairs at once: the hot
// loop of the near refresh of multiple time stepping (doc/theory.md, eq. (5.2)), where each
// step sums, for the pairs closer than a cutoff, K(r(t)) - K(r(t_e)) with K(d) = d / |d|^3 and
// the potential's 1/|d|. The terms are those of charge_terms (dipole_kernels.hpp, one home),
// compiled for each instruction-set path (simd.hpp) with exact square roots and divisions and
// without fused multiply-adds, so every path gives the scalar result bit for bit and a caller
// can sum the pairs in its own order.
#ifndef GCFMM_CHARGE_PAIR_CHANGE_HPP
#define GCFMM_CHARGE_PAIR_CHANGE_HPP

#include <cstddef>

#include "gcsimd/simd.hpp"

namespace gcfmm {

//! n separations as three arrays (structure of arrays).
struct Separations {
  const double *x, *y, *z;
};

//! The results for n pairs: the change of (E_x, E_y, E_z, phi) of a unit charge, and the
//! squared separations (for the caller's cutoff test).
struct ChargePairChange {
  double *ex, *ey, *ez, *pot;
  double *r2now, *r2then;
};

/** @brief For k < n: (ex, ey, ez, pot)[k] = terms(now_k) - terms(then_k), the terms of a unit
 *  charge (charge_terms) at separation d: (d / |d|^3, 1 / |d|); a zero separation has no terms
 *  (its end contributes 0). r2now[k] = |now_k|^2, r2then[k] = |then_k|^2. Output arrays must
 *  not overlap the inputs. */
void charge_pair_change(std::size_t n, Separations now, Separations then, ChargePairChange out,
                        gcsimd::SimdPath path = gcsimd::default_simd_path());

//! The terms of n separations: (ex, ey, ez, pot)[k] = charge_terms of a unit charge at
//! separation at_k (zero separation: 0), r2[k] = |at_k|^2 (struct ChargePairChange without
//! r2then, which may be null here).
struct ChargeTerms {
  double *ex, *ey, *ez, *pot;
  double *r2;
};

/** @brief For k < n: the terms (d / |d|^3, 1 / |d|) of a unit charge at separation d = at_k and
 *  |d|^2, bit for bit the `now` half of charge_pair_change on every path (the near refresh
 *  between evaluations, whose evaluation-time half is held). Outputs must not overlap inputs. */
void charge_terms_at(std::size_t n, Separations at, ChargeTerms out,
                     gcsimd::SimdPath path = gcsimd::default_simd_path());

}  // namespace gcfmm

#endif
