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

// Sleeping particles for granular beds (doc/fix_sleep_gran.md): a particle of the group that has
// been at rest (speed, surface spin speed and net force below thresholds) for a stated time, and
// optionally lies deep enough below the local bed surface, sleeps: velocity, spin, force and
// torque are held at zero, so the integrator leaves it in place, and pair_style granular/opt
// skips the contacts between two sleepers (their history is kept). Contacts of an awake particle
// with a sleeper are computed as usual: the sleeper is a fixed body of its own shape. A sleeper
// wakes, with the sleepers touching it, when the contact force from its awake partners exceeds
// the wake threshold. Falling asleep is committed every `every` steps, waking on the step.
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

  // for pair_style granular/opt and fix coul/fmm: 1.0 for a sleeping atom (local and ghost
  // atoms; ghosts are current from pre_force() on), 0.0 awake
  const double *sleeping() const { return asleep; }
  // changes whenever the sleeping set may have changed on any rank (the same on all ranks)
  bigint generation() const { return set_generation; }
  // per atom (local and ghost): contact force on a sleeper from its awake partners, summed
  // by the pair style into this array (zeroed in pre_force)
  double **awake_push() { return push; }
  // per atom (local and ghost): contacts the pair style computed this step (zeroed in
  // pre_force); only an atom that touches another can fall asleep
  double *contact_count() { return ncontact; }
  bigint sleeping_count() const { return nsleeping_all; }

 private:
  double speed_sleep, force_sleep, force_wake, rest_time, depth;
  int every, rest_steps_needed;
  bool rest_rule;    // time none: only the depth rule

  double *asleep;        // 1.0 sleeping, 0.0 awake (local + ghost)
  double *rest_steps;    // consecutive steps at rest (local)
  double **push;         // force from awake contact partners (local + ghost)
  double *wake_mark;     // reverse-communicated wake requests (local + ghost)
  double *ncontact;      // computed contacts this step (local + ghost)
  int comm_mode;         // what pack_forward_comm / pack_reverse_comm move

  bigint set_generation;
  bigint nsleeping_all, nsleep_events, nwake_events;
  int pair_checked;

  void exchange_flags();
  bool at_rest(int i) const;
  void fall_asleep();
  void wake_pushed();
  void hold_sleepers();
  void surface_heights(std::vector<double> &top, int &nbx, int &nby) const;
  int column_of(const double *x, int nbx, int nby) const;
  void count_sleeping();
  void check_fix_order();
};

}    // namespace LAMMPS_NS

#endif
#endif
