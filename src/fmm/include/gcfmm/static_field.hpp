// GRANULAR-CHARGED FMM core library (gcfmm).
// The field of a fixed ("static") set of sources at moving targets: everything that depends on
// the sources only (their tree and multipoles, the exact far field's node potentials, the
// average far field's charge and bed) is computed once by set_sources(); each evaluate() then
// costs about O(N_targets log N_sources), independent of N_sources for the far part.
// Use: the sleeping (frozen) particles of a deposition as sources, the awake ones as targets;
// the awake particles' field is Solver(awake) + StaticSourceField(sleeping) at the awake.
// Method, error and costs: doc/fmm-static-sources.md.
#ifndef GCFMM_STATIC_FIELD_HPP
#define GCFMM_STATIC_FIELD_HPP

#include <cstddef>
#include <memory>

#include "gcfmm/options.hpp"
#include "gcfmm/solver.hpp"
#include "gcfmm/types.hpp"

namespace gcfmm {

//! Parameters, counts and timings (seconds) of the last set_sources() / evaluate().
struct StaticFieldStats {
  int order = 0;                 //!< expansion order p (resolve(), as Solver)
  double theta = 0.0;            //!< MAC opening angle
  int leaf = 0;                  //!< max sources per leaf of the source tree
  int target_leaf = 0;           //!< max targets per leaf of the target tree
  double estimated_error = 0.0;  //!< predicted relative RMS force error (near field; plus far field)
  // set_sources()
  std::size_t sources = 0;       //!< charged sources kept (zero charges are dropped)
  std::size_t source_nodes = 0;  //!< nodes of the source tree
  std::size_t source_leaves = 0; //!< leaves of the source tree
  int far_setups = 0;            //!< far-field operator set-ups so far (set_sources, or an evaluate()
                                 //!< whose targets left the stored column)
  double t_set_sources = 0.0;    //!< all of set_sources()
  double t_source_tree = 0.0;    //!< wrap, source tree
  double t_upward = 0.0;         //!< P2M + M2M of the sources
  double t_far_setup = 0.0;      //!< far-field operator set-up (0 when the stored one still covers)
  double t_far_prepare = 0.0;    //!< exact far field's node potentials (anterpolation + operator)
  double t_energy = 0.0;         //!< the last source_energy() that computed (one Solver over the sources)
  // evaluate()
  std::size_t targets = 0;       //!< targets of the last evaluate()
  std::size_t target_nodes = 0;  //!< nodes of the target tree
  std::size_t m2l_count = 0;     //!< M2L interactions (all shifts)
  std::size_t p2p_pairs = 0;     //!< target-source pairs summed directly (all shifts)
  double t_evaluate = 0.0;       //!< all of evaluate()
  double t_target_tree = 0.0;    //!< wrap, target tree, coincidence test
  double t_lists = 0.0;          //!< dual-tree traversal target tree x source tree
  double t_m2l = 0.0;            //!< M2L
  double t_p2p = 0.0;            //!< P2P
  double t_downward = 0.0;       //!< L2L + L2P
  double t_far = 0.0;            //!< far field (interpolation, or the average field)
};

/**
 * @brief Potential and field of a fixed set of charges ("sources") at any number of other
 * points ("targets"), evaluated many times for moving targets.
 *
 * Usage: StaticSourceField f(opts); f.set_box(...) (Periodic2D); f.set_z_range(...)
 * (Periodic2D, recommended); f.set_sources(ns, x, y, z, q) once per change of the sources;
 * f.evaluate(nt, x, y, z, pot, ex, ey, ez) any number of times.
 *
 * Conventions exactly as Solver (bare 1/r kernel, multiply by the Coulomb constant; E = -grad
 * pot; Periodic2D positions wrapped into the cell; `images` shells by the FMM and the rest by
 * Options::farfield; computed in the same power-of-two length unit h as Solver), with the
 * targets never counted as sources:
 *     pot_t = sum_s q_s K(r_t - r_s),  E_t = -grad_t pot_t
 * (K = 1/r in free space; the near block plus the far field for Periodic2D). Hence, for any
 * split of a particle set P into A and S, Solver(A) at A plus StaticSourceField(S) at A equals
 * Solver(P) at A to the accuracy (FarField::Average: when the bed is given, Options::bed_zlo
 * and bed_zhi; with the automatic bed each part smears its charge over its own z range).
 * Order, theta and leaf come from the same resolve() and the same MAC (doc/theory.md, eqs.
 * (3.14)-(3.16)) as Solver, so the requested accuracy holds in the same sense.
 *
 * Thread safety: one instance per thread (evaluate() writes scratch space).
 */
class StaticSourceField {
 public:
  //! default max targets per leaf of the target tree (set_target_leaf(); doc/fmm-static-sources.md)
  static constexpr int kDefaultTargetLeaf = 8;

