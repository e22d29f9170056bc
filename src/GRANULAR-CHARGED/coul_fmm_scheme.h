/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

// What fix coul/fmm asks of its Coulomb computation, whatever it is: the charges with the
// multiple time stepping (CoulFMMChargeScheme) or charges with an applied field, induced
// dipoles and an electrode (CoulFMMPolarizable). The fix holds one and calls it on the LAMMPS
// hooks; both write their fields and forces into the fix's CoulFMMState.
//
// Both continue the field between full evaluations by one rule, compute(): a minimizer's trial
// positions are evaluated afresh; otherwise the last evaluation is continued to the atoms now
// unless an evaluation is due or the continuation cannot follow the atoms. What is continued,
// and how, is each scheme's own: the charges' field (far part extrapolated, near pairs refreshed
// over the neighbor lists, doc/theory.md, section 5), or the forces of charges and dipoles with
// the dipoles held (near pairs' change over the gathered atoms, doc/polarization.md, section 8;
// the dipoles follow the field, so they cannot share the charges' field continuation).

#ifndef LMP_COUL_FMM_SCHEME_H
#define LMP_COUL_FMM_SCHEME_H

namespace gcfmm {
struct Options;
}    // namespace gcfmm

namespace LAMMPS_NS {
class CoulFMMBackend;
class CoulFMMNearRefresh;
class CoulFMMState;
class CoulFMMTimeStepping;
class Fix;

class CoulFMMScheme {
 public:
  // keyword qchange: evaluate the field when a charge changes, absorb the change (doc/theory.md,
  // eq. (5.5)), or absorb when a fix declares charge transfers (the default)
  enum class QChange { AUTO, EVALUATE, ABSORB };

  // the fix's parts a scheme works with (kept by the fix)
  struct Parts {
    Fix *fix;
    const gcfmm::Options *opts;
    CoulFMMTimeStepping *stepping;
    CoulFMMState *state;
    CoulFMMBackend *backend;
    CoulFMMNearRefresh *near;
    bool sleepers_static;    // keyword sleepers static
    bool distributed;        // keyword solver distributed
    QChange qchange;         // keyword qchange
  };

  // the solver's side of the last evaluation (the same on every rank): vector elements 1-4,
  // 11-14 of doc/fix_coul_fmm.rst, "Output"
  struct Diagnostics {
    double estimated_error = 0.0, theta = 0.0;
    int order = 0, leaf = 0;
    double m2l = 0.0, p2p = 0.0;      // interactions of all ranks together
    double bytes_received = 0.0;      // largest over the ranks, all collectives of the evaluation
    double solver_memory = 0.0;       // largest over the ranks
    double charges = 0.0;             // charged atoms evaluated
    int iterations = 0;               // induction iterations (polarize)
    double residual = 0.0;            // induction residual (polarize)
  };

  virtual ~CoulFMMScheme() noexcept(false) = default;    // as Pointers, which schemes derive from
  // checks of the settings against the other styles, and the solver (the fix's own checks done)
  virtual void init() = 0;
  // at a run's setup: the schedule goes on from the stored state (unchanged, or changed only by
  // a known change that the first step evaluates); else it starts again
  virtual bool continues() = 0;
  // the forces of this step (CoulFMMState::force) and the fields; predict false: a minimizer's
  // trial positions (a fresh evaluation, nothing continued, whatever the keyword every).
  // Returns this rank's energy.
  double compute(bool predict)
  {
    if (!predict) return evaluate(Evaluation::FRESH);
    if (evaluation_due()) return evaluate(Evaluation::SCHEDULED);
    double energy = 0.0;
    if (continue_last(energy)) return energy;
    return evaluate(Evaluation::BROUGHT_FORWARD);
  }
  // atom i (local) receives a force
  virtual bool acts_on(int i) const = 0;
  // the energy of all atoms (the ranks' sums of compute()) plus what no atom's force carries
  // (the static sleepers' pairs)
  virtual double total_energy(double atoms) { return atoms; }
  virtual const Diagnostics &diagnostics() const = 0;
  virtual double evaluations() const = 0;
  virtual double memory_usage() const = 0;

 protected:
  // why a full evaluation is made: a minimizer's trial positions (nothing continued, nothing
  // adapted), the schedule (or other atoms or charges), or a continuation that cannot follow
  // the atoms (brought forward: its span is shorter than the interval)
  enum class Evaluation { FRESH, SCHEDULED, BROUGHT_FORWARD };
  // an evaluation is due on this step: the schedule's steps, and whenever the last one no
  // longer belongs to these atoms and charges
  virtual bool evaluation_due() = 0;
  // the last evaluation continued to the atoms now, its forces and fields written and this
  // rank's energy in `energy`; false (nothing applied) when it cannot follow them (every rank
  // answers the same)
  virtual bool continue_last(double &energy) = 0;
  // a full evaluation, its forces and fields written; returns this rank's energy
  virtual double evaluate(Evaluation why) = 0;
};

}    // namespace LAMMPS_NS

#endif
