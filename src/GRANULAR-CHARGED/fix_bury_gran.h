/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#ifdef FIX_CLASS
// clang-format off
FixStyle(bury/gran,FixBuryGran);
// clang-format on
#else

#ifndef LMP_FIX_BURY_GRAN_H
#define LMP_FIX_BURY_GRAN_H

#include "fix.h"

#include <vector>

namespace LAMMPS_NS {

// Buried sleepers leave LAMMPS's per-atom work (doc/fix_bury_gran.rst). The fix keeps a group
// (the one of atom_modify first, neigh_modify include and comm_modify group) equal to the awake
// atoms, the atoms outside the fix group and the sleepers with an awake atom within `halo`; the
// other sleepers are buried: LAMMPS does not bin them, list them, send them as ghosts or
// integrate them. The contact histories of buried pairs are kept
// per atom by this fix and given back to the pair's fix NEIGH_HISTORY when both atoms rejoin.
class FixBuryGran : public Fix {
 public:
  FixBuryGran(class LAMMPS *, int, char **);
  ~FixBuryGran() override;
  int setmask() override;
  void init() override;
  void setup_pre_exchange() override;
  void pre_exchange() override;
  void setup_pre_neighbor() override;
  void pre_neighbor() override;
  void end_of_step() override;
  double compute_vector(int) override;
  double memory_usage() override;
  // "sleep" (dim 0, char *): the ID of the fix sleep/gran whose sleepers this fix buries
  void *extract(const char *, int &) override;

  void grow_arrays(int) override;
  void copy_arrays(int, int, int) override;
  void set_arrays(int) override;
  int pack_exchange(int, double *) override;
  int unpack_exchange(int, double *) override;
  int pack_restart(int, double *) override;
  void unpack_restart(int, int) override;
  int size_restart(int) override;
  int maxsize_restart() override;

 private:
  char *id_sleep;
  int active_group, active_bit;
  double halo;

  class Fix *sleep_fix;
  class FixNeighHistory *history;    // the pair's contact histories (null: none kept)
  int dnum;                          // values per contact history
  bigint seen_generation;

  // per atom: kept contact histories, (partner tag, dnum values) per contact
  std::vector<std::vector<double>> kept;
  int restart_dnum;    // values per contact of the histories read from a restart (-1: none)

  bigint nactive, nburied, nrecompute, nforced;

  bool apply_rule();
  void keep_and_restore_histories();
  void update_maxexchange();
};

}    // namespace LAMMPS_NS

#endif
#endif
