/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#ifdef FIX_CLASS
// clang-format off
FixStyle(sleep/gran,FixSleepGran);
// clang-format on
#else

#ifndef LMP_FIX_SLEEP_GRAN_H
#define LMP_FIX_SLEEP_GRAN_H

#include "fix.h"

#include <vector>

namespace LAMMPS_NS {

// Sleeping particles for granular beds (doc/fix_sleep_gran.rst): a particle of the group that has
// been at rest (speed, surface spin speed and net force below thresholds) for a stated time, and
// optionally lies deep enough below the local bed surface, sleeps: velocity, spin, force and
// torque are held at zero after the forces, so the integrator leaves it in place. The pair style
// computes every contact as it does without this fix (keyword pairs all), or, with pairs awake
// (granular/opt only), every contact but those of two sleepers, whose histories it leaves as
// they are. A sleeper wakes, with the sleepers
// touching it, when the contact force from its awake partners exceeds the wake threshold. Falling
// asleep is committed every `every` steps, waking on the step.
//
// This fix keeps its own books for every granular pair style: it counts the contacts from the
// pair's neighbor list and contact flags and sums the push of each awake-sleeper contact with
// the pair's single(). The state is published through extract() (names below), so that other
// styles (fix coul/fmm) read it without including this header.
class FixSleepGran : public Fix {
 public:
  FixSleepGran(class LAMMPS *, int, char **);
  ~FixSleepGran() override;
  int setmask() override;
  void init() override;
  void setup_pre_force(int) override;
  void setup(int) override;
  void pre_force(int) override;
  void post_force(int) override;
  double compute_scalar() override;
  double compute_vector(int) override;
  double memory_usage() override;

  void grow_arrays(int) override;
  void copy_arrays(int, int, int) override;
  void set_arrays(int) override;
  int pack_exchange(int, double *) override;
  int unpack_exchange(int, double *) override;
  int pack_forward_comm(int, int *, double *, int, int *) override;
  void unpack_forward_comm(int, int, double *) override;
  int pack_reverse_comm(int, int, double *) override;
  void unpack_reverse_comm(int, int *, double *) override;
  void write_restart(FILE *) override;
  void restart(char *) override;
  int pack_restart(int, double *) override;
  void unpack_restart(int, int) override;
  int size_restart(int) override;
  int maxsize_restart() override;

  // "sleeping" (dim 1): 1.0 for a sleeping atom, 0.0 awake (local and ghost atoms; ghosts are
  //   current from pre_force() on)
  // "generation" (dim 0, bigint): changes whenever the sleeping set may have changed on any rank
  //   (the same on all ranks)
  // "push" (dim 2): per atom (local and ghost), the contact force on a sleeper from its awake
  //   partners (zeroed in pre_force, summed in post_force)
  // "contacts" (dim 1): per atom (local and ghost), contacts computed this step (zeroed in
  //   pre_force, counted in post_force; pairs of two sleepers not counted; for a local atom also
  //   its contacts with the walls of fix wall/gran or wall/gran/opt with a JKR model) on commit
  //   steps, and on every step with a rest time (else 0); only an atom that touches another or
  //   such a wall can fall asleep
  // "pairs_awake" (dim 0, int): 1 with keyword pairs awake (the pair style leaves out the pairs
  //   of two sleepers, by the flags of "sleeping"), 0 with pairs all
  // With a fix bury/gran of this fix, "push" and "contacts" hold no values for the local atoms
  // past atom->nfirst (the buried sleepers, which this fix does not visit each step).
  void *extract(const char *, int &) override;

 private:
  double speed_sleep, force_sleep, force_wake, rest_time, depth;
  int every, rest_steps_needed;
  bool rest_rule;    // time none: only the depth rule
  int pairs_awake;   // keyword pairs: 1 awake (granular/opt skips the pairs of two sleepers), 0 all

  double *asleep;        // 1.0 sleeping, 0.0 awake (local + ghost)
  double *pushed;        // 1.0 for a sleeper pushed beyond wake on this step (local + ghost)
  double *rest_steps;    // consecutive steps at rest (local)
  double **push;         // force from awake contact partners (local + ghost)
  double *wake_mark;     // reverse-communicated wake requests (local + ghost)
  double *ncontact;      // computed contacts this step (local + ghost)
  int comm_mode;         // what pack_forward_comm / pack_reverse_comm move

  bigint set_generation;
  // atoms that fell asleep and atoms woken since the fix was defined (kept across restarts)
  bigint fallen_asleep_total, woken_total;
  class FixNeighHistory *pair_history;    // the pair style's contact flags (null: none)
  std::vector<class FixWallGran *> walls;    // flat granular walls whose contacts count
  std::vector<double> kept_history;       // one contact's history, kept across single()
  // the entries of the pair's list with an awake atom or neighbor, and those of them with an
  // awake atom and a sleeping neighbor or the reverse (update_active_entries())
  std::vector<int> active_entries, interface_entries;
  bigint active_build, active_generation;    // the list build and sleeping set they are of
  // a fix bury/gran of this fix keeps its buried sleepers past atom->nfirst (set in init())
  bool buried_past_nfirst;

  int nvisited() const;
  bool counting_step() const;    // are this step's contacts counted

  void exchange_flags();
  void clear_push_and_contacts();
  void sum_contacts_and_push();
  void update_active_entries(const class NeighList *list);
  void mark_touching_sleepers();
  bool touching(int i, int j, int jj, const int *touch) const;
  bigint sleeping_count() const;
  bigint awake_count() const;
  bool at_rest(int i) const;
  void fall_asleep();
  void wake_pushed();
  void hold_sleepers(bool woken_too);
  void surface_heights(std::vector<double> &top, int &nbx, int &nby) const;
  void count_wall_contacts();
  int column_of(const double *x, int nbx, int nby) const;
  void check_fix_order();
};

}    // namespace LAMMPS_NS

#endif
#endif
