/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "fix_charge_check.h"

#include "atom.h"
#include "comm.h"
#include "error.h"
#include "force.h"
#include "modify.h"

using namespace LAMMPS_NS;

static constexpr char CHECK_ID[] = "GC_CHARGE_CHECK";

FixChargeCheck::FixChargeCheck(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), warned(false)
{
  if (narg != 3) error->all(FLERR, "Illegal fix {} command: takes no arguments", style);
}

void FixChargeCheck::ensure(LAMMPS *lmp)
{
  if (lmp->modify->get_fix_by_id(CHECK_ID)) return;
  lmp->modify->add_fix(std::string(CHECK_ID) + " all " + CHECK_ID);
}

void FixChargeCheck::init()
{
  if (warned || !atom->q_flag || force->kspace || force->pair_match("coul", 0)) return;
  if (!modify->get_fix_by_style("^coul/fmm").empty() ||
      !modify->get_fix_by_style("^efield").empty())
    return;
  int charged = 0, any = 0;
  for (int i = 0; i < atom->nlocal && !charged; i++) charged = atom->q[i] != 0.0;
  MPI_Allreduce(&charged, &any, 1, MPI_INT, MPI_MAX, world);
  if (!any) return;
  warned = true;
  if (comm->me == 0)
    error->warning(FLERR, "Atoms carry charges, but no Coulomb interaction is computed (no "
                          "fix coul/fmm, kspace or pair style with coul): define fix coul/fmm "
                          "to include them");
}
