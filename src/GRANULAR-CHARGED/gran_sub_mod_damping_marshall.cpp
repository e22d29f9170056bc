/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "gran_sub_mod_damping_marshall.h"

#include "error.h"
#include "gran_sub_mod_normal_jkr_marshall.h"
#include "granular_model.h"
#include "marshall_kernels.h"

using namespace LAMMPS_NS;
using namespace Granular_NS;

/* ---------------------------------------------------------------------- */

GranSubModDampingMarshall::GranSubModDampingMarshall(GranularModel *gm, LAMMPS *lmp) :
    GranSubModDamping(gm, lmp), jkr(nullptr), alpha(0.0), mass_factor(2.0)
{
  contact_radius_flag = 1;
}

GranSubModDampingMarshallPrinted::GranSubModDampingMarshallPrinted(GranularModel *gm,
                                                                   LAMMPS *lmp) :
    GranSubModDampingMarshall(gm, lmp)
{
  mass_factor = 1.0;
}

/* ----------------------------------------------------------------------
   alpha(e) of Tsuji et al., Powder Technol. 71, 239 (1992), as used by Marshall 2009 and the
   paper's eq. 2 (marshall_kernels.h: damping_alpha)
------------------------------------------------------------------------- */

void GranSubModDampingMarshall::init()
{
  jkr = dynamic_cast<GranSubModNormalJKRMarshall *>(gm->normal_model);
  if (!jkr)
    error->all(FLERR,
               "Damping marshall requires normal model jkr/marshall (it reads the restitution "
               "coefficient and E* from it), not {}",
               gm->normal_model->name);
  alpha = MarshallKernels::damping_alpha(jkr->get_restitution());
  damp = alpha;
}

/* ----------------------------------------------------------------------
   F_nd = -eta_N (v_ij . n),  eta_N = alpha(e) sqrt(mass_factor m* k_N),  k_N = 4/3 E* a
   (doc/theory.md, eqs. (1.5)-(1.6); marshall_kernels.h: damping_prefactor). mass_factor 2
   (marshall) makes the Tsuji fit alpha(e) deliver e for a Hertz collision; 1
   (marshall/printed) is the form printed in the paper's eq. 2 and in LAMMPS's tsuji, which
   rebounds with more than e (figures in doc/pair_granular_jkr_marshall.rst).
------------------------------------------------------------------------- */

double GranSubModDampingMarshall::calculate_forces()
{
  damp_prefactor = MarshallKernels::damping_prefactor(
      alpha, MarshallKernels::damping_sqrt_mass(mass_factor, gm->meff), jkr->get_contact());
  return -damp_prefactor * gm->vnnr;
}
