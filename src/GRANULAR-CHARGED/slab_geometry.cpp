/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "slab_geometry.h"

#include "domain.h"
#include "error.h"
#include "lammps.h"
#include "utils.h"

#include <cmath>
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

void LAMMPS_NS::check_slab_box(LAMMPS *lmp, const std::string &style)
{
  Domain *domain = lmp->domain;
  if (!domain->xperiodic || !domain->yperiodic)
    lmp->error->all(FLERR, "{} requires a box periodic in x and y, boundary is {} {} {}", style,
                    domain->xperiodic ? "p" : "non-periodic",
                    domain->yperiodic ? "p" : "non-periodic",
                    domain->zperiodic ? "p" : "non-periodic");
  if (domain->dimension != 3) lmp->error->all(FLERR, "{} requires a 3d system", style);
}

void LAMMPS_NS::reduce_z_range(MPI_Comm world, double lo_local, double hi_local, double &lo,
                               double &hi)
{
  double local[2] = {-lo_local, hi_local}, all[2];
  MPI_Allreduce(local, all, 2, MPI_DOUBLE, MPI_MAX, world);
  lo = -all[0];
  hi = all[1];
}