  /** @throws std::invalid_argument as Options::validate() */
  explicit StaticSourceField(const Options &opts);
  ~StaticSourceField();
  StaticSourceField(const StaticSourceField &) = delete;
  StaticSourceField &operator=(const StaticSourceField &) = delete;

  /** @brief Periodic2D only: the primary cell [xlo, xlo+lx) x [ylo, ylo+ly). Forgets the
   *  sources (call set_sources() again). */
  void set_box(double xlo, double ylo, double lx, double ly);

  /** @brief Periodic2D only: the z range that sources and targets may occupy; the exact far
   *  field's column covers it (with the sources' range), so that moving targets never force
   *  a new far-field set-up. Targets outside the stored column are still handled: evaluate()
   *  then extends the column (a new set-up and node potentials, ~0.5 s at accuracy 1e-4). */
  void set_z_range(double zlo, double zhi);

  /** @brief Max targets per leaf of the target tree (0: kDefaultTargetLeaf). Smaller than the
   *  source leaves: a few sparse targets above a dense bed would otherwise sit in wide leaves
   *  that sum many bed sources directly. */
  void set_target_leaf(int leaf);

  /** @brief Everything that depends on the sources only: wrap and scale, the source tree, the
   *  multipoles (P2M, M2M), the exact far field's set-up (if the stored column does not cover
   *  the z range) and node potentials, the average far field's charge and bed, and
   *  nothing else (source_energy() is computed when first asked). Sources with zero charge are dropped (sources of nothing). Cost O(ns)
   *  (plus, for FarField::Exact, a set-up of ~0.5 s when the column changes).
   *  @throws CoincidentParticles (indices into these arrays) if two charged sources are closer
   *  than kCoincidenceRadius h; std::runtime_error for Periodic2D without set_box(). */
  void set_sources(std::size_t ns, const double *x, const double *y, const double *z, const double *q);

  /** @brief Potential and field of the sources at the nt targets, WRITTEN (not added). Cost
   *  ~O(nt log ns): a target tree, the dual-tree traversal against the source tree for every
   *  image shift (M2L into the target nodes, P2P against source leaves), L2L/L2P on the
   *  target tree, and the far field interpolated from the precomputed node potentials.
   *  Targets may lie anywhere (in free space far outside the sources; for Periodic2D x, y are
   *  wrapped).
   *  @throws CoincidentParticles with first() = the target's index and second() = the source's
   *  index (in the arrays given to set_sources()) if a target is closer than kCoincidenceRadius h
   *  to a charged source (or one of its image-shell copies); std::runtime_error if set_sources()
   *  was not called. */
  void evaluate(std::size_t nt, const double *x, const double *y, const double *z, double *pot, double *ex,
                double *ey, double *ez);

  /** @brief Energy of the sources among themselves, U_S = (1/2) sum_s q_s u_s with u as
   *  Solver::energy_potential() over the sources alone (self term dropped, images and the far
   *  field included), computed on the first call after set_sources() (one Solver over the
   *  sources: about the cost of a whole evaluation) and kept.
   *  @throws CoincidentParticles (indices into the set_sources() arrays) if two charged
   *  sources are closer than kCoincidenceRadius h. For FarField::None and Exact (pair
   *  energies) U_P = U_A + U_S + sum_{a in A} q_a pot^S_a for a split of P into A and S; the
   *  average far field is no pair interaction and does not split so. */
  double source_energy() const;

  /** @brief Parameters, counts and timings of the last set_sources() / evaluate(). */
  const StaticFieldStats &stats() const;
  /** @brief Options after validation, with order/theta/leaf as resolved. */
  const Options &options() const;
  /** @brief Number of sources of the last set_sources() (including zero charges). */
  std::size_t size() const;
  /** @brief Bytes held (trees, expansions, scratch, far-field operator and node potentials). */
  std::size_t memory_bytes() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace gcfmm

#endif
