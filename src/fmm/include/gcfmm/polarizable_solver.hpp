// GRANULAR-CHARGED FMM core library (gcfmm).
// Charged, polarizable particles by the FMM: a uniform applied field, induced point dipoles
// solved self-consistently (mutual induction, warm-started), a grounded electrode by image
// sources in the same tree, forces q E + G p and the energy of doc/polarization.md, eq. (3.4).
// The FMM counterpart of direct_polarizable.hpp (its reference), over Solver::evaluate_dipoles.
#ifndef GCFMM_POLARIZABLE_SOLVER_HPP
#define GCFMM_POLARIZABLE_SOLVER_HPP

#include <cstddef>
#include <vector>

#include "gcfmm/options.hpp"
#include "gcfmm/polarization.hpp"
#include "gcfmm/solver.hpp"
#include "gcfmm/types.hpp"

namespace gcfmm {

//! What surrounds the particles (bare units).
struct PolarizableEnvironment {
  Vec3 applied_field;         //!< uniform applied field
  bool electrode = false;     //!< a grounded conducting plane z = electrode_z below every particle
  double electrode_z = 0.0;
};

//! Per-particle results of PolarizableSolver::compute (caller's order; 3 per particle for vectors).
struct PolarizableOutputs {
  std::vector<double> field;   //!< total field E at each particle (applied field included), 3 n
  std::vector<double> force;   //!< q E + G p, 3 n
  std::vector<double> energy;  //!< per-particle terms of eq. (3.4) (they sum to the energy), n
};

/** Usage: PolarizableSolver s(opts); s.set_box(...) (periodic); s.set_environment(env);
 *  s.compute(n, x, y, z, q, alpha, p, out) once per step, p holding the last step's dipoles.
 *  With an electrode the tree holds the particles and their mirror images (2 n sources),
 *  images of charges -q and of dipoles (-px, -py, pz) (dipole_kernels.hpp). */
class PolarizableSolver {
 public:
  /** @param dipoles whether compute() will be given polarizabilities. Their forces G p need the
   *  field gradient, whose error at a given expansion order is larger than the field's
   *  (doc/benchmarks.md, "Induced dipoles"): the expansions are then chosen for
   *  Options::accuracy divided by gcfmm::dipole_accuracy_margin() (an order given explicitly
   *  is kept). The induction stops at gcfmm::induction_tolerance(opts). */
  explicit PolarizableSolver(const Options &opts, bool dipoles = true);
  /** @brief Periodic2D: the primary cell (Solver::set_box). */
  void set_box(double xlo, double ylo, double lx, double ly);
  /** @brief Periodic2D with FarField::Exact: the z range the far field covers (Solver::
   *  set_z_range); with an electrode the mirror of the range is added. */
  void set_z_range(double zlo, double zhi);
  /** @throws std::invalid_argument if a component of the field or electrode_z is not finite. */
  void set_environment(const PolarizableEnvironment &env);
  /** @brief The induction's stopping rule (default: residual gcfmm::induction_tolerance() of
   *  the options): a start within `tolerance` is accepted, iterations go on to tolerance / 4. */
  void set_induction(const PolarizationSettings &settings);
  /** @brief The induction's residual in use (set_induction()'s tolerance). */
  double induction_tolerance() const { return induction_.accept_start; }
  /** @brief Split every evaluation among nparts callers running at once (e.g. MPI ranks):
   *  each computes the targets of its work partition (Solver::evaluate_dipoles) and `sum`
   *  adds the callers' results in place (each value is nonzero on one caller only, so the
   *  result is bit-identical to nparts = 1). All callers then hold the same fields and solve
   *  the same induction. Default: one part.
   *  @throws std::invalid_argument unless 0 <= part < nparts and, for nparts > 1, sum is set */
  void set_partition(int part, int nparts, PartSum sum);

  /** @brief Dipoles, fields, forces and energy of n particles with charges q and
   *  polarizabilities alpha (null: none, p = 0). p (3 n): in, the starting dipoles (warm
   *  start); out, the solution. Evaluations: one of the charges and the starting dipoles,
   *  one per induction iteration, and a last one with the field gradient;
   *  report().iterations counts them all but the last. When the last call's start already
   *  solved (3.3) (a good prediction of the dipoles, e.g. extrapolated from the last two
   *  steps), the start's evaluation carries the gradient, and if the start solves (3.3) again
   *  it is the only evaluation.
   *  @throws std::invalid_argument if a particle is at or below the electrode, or as
   *  solve_induced_dipoles(); CoincidentParticles as Solver::evaluate_dipoles. */
  void compute(std::size_t n, const double *x, const double *y, const double *z, const double *q,
               const double *alpha, double *p, PolarizableOutputs &out);

  const PolarizationReport &report() const { return report_; }  //!< the last induction solve
  int evaluations() const { return evaluations_; }  //!< FMM evaluations of the last compute()
  double energy() const { return energy_; }                      //!< total energy of the last compute()
  const Stats &stats() const { return solver_.stats(); }        //!< the FMM's last evaluation
  const Options &options() const { return solver_.options(); }

 private:
  // field at the n particles of the sources q (2 n with images) and dipoles p (3 n, or null),
  // into pot, ex, ey, ez (2 n each) and g (6 x 2 n, or none)
  void evaluate(const double *p, bool charges, bool gradient);
  Solver solver_;
  int part_ = 0, nparts_ = 1;
  bool start_converged_ = false;  // the last compute()'s start already solved (3.3)
  int evaluations_ = 0;
  PartSum sum_;
  std::vector<double> buffer_;  // the results of the n particles, summed over the parts
  PolarizableEnvironment env_;
  PolarizationSettings induction_;
  PolarizationReport report_;
  double energy_ = 0.0;
  std::size_t n_ = 0;
  std::vector<double> sx_, sy_, sz_, sq_, spx_, spy_, spz_;  // sources (particles, then images)
  std::vector<double> pot_, ex_, ey_, ez_, g_;                // results at the sources
};

}  // namespace gcfmm

#endif
