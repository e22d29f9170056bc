/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

// The contact history of pair_style granular/opt handed over across a switch of pair style and
// across restarts. The history of granular and granular/opt is one fix NEIGH_HISTORY with the
// same per-pair values. LAMMPS names it NEIGH_HISTORY_GRANULAR<n> after the pair style's
// instance (from 4Jul2026 on), and read_restart restores it only into a fix of the stored name:
// a restart written by one style and read with the other (a new instance) would start every
// contact afresh. So granular/opt takes over a stored history that no fix has claimed when it
// creates its own, and, when it is deleted for a style given after read_restart, renames the
// stored history for the instance created next. Where a history is lost (a switch within one
// input), it says so.

#ifndef LMP_GC_GRANULAR_HISTORY_HANDOVER_H
#define LMP_GC_GRANULAR_HISTORY_HANDOVER_H

#include "pointers.h"

namespace LAMMPS_NS {

class FixNeighHistory;

class GranularHistoryHandover : protected Pointers {
 public:
  explicit GranularHistoryHandover(LAMMPS *lmp) : Pointers(lmp) {}

  // before the pair's first init_style() creates its history fix named id_history (LAMMPS
  // 4Jul2026 on: one name per pair style instance): takes over the one stored history no fix
  // has claimed if none has that name (id_history renamed)
  void adopt_stored_history(char *&id_history);
  // after that first init_style(): notes whether the fix created started empty
  void history_created(const FixNeighHistory *history);
  // from the pair's compute(): on the first after history_created(), warns if the history
  // started empty and meets touching pairs after step 0 (touching: those of this rank)
  void check_fresh_history(bigint touching)
  {
    if (!fresh_checked) warn_fresh_history(touching);
  }
  // from the pair's destructor (history: its fix, or null if it never made one)
  void pair_deleted(FixNeighHistory *history);

 private:
  void warn_fresh_history(bigint touching);

  bool fresh = false;            // the history fix was created empty by the pair's first init
  bool fresh_checked = true;     // the touching pairs of a fresh history were counted
};

}    // namespace LAMMPS_NS

#endif
