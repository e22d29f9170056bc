// GRANULAR-CHARGED FMM core library (gcfmm).
// The FMM over particles distributed among ranks: each rank holds only its own particles and
// receives a local essential tree (LET) from every other rank (doc/fmm-distributed.md).
#ifndef GCFMM_DISTRIBUTED_SOLVER_HPP
#define GCFMM_DISTRIBUTED_SOLVER_HPP

#include <cstddef>
#include <cstdint>
#include <memory>

#include "gcfmm/communicator.hpp"
#include "gcfmm/options.hpp"
#include "gcfmm/solver.hpp"

namespace gcfmm {

//! Parameters, counts and timings of the last DistributedSolver::evaluate() on this rank
//! (seconds, bytes).
struct DistributedStats {
  int order = 0;                          //!< expansion order p
  double theta = 0.0;                     //!< MAC opening angle
  int leaf = 0;                           //!< max particles per leaf
  double estimated_error = 0.0;           //!< predicted relative RMS force error (as Stats)
  std::size_t nodes = 0;                  //!< nodes of this rank's tree
  std::size_t m2l_count = 0;              //!< M2L interactions, local and remote sources (all shifts)
  std::size_t p2p_pairs = 0;              //!< particle pairs summed directly, local and remote
  std::size_t m2p_count = 0;              //!< (target particle, truncated LET node, shift) M2P evaluations
  std::size_t bytes_sent = 0;             //!< LET bytes this rank sent (all ranks together)
  std::size_t bytes_received = 0;         //!< LET bytes this rank received
  std::size_t let_nodes_received = 0;     //!< LET nodes received (all ranks)
  std::size_t let_particles_received = 0; //!< LET particles received (all ranks)
  std::size_t memory_bytes = 0;           //!< this rank's solver memory (trees, expansions, lists,
                                          //!< received LET, far-field operator, buffers, scratch)
  double t_tree = 0.0;                    //!< global geometry, tree, local lists (+ far-field set-up)
  double t_upward = 0.0;                  //!< P2M + M2M
  double t_let = 0.0;                     //!< LET construction, exchange and the remote lists
  double t_m2l = 0.0;                     //!< M2L (local and remote)
  double t_p2p = 0.0;                     //!< P2P (local and remote) and M2P
  double t_downward = 0.0;                //!< L2L + L2P
  double t_far = 0.0;                     //!< far field beyond the image shells
};

/** @brief FMM over particles distributed among the ranks of a Communicator, with exactly the
 *  conventions of Solver::evaluate() (bare 1/r kernel, self term dropped, `images` shells plus
 *  Options::farfield, zero charges are sources of nothing but get their field, any net charge).
 *  Each rank builds a tree over its own particles, computes their mutual interactions as
 *  Solver does, sends every other rank the part of its tree that rank needs (a LET: nodes far
 *  from that rank's particles as multipoles only, near ones down to their particles) and adds
 *  the field of the LETs it receives. The length unit h (a power of two) is that of the global
 *  geometry, so all ranks compute in the same units. With size() == 1 the results are
 *  bit-identical to Solver's (tested); with more ranks the near-field lists differ, so the
 *  results agree with Solver's to the requested accuracy (doc/fmm-distributed.md). Usage:
 *  DistributedSolver s(opts, comm); s.set_box(...) (periodic); s.evaluate(...) every step. */
class DistributedSolver {
 public:
  /** @throws std::invalid_argument as Options::validate() */
  DistributedSolver(const Options &opts, Communicator &comm);
  ~DistributedSolver();
  DistributedSolver(const DistributedSolver &) = delete;
  DistributedSolver &operator=(const DistributedSolver &) = delete;

  /** @brief Periodic2D only: the primary cell, as Solver::set_box() (the same on every rank). */
  void set_box(double xlo, double ylo, double lx, double ly);
  /** @brief Periodic2D only: a z range the far-field operator covers, as Solver::set_z_range(). */
  void set_z_range(double zlo, double zhi);

  /** @brief COLLECTIVE (every rank calls it, the same number of times): the field of all
   *  particles of all ranks at this rank's n particles. x, y, z, q: this rank's particles
   *  (periodic positions may lie outside the cell: they are wrapped), ids: a global id per
   *  particle (for error messages only). Writes pot, ex, ey, ez of this rank's particles with
   *  the conventions of Solver::evaluate(). n = 0 is allowed (the rank still takes part).
   *  Errors: the same sequence of Communicator calls is made on every rank whatever the data;
   *  an error caused by one rank's data is thrown on that rank after the last collective call,
   *  and the other ranks return normally (their results then lack nothing they could compute).
   *  @throws CoincidentParticles with first() < second() the two particles' ids when two
   *  distinct particles (of this rank, or of this rank and another) are closer than
   *  kCoincidenceRadius h and either is charged (thrown by a rank holding one of them);
   *  std::invalid_argument for null arrays (n > 0); std::runtime_error for non-finite
   *  positions or if Periodic2D has no set_box() (on every rank, before any collective). */
  void evaluate(std::size_t n, const double *x, const double *y, const double *z, const double *q,
                const std::int64_t *ids, double *pot, double *ex, double *ey, double *ez);

  /** @brief Per-particle energy potential of the last evaluate() for this rank's particles,
   *  as Solver::energy_potential() (U = 1/2 sum_i q_i u_i over all ranks' particles).
   *  @throws std::runtime_error if evaluate() has not completed. */
  void energy_potential(double *u) const;

  /** @brief Counts and timings of the last evaluate() on this rank. */
  const DistributedStats &stats() const;
  /** @brief Options after validation, with order/theta/leaf as resolved. */
  const Options &options() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace gcfmm

#endif
