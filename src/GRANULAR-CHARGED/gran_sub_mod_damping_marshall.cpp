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

#include <cmath>

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
   alpha(e) = 1.2728 - 4.2783 e + 11.087 e^2 - 22.348 e^3 + 27.467 e^4 - 18.022 e^5
              + 4.8218 e^6   (Tsuji et al., Powder Technol. 71, 239 (1992), as used by
              Marshall 2009 and the paper's eq. 2); alpha(1) = 0 within 1e-4, clamped at 0
------------------------------------------------------------------------- */

void GranSubModDampingMarshall::init()
{
  jkr = dynamic_cast<GranSubModNormalJKRMarshall *>(gm->normal_model);
  if (!jkr)
    error->all(FLERR,
               "Damping marshall requires normal model jkr/marshall (it reads the restitution "
               "coefficient and E* from it), not {}",
               gm->normal_model->name);
  const double e = jkr->get_restitution();
  alpha = 1.2728 +
      e * (-4.2783 + e * (11.087 + e * (-22.348 + e * (27.467 + e * (-18.022 + e * 4.8218)))));
  // the fit is 1e-4 off zero at e = 1: no damping means none, and never negative damping
  if (e == 1.0 || alpha < 0.0) alpha = 0.0;
  damp = alpha;
}

/* ----------------------------------------------------------------------
   F_nd = -eta_N (v_ij . n),  eta_N = alpha(e) sqrt(mass_factor m* k_N),  k_N = 4/3 E* a
   (doc/theory.md, eqs. (1.5)-(1.6)). mass_factor 2 (marshall) makes the Tsuji fit alpha(e)
   deliver e for a Hertz collision; 1 (marshall/printed) is the form printed in the paper's
   eq. 2 and in LAMMPS's tsuji, which rebounds with more than e (figures in
   doc/pair_granular_jkr_marshall.md).
   a >= 0.30285 a_0 > 0 for every live JKR contact, so k_N > 0 also in tension.
------------------------------------------------------------------------- */

double GranSubModDampingMarshall::calculate_forces()
{
  const double kn = 4.0 / 3.0 * jkr->get_emix() * gm->contact_radius;
  damp_prefactor = alpha * sqrt(mass_factor * gm->meff * (kn > 0.0 ? kn : 0.0));
  return -damp_prefactor * gm->vnnr;
}
