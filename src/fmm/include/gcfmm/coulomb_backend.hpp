// GRANULAR-CHARGED FMM core library (gcfmm).
// One interface over the library's Coulomb solvers, in the shape of ScaFaCoS's solver handle:
// set the cell and its z range, evaluate, read the energy potential and the statistics. A
// caller (the LAMMPS fix) holds one CoulombBackend whatever the solver: the replicated Solver
// (every caller holds all particles and computes its share of the targets), the
// DistributedSolver (every caller holds its own particles) or the PolarizableSolver (charges
// with induced dipoles, an applied field and an electrode).
#ifndef GCFMM_COULOMB_BACKEND_HPP
#define GCFMM_COULOMB_BACKEND_HPP

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "gcfmm/communicator.hpp"
#include "gcfmm/distributed_solver.hpp"
#include "gcfmm/options.hpp"
#include "gcfmm/polarizable_solver.hpp"
#include "gcfmm/solver.hpp"

namespace gcfmm {

//! The particles of one evaluation (bare units).
struct BackendInput {
  std::size_t n = 0;
  const double *x = nullptr, *y = nullptr, *z = nullptr, *q = nullptr;
  const std::int64_t *ids = nullptr;  //!< global ids, for the distributed solver's errors
  const double *alpha = nullptr;      //!< polarizabilities (polarizable; null: none)
  double *p = nullptr;                //!< dipoles, 3 n (polarizable): in the start, out the solution
};

//! Results at the particles: the caller's share (BackendOutput::share), zero elsewhere.
struct BackendOutput {
  double *pot = nullptr, *ex = nullptr, *ey = nullptr, *ez = nullptr;  //!< n each
  double *force = nullptr;   //!< 3 n, q E + G p (polarizable only)
  double *energy = nullptr;  //!< n, the per-particle terms of the energy (polarizable only)
};

//! The parameters and counts of the last evaluation.
struct BackendStats {
  double estimated_error = 0.0;  //!< predicted relative RMS force error
  int order = 0;
  double theta = 0.0;
  int leaf = 0;
  double m2l = 0.0, p2p = 0.0;   //!< interactions this caller computed (see counts_whole)
  bool counts_whole = true;      //!< m2l, p2p are the whole evaluation's (else this caller's)
  double memory_bytes = 0.0;     //!< this caller's solver memory
  int iterations = 0;            //!< induction iterations (polarizable)
  double residual = 0.0;         //!< induction residual (polarizable)
  bool converged = true;         //!< the induction converged (polarizable)
};

class CoulombBackend {
 public:
  virtual ~CoulombBackend() = default;
  /** @brief Periodic2D only: the primary cell [xlo, xlo+lx) x [ylo, ylo+ly). */
  virtual void set_box(double xlo, double ylo, double lx, double ly) = 0;
  /** @brief Periodic2D with FarField::Exact: a z range the far field covers (Solver::set_z_range). */
  virtual void set_z_range(double zlo, double zhi) = 0;
  /** @brief The field of all particles at the caller's targets (bare 1/r kernel); the
   *  conventions and exceptions of the solver behind it. */
  virtual void evaluate(const BackendInput &in, const BackendOutput &out) = 0;
  /** @brief Per-particle potential u of the last evaluate(), with energy 1/2 sum_i q_i u_i
   *  (Solver::energy_potential; polarizable: u_i = 2 e_i / q_i, 0 for q_i = 0, whose own
   *  energy is in BackendOutput::energy). */
  virtual void energy_potential(double *u) const = 0;
  virtual BackendStats stats() const = 0;
  /** @brief true: each caller passes its own particles; false: every caller passes all. */
  virtual bool distributed() const = 0;
  /** @brief The particles [first, last) of n whose results this caller computes and owns. */
  virtual void share(std::size_t n, std::size_t &first, std::size_t &last) const;
};

//! Solver on every caller's copy of all particles; caller `part` of `nparts` computes its share
//! of the targets, `sum` (may be null for one part) completes the shared far-field work.
class ReplicatedBackend : public CoulombBackend {
 public:
  ReplicatedBackend(const Options &opts, int part, int nparts, PartSum sum);
  void set_box(double xlo, double ylo, double lx, double ly) override;
  void set_z_range(double zlo, double zhi) override;
  void evaluate(const BackendInput &in, const BackendOutput &out) override;
  void energy_potential(double *u) const override;
  BackendStats stats() const override;
  bool distributed() const override { return false; }
  void share(std::size_t n, std::size_t &first, std::size_t &last) const override;

 private:
  Solver solver_;
  int part_, nparts_;
  PartSum sum_;
};

//! DistributedSolver: each caller (MPI rank) its own particles, collectives through `comm`.
class DistributedBackend : public CoulombBackend {
 public:
  DistributedBackend(const Options &opts, Communicator &comm);
  void set_box(double xlo, double ylo, double lx, double ly) override;
  void set_z_range(double zlo, double zhi) override;
  void evaluate(const BackendInput &in, const BackendOutput &out) override;
  void energy_potential(double *u) const override;
  BackendStats stats() const override;
  bool distributed() const override { return true; }

 private:
  DistributedSolver solver_;
};

//! PolarizableSolver: charges and induced dipoles; every caller passes all particles (its
//! evaluations split as set_partition()). The environment and the induction's settings are
//! the solver's own (solver()).
class PolarizableBackend : public CoulombBackend {
 public:
  PolarizableBackend(const Options &opts, bool dipoles);
  void set_box(double xlo, double ylo, double lx, double ly) override;
  void set_z_range(double zlo, double zhi) override;
  void evaluate(const BackendInput &in, const BackendOutput &out) override;
  void energy_potential(double *u) const override;
  BackendStats stats() const override;
  bool distributed() const override { return false; }
  PolarizableSolver &solver() { return solver_; }

 private:
  PolarizableSolver solver_;
  PolarizableOutputs last_;
  std::vector<double> charges_;  // of the last evaluate(), for energy_potential()
};

}  // namespace gcfmm

#endif
