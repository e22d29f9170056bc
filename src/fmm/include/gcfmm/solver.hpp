// GRANULAR-CHARGED FMM core library (gcfmm).
// The driver: adaptive octree FMM for the bare 1/r kernel, free space or 2D periodic.
#ifndef GCFMM_SOLVER_HPP
#define GCFMM_SOLVER_HPP

#include <cstddef>
#include <memory>
#include <stdexcept>
#include <string>

#include "gcfmm/kernels.hpp"
#include "gcfmm/options.hpp"
#include "gcfmm/types.hpp"

namespace gcfmm {

//! Parameters used and timings of the last build()/evaluate() (seconds).
struct Stats {
  int order = 0;                 //!< expansion order p
  double theta = 0.0;            //!< MAC opening angle
  int leaf = 0;                  //!< max particles per leaf
  int levels = 0;                //!< tree levels
  std::size_t nodes = 0;         //!< tree nodes
  std::size_t leaves = 0;        //!< tree leaves
  double estimated_error = 0.0;  //!< predicted relative RMS force error (near field; plus far field)
  std::size_t m2l_count = 0;     //!< M2L interactions (all shifts)
  std::size_t p2p_pairs = 0;     //!< particle pairs summed directly (all shifts)
  double t_build = 0.0;          //!< tree + lists (+ far-field set-up) in build()
  double t_upward = 0.0;         //!< P2M + M2M
  double t_m2l = 0.0;            //!< M2L
  double t_p2p = 0.0;            //!< P2P
  double t_downward = 0.0;       //!< L2L + L2P
  double t_far = 0.0;            //!< far field beyond the image shells
};

/** @brief Thrown by Solver::evaluate when two distinct particles are closer than the
 *  coincidence radius (kCoincidenceRadius times the solver's length unit) and either is
 *  charged. first() and second() are the two particles' indices in the arrays given to
 *  build() (first() < second()); the message reads "gcfmm: particles <first> and <second> are
 *  at the same position ...". */
class CoincidentParticles : public std::runtime_error {
 public:
  CoincidentParticles(std::size_t first, std::size_t second, const std::string &what)
      : std::runtime_error(what), first_(first), second_(second) {}
  std::size_t first() const { return first_; }    //!< smaller input index of the pair
  std::size_t second() const { return second_; }  //!< larger input index of the pair

 private:
  std::size_t first_, second_;
};

/** @brief Coincidence radius relative to the solver's length unit h (the power of two >= the
 *  larger period of a periodic cell, or >= the largest extent of the particles in free
 *  space): pairs closer than kCoincidenceRadius h are treated as coincident. Positions are
 *  stored with a rounding error of ~1e-16 h, so at this separation the direction of the pair
 *  (and hence its field) is uncertain by ~1e-6 relative, the tightest accuracy the solver is
 *  asked for, while the field q / d^2 is 1e20 times a typical one. */
inline constexpr double kCoincidenceRadius = 1e-10;

//! Sources of Solver::evaluate_dipoles: arrays over the particles of build(), caller's order.
struct DipoleSources {
  const double *q = nullptr;   //!< charges; null: none
  const double *px = nullptr;  //!< point dipoles (charge x length); null (all three): none
  const double *py = nullptr;
  const double *pz = nullptr;
};

//! Outputs of Solver::evaluate_dipoles (overwritten), caller's order.
struct FieldOutputs {
  double *pot = nullptr;       //!< potential
  double *ex = nullptr;        //!< field E = -grad pot
  double *ey = nullptr;
  double *ez = nullptr;
  double *gradient = nullptr;  //!< 6 per particle, G_ab = dE_a/dx_b as xx, xy, xz, yy, yz, zz; null: not computed
  /// only the particles with index < targets are targets (the others are sources only, e.g.
  /// the images of an electrode: their results are left 0 or partial, and their nodes skip
  /// M2L, L2L, L2P and P2P); the default: all
  std::size_t targets = static_cast<std::size_t>(-1);
};

/** Adaptive FMM solver. Usage: Solver s(opts); s.set_box(...) (periodic); s.build(n, x, y, z);
 *  s.evaluate(q, pot, ex, ey, ez) (any number of times with new charges); s.stats(). */
class Solver {
 public:
  explicit Solver(const Options &opts);
  ~Solver();
  Solver(const Solver &) = delete;
  Solver &operator=(const Solver &) = delete;

  /** @brief Periodic2D only: the primary cell [xlo, xlo+lx) x [ylo, ylo+ly). */
  void set_box(double xlo, double ylo, double lx, double ly);

