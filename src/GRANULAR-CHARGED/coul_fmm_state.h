/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

// The per-atom state of fix coul/fmm and its one owner: the field applied to each atom (and,
// with efield, polarize or electrode, the force), and the row of the last evaluation that the
// multiple time stepping continues (CoulFMMTimeStepping::Column). It grows, copies, migrates
// and restarts the columns; the fix, the time stepping, the near refresh and the evaluator use
// it through the named accessors below.

#ifndef LMP_COUL_FMM_STATE_H
#define LMP_COUL_FMM_STATE_H

#include "coul_fmm_comm.h"
#include "coul_fmm_time_stepping.h"
#include "pointers.h"

#include <cstdint>
#include <functional>

namespace LAMMPS_NS {

class CoulFMMState : protected Pointers {
  using MTS = CoulFMMTimeStepping;

 public:
  // field_cols: 4 (Ex, Ey, Ez, phi) or 7 (and the induced dipole); groupbit: the fix's group
  CoulFMMState(class LAMMPS *, int field_cols, int groupbit);
  ~CoulFMMState() override;

  // ---- the columns (Fix::grow_arrays and the other per-atom callbacks) ----
  void grow(int nmax);
  void copy(int i, int j);
  void clear(int i);    // a created atom: no stored field, charge 0 at the "evaluation"
  int exchange_size() const { return field_cols + MTS::COLS; }
  int pack_exchange(int i, double *buf) const;
  int unpack_exchange(int i, const double *buf);
  static int restart_size() { return 5 + MTS::COLS; }
  int pack_restart(int i, double *buf) const;
  // the values of this fix in atom->extra[i], starting with their count
  void unpack_restart(int i, const double *values);
  double memory_usage() const;

  // ---- named accessors ----
  int columns() const { return field_cols; }
  double *field(int i) { return applied[i]; }    // Ex, Ey, Ez, phi (, dipole) applied
  double **field_rows() { return applied; }      // LAMMPS's per-atom output (array_atom)
  double *force_on(int i) { return applied_force[i]; }    // the force applied to atom i
  double **force_rows() { return applied_force; }
  double *evaluation(int i) { return row[i]; }    // the CoulFMMTimeStepping row
  const double *evaluation(int i) const { return row[i]; }
  double *evaluated_field(int i) { return &row[i][MTS::FIELD]; }
  double charge_then(int i) const { return row[i][MTS::Q]; }
  bool static_source_then(int i) const { return row[i][MTS::ASLEEP] != 0.0; }
  const double *position_applied(int i) const { return &row[i][MTS::LAST_X]; }
  // the evaluated field becomes the applied one (the atoms' first field columns)
  void apply_evaluated(int i);
  // the local atoms' charges when a field was applied: the next step counts the charges changed
  void remember_charges();
  // where the local atoms are when a field was applied: a later run continues the stored field
  // only from those positions. `now` false: the positions of the dynamics' last step, taken when
  // they are needed (settle_positions at the end of the run, a restart file written meanwhile),
  // as the atoms do not move between a step's forces and its end
  void remember_positions(bool now);
  void settle_positions();
  // before an evaluation: every charge of the group is finite, else an error naming the atom
  // (a NaN or inf charge would make every field and force NaN)
  void check_charges(const char *fix_id) const;

  // ---- the continuity record: what the stored evaluation belongs to ----
  // asleep_now(i): atom i is a static source now (fix sleep/gran with static sleepers)
  using Predicate = std::function<bool(int)>;
  // before an evaluation: the charges, step, Coulomb constant, boundary and cell it is of
  void record(CoulFMMTimeStepping &scheme, int boundary);
  // how the stored evaluation relates to the atoms now; also takes charge_changes()
  CoulFMMTimeStepping::Continuity continuity(const CoulFMMTimeStepping &scheme, int boundary,
                                             const Predicate &asleep_now);
  // the charges found by the last continuity(), summed over the ranks
  struct ChargeChanges {
    double since_applied = 0.0;    // atoms whose charge changed since a field was last applied
    double absorbed = 0.0;         // atoms absorbing a change (CoulFMMTimeStepping::absorbs)
    double absorbed_now = 0.0;     // of those, the ones whose charge changed since last applied
    double sum_abs_dq = 0.0;       // sum |q - q_then| over the absorbing atoms
    double net_dq = 0.0;           // sum (q - q_then) over them
  };
  const ChargeChanges &charge_changes() const { return changes; }
  // sum q^2 |E|^2 and sum q^2 over the charged atoms of the evaluation (not static sources),
  // all ranks: the field scale of CoulFMMTimeStepping::set_field_scale
  void field_scale_sums(double sums[2]);
  // at the start of a run: continuity(), and NONE also when an atom of the evaluation was moved
  // since the field was last applied (displace_atoms, set)
  CoulFMMTimeStepping::Continuity continuation(const CoulFMMTimeStepping &scheme, int boundary,
                                               const Predicate &asleep_now);
  // the checksum of the evaluation's charges is taken afresh at its next use: the atoms changed,
  // or a run starts (their tags may have been changed in between)
  void forget_hashes() { hashes_nlocal = -1; }

 private:
  int field_cols;
  int groupbit;
  double **applied, **applied_force, **row;
  CoulFMMComm mpi;
  ChargeChanges changes;
  // positions of the last applied field still to be taken (remember_positions(false))
  bool positions_pending;
  // this rank's sum of coul_fmm_charge_hash over the evaluation's charges (continuity): it
  // changes only with the atoms (created, deleted, migrated, sorted, read: the per-atom
  // callbacks) or with an evaluation, so it is kept until one of those
  uint64_t hashes_local;
  int hashes_nlocal;    // -1: not known
  void cell(double box[4]) const;
  uint64_t local_hashes();
};

}    // namespace LAMMPS_NS

#endif
