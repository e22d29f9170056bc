/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "slab_bounds.h"

#include "error.h"
#include "lammps.h"
#include "utils.h"

#include <cstring>

using namespace LAMMPS_NS;

void LAMMPS_NS::parse_slab_bounds(LAMMPS *lmp, char **arg, int ilo, const std::string &what,
                                  double &zlo, double &zhi, int &zlo_null, int &zhi_null)
{
  zlo_null = (strcmp(arg[ilo], "NULL") == 0);
  zhi_null = (strcmp(arg[ilo + 1], "NULL") == 0);
  zlo = zlo_null ? 0.0 : utils::numeric(FLERR, arg[ilo], false, lmp);
  zhi = zhi_null ? 0.0 : utils::numeric(FLERR, arg[ilo + 1], false, lmp);
  if (!zlo_null && !zhi_null && zlo >= zhi)
    lmp->error->all(FLERR, ilo, "{} zlo {} must be < zhi {}", what, zlo, zhi);
}
