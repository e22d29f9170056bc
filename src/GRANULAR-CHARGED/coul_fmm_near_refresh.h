/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

// The LAMMPS side of fix coul/fmm's near refresh (doc/theory.md, eq. (5.3)): the neighbor list
// of the pairs closer than the near cutoff, the atoms' displacements since the evaluations
// (forward-communicated to the ghosts through the fix) and the sum over the pairs; the pair
// formula itself is CoulFMMTimeStepping::near_pair_change.

#ifndef LMP_COUL_FMM_NEAR_REFRESH_H
#define LMP_COUL_FMM_NEAR_REFRESH_H

#include "pointers.h"

#include "gcsimd/simd.hpp"

#include <utility>
#include <vector>

namespace LAMMPS_NS {
class CoulFMMTimeStepping;

class CoulFMMNearRefresh : protected Pointers {
 public:
  CoulFMMNearRefresh(class LAMMPS *, class Fix *owner);
  ~CoulFMMNearRefresh() override;

  // a half list without newton (each pair once per rank that owns one of its atoms, so no
  // reverse communication) of the pairs closer than cutoff, ghosts out to it
  void request(double cutoff);
  void set_list(class NeighList *ptr) { list = ptr; }

  // C sum_j q_j (change of (K, 1/r) of pair ij since the evaluation) for the local atoms of the
  // group into now() (trend >= 0: between evaluations) or then() (trend < 0: the D of a slope)
  void compute(const CoulFMMTimeStepping &scheme, const class CoulFMMState &state, bool into_then,
               double trend);
  // the evaluation state changed (an evaluation, a new run): the held pairs are taken afresh
  void forget_pairs() { held_valid = false; }
  // after compute() between evaluations, on this rank: a pair closer than the near cutoff at
  // the evaluation is now farther than the cutoff + skin/2. A list holds such a pair only while
  // it is within the cutoff + skin when the list is built, so the field must be evaluated
  // afresh now: a list built later would no longer refresh it, and its field would fall back
  // to the one of the evaluation on a step that depends on when the lists are built. Found
  // here, the pair is in every list whenever built (an atom moves less than skin/4 per step).
  bool pair_leaving() const { return leaving; }
  // at an evaluation: the number of charged pairs closer than the near cutoff (the pairs the
  // refresh must hold until the next evaluation). A list built later that holds fewer of them
  // (an atom moved more than skin/4 in a step, so a pair passed near + skin/2 and the list's
  // cutoff between two steps) sets pair_leaving(): the field is evaluated afresh, whatever the
  // atoms' speed.
  void record_evaluation(double near_cutoff);
  double **now() const { return near_now; }
  double **then() const { return near_then; }

  // the local atoms' charges to their ghosts: a style that changes charges within a run may
  // change the local atoms' only, and the refresh sums the ghosts' charges (called on the steps
  // on which a charge changed)
  void share_charges();

  // the owner fix's forward communication of the displacements (or of the charges)
  int pack(int n, int *list_send, double *buf) const;
  void unpack(int n, int first, const double *buf);
  double memory_usage() const;

 private:
  class Fix *fix;
  class NeighList *list;
  double **delta, **near_now, **near_then;
  bool sending_charges;    // forward communication: the charges (share_charges), not delta
  int nmax_delta, nmax_out;
  // the pairs of one compute() as arrays (gcfmm::charge_pair_change): separations now and at
  // the evaluation, the kernel differences and the squared separations, in pair_buffer
  // (compute_held: the separations now, their terms (gcfmm::charge_terms_at) in pair_dg)
  std::vector<double> pair_buffer;
  double *pair_now[3], *pair_then[3], *pair_dg[4], *pair_r2now, *pair_r2then;
  std::vector<int> pair_j;                      // the pairs' second atoms
  std::vector<std::pair<int, int>> pair_i;      // each first atom and the end of its pairs
  gcsimd::SimdPath simd_path;
  void grow_pairs(int n);
  void exchange_displacements(const class CoulFMMState &state);
  bool charged(int i) const;    // of the fix's group, with a charge
  template <typename Visit, typename DoneWith>
  void for_each_charged_separation(Visit &&visit, DoneWith &&done_with) const;
  template <typename Visit, typename DoneWith>
  void for_each_charged_pair(Visit &&visit, DoneWith &&done_with) const;
  void compute_all(const CoulFMMTimeStepping &scheme, double trend, double **out);

  // Between evaluations a pair's separation at the evaluation, now - (Delta_i - Delta_j), does
  // not change while the atoms do not wrap (only when the lists are built), nor does the change
  // its slope carries: they are taken once per list build and evaluation (held), and each step
  // only the separation now is computed, without the displacements or their communication.
  struct HeldPair {
    int j;
    double qi_then, qj_then;       // the two charges at the evaluation (absorbed changes)
    double r2then;                 // squared separation at the evaluation
    double terms_then[4];          // (K, 1/r) at the evaluation
    double slope_change[4];        // CoulFMMTimeStepping::slope_pair_change
  };
  std::vector<HeldPair> held;
  std::vector<std::pair<int, int>> held_i;      // each first atom and the end of its pairs
  // what the held pairs belong to: the neighbor build (count and step), the evaluation state
  // (forget_pairs) and the box (atoms unmap with it)
  bool held_valid;
  bool leaving;
  // pairs closer than the cutoff at the evaluation, over all ranks (a pair whose second atom
  // is a ghost counts 1/2 on each rank that holds it); -1 while unknown (after a restart)
  double near_pairs_evaluated;
  bool pairs_lost;
  bigint held_ncalls, held_lastcall;
  double held_box[9];
  void box_now(double box[9]) const;
  bool holds_current() const;
  void hold_pairs(const CoulFMMTimeStepping &scheme, const class CoulFMMState &state);
  void compute_held(const CoulFMMTimeStepping &scheme, double trend, double **out);
};

}    // namespace LAMMPS_NS

#endif