  /** @brief Periodic2D with FarField::Exact: the far-field operator covers at least
   *  [zlo, zhi] (e.g. the simulation box), so that it is set up once instead of again each
   *  time the particles' z range grows (its set-up costs far more than an evaluation). */
  void set_z_range(double zlo, double zhi);

  /** @brief Build the tree and interaction lists for n particles. Positions of a periodic
   *  system may lie outside the primary cell: x and y are wrapped into it internally.
   *  Charges are not needed. */
  void build(std::size_t n, const double *x, const double *y, const double *z);

  /** @brief For every particle i: pot[i] = sum_{j != i} q_j / |r_i - r_j| (plus the periodic
   *  images for Periodic2D: `images` shells by the FMM, the far field per Options::farfield)
   *  and E = -grad pot. Bare 1/r kernel (Gaussian units): multiply by the Coulomb constant.
   *  The self term (j = i, unshifted) is dropped; zero-charge particles are sources of
   *  nothing but get their field. No neutrality is assumed (net charge is allowed).
   *  With nparts > 1 only the targets of work partition `part` (contiguous leaf ranges
   *  balanced by estimated cost, the same on every caller) are computed and all others are
   *  set to 0; the sum over parts is bit-identical to nparts = 1. With a PartSum (one
   *  evaluate() call per part running at the same time, e.g. one per MPI rank) the parts
   *  also split the far field's anterpolation, which each part otherwise repeats; the results
   *  stay bit-identical.
   *  Any length scale works: the solver computes in coordinates relative to its length unit
   *  h (a power of two, see kCoincidenceRadius), so results are bit-identical to those of the
   *  unscaled arithmetic except the average far field (round-off).
   *  @throws CoincidentParticles (a std::runtime_error) if two distinct particles are closer
   *  than kCoincidenceRadius h and either has a nonzero charge (the field would be infinite
   *  or meaningless); std::runtime_error if build() was not called. */
  void evaluate(const double *q, double *pot, double *ex, double *ey, double *ez, int part = 0, int nparts = 1,
                const PartSum &sum = nullptr);

  /** @brief evaluate() with point dipoles among the sources (doc/polarization.md, section 5):
   *  the potential pot_i = sum_j [q_j / r_ij + p_j . r_ij / r_ij^3] (r_ij = r_i - r_j), the
   *  field and, if out.gradient is set, the field gradient at every particle, over the same
   *  images and far field as evaluate(). The self term is dropped. The dipoles enter the
   *  upward pass by their P2M (eq. (5.1)) and the near field by dipole_kernels.hpp; the
   *  gradient comes from the local expansions to second degree (eq. (5.2)) and the far
   *  field's second derivative. Work partitions as in evaluate() (no PartSum).
   *  @throws std::invalid_argument with FarField::Average (its smeared images are of charges
   *  only); CoincidentParticles if two sources coincide; as evaluate() otherwise. */
  void evaluate_dipoles(const DipoleSources &src, const FieldOutputs &out, int part = 0, int nparts = 1);

  /** @brief Per-particle potential u of the energy of the last evaluate(): the energy
   *  U = 1/2 sum_i q_i u_i is the one whose gradient is minus the applied forces q_i E_i
   *  (doc/theory.md, eq. (4.10)). u = pot, except with FarField::Average: the smeared far
   *  images do not move with the particles (an external field for them), so the energy
   *  whose gradient is the applied force is sum_i q_i phi_far(r_i), without the 1/2 of a
   *  field the particles make themselves, and u holds the average far part twice. Exact
   *  when the bed is given (Options::bed_zlo/bed_zhi); with the automatic bed the two
   *  particles that bound it also move the bed. Written for the targets of the last
   *  evaluate()'s part, 0 elsewhere (so the parts sum like pot).
   *  @throws std::runtime_error if evaluate() was not called since the last build(). */
  void energy_potential(double *u) const;

  /** @brief Parameters and timings of the last build()/evaluate(). */
  const Stats &stats() const;

  /** @brief Options after validation, with order/theta/leaf as resolved. */
  const Options &options() const;
  /** @brief Number of particles of the last build(). */
  std::size_t size() const;
  /** @brief Bytes held (tree, lists, expansions, per-particle arrays, scratch, far-field operator). */
  std::size_t memory_bytes() const;
  /** @brief Range [first, last) of particle indices in the internal (sorted) order computed by
   *  work partition `part` of `nparts` (for tests and diagnostics). */
  void partition(int part, int nparts, std::size_t &first, std::size_t &last) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace gcfmm

#endif
