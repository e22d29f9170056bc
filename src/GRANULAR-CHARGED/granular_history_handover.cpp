/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "granular_history_handover.h"

#include "atom.h"
#include "comm.h"
#include "error.h"
#include "fix_neigh_history.h"
#include "modify.h"
#include "neigh_history_arrays.h"
#include "pair.h"
#include "update.h"
#include "utils.h"

#include <cstring>
#include <string>
#include <vector>

using namespace LAMMPS_NS;

/* ----------------------------------------------------------------------
   Modify keeps the stored entries of a restart file in protected members: a derived class may
   form pointers to them
------------------------------------------------------------------------- */

namespace {
struct StoredFixData : Modify {
  static char **Modify::*ids() { return &StoredFixData::id_restart_peratom; }
  static char **Modify::*styles() { return &StoredFixData::style_restart_peratom; }
  static int *Modify::*used() { return &StoredFixData::used_restart_peratom; }
};

// the stored histories of pair styles granular and granular/opt no fix has taken
std::vector<int> unclaimed_histories(Modify *modify)
{
  std::vector<int> found;
  char **ids = modify->*StoredFixData::ids();
  char **styles = modify->*StoredFixData::styles();
  int *used = modify->*StoredFixData::used();
  for (int k = 0; k < modify->nfix_restart_peratom; k++)
    if (!used[k] && strcmp(styles[k], "NEIGH_HISTORY") == 0 &&
        utils::strmatch(ids[k], "^NEIGH_HISTORY_GRANULAR\\d*$") && !modify->get_fix_by_id(ids[k]))
      found.push_back(k);
  return found;
}

// was fix `id` given its values by the restart file just read (even an empty history)?
bool restored_from_restart(Modify *modify, const char *id)
{
  char **ids = modify->*StoredFixData::ids();
  int *used = modify->*StoredFixData::used();
  for (int k = 0; k < modify->nfix_restart_peratom; k++)
    if (used[k] && strcmp(ids[k], id) == 0) return true;
  return false;
}

bigint history_contacts(LAMMPS *lmp, FixNeighHistory *history)
{
  // the number of contacts (partners) the history holds for each local atom after a run
  const int *count = neigh_history_arrays(history).npartner;
  bigint mine = 0;
  for (int i = 0; count && i < lmp->atom->nlocal; i++) mine += count[i];
  bigint all = 0;
  MPI_Allreduce(&mine, &all, 1, MPI_LMP_BIGINT, MPI_SUM, lmp->world);
  return all;
}
}    // namespace

/* ---------------------------------------------------------------------- */

void GranularHistoryHandover::adopt_stored_history(char *&id_history)
{
  const auto stored = unclaimed_histories(modify);
  char **ids = modify->*StoredFixData::ids();
  for (int k : stored)
    if (strcmp(ids[k], id_history) == 0) return;
  if (stored.size() > 1)
    error->warning(FLERR, "Pair granular/opt: {} contact histories in the restart file, none "
                   "of this style's name {}: it starts with none", stored.size(), id_history);
  if (stored.size() != 1) return;
  delete[] id_history;
  id_history = utils::strdup(ids[stored.front()]);
}

/* ---------------------------------------------------------------------- */

void GranularHistoryHandover::history_created(const FixNeighHistory *history)
{
  if (!history) return;
  fresh = !restored_from_restart(modify, history->id);
  fresh_checked = false;
}

/* ----------------------------------------------------------------------
   a history created empty after step 0 on touching pairs (a switch from pair_style granular
   within one input, or a bed read from a dump): every contact starts afresh, which is a
   different answer from a run that kept its contacts; say so once
------------------------------------------------------------------------- */

void GranularHistoryHandover::warn_fresh_history(bigint touching)
{
  fresh_checked = true;
  if (!fresh || update->ntimestep == 0) return;
  bigint all = 0;
  MPI_Allreduce(&touching, &all, 1, MPI_LMP_BIGINT, MPI_SUM, world);
  if (all > 0 && comm->me == 0)
    error->warning(FLERR,
                   "Pair granular/opt starts at step {} with {} touching pairs and no contact "
                   "history: each starts afresh (no tangential, rolling or twisting spring, the "
                   "JKR loading branch). A switch from pair_style granular within one input "
                   "loses the history; a restart read with granular/opt keeps it",
                   update->ntimestep, all);
}

/* ----------------------------------------------------------------------
   a history that other styles cannot take is reported; a stored one nobody claimed is named
   for the pair style instance created next
------------------------------------------------------------------------- */

void GranularHistoryHandover::pair_deleted(FixNeighHistory *history)
{
  // LAMMPS deletes update before the pair style at its end: then nothing follows this style
  if (!update) return;
  if (history) {
    const bigint lost = history_contacts(lmp, history);
    if (lost > 0 && comm->me == 0)
      error->warning(FLERR,
                     "Pair granular/opt deleted with {} contacts in its history: a pair style "
                     "defined now starts them afresh (no tangential, rolling or twisting spring, "
                     "no JKR branch); write_restart, then read_restart and the other style, "
                     "keeps them",
                     lost);
    return;
  }
#if GC_LAMMPS_VERSION >= 20260704
  const auto stored = unclaimed_histories(modify);
  if (stored.size() == 1) {
    char *&id = (modify->*StoredFixData::ids())[stored.front()];
    delete[] id;
    id = utils::strdup("NEIGH_HISTORY_GRANULAR" + std::to_string(Pair::instance_total));
  }
#endif
}
