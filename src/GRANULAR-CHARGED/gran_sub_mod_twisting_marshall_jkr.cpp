/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "gran_sub_mod_twisting_marshall_jkr.h"

#include "error.h"
#include "gran_sub_mod_normal.h"
#include "gran_sub_mod_tangential.h"
#include "granular_model.h"
#include "marshall_kernels.h"

using namespace LAMMPS_NS;
using namespace Granular_NS;

/* ---------------------------------------------------------------------- */

GranSubModTwistingMarshallJKR::GranSubModTwistingMarshallJKR(GranularModel *gm, LAMMPS *lmp) :
    GranSubModTwisting(gm, lmp), k_tang(0.0), mu_tang(0.0)
{
  num_coeffs = 0;
  size_history = 1;
  contact_radius_flag = 1;
  // the twist angle (integral of (w_i - w_j) . n) is symmetric in i and j: copy it when a
  // neighbor rebuild swaps the pair (LAMMPS's default negation is wrong for it, as in the
  // built-in twisting marshall)
  nondefault_history_transfer = 1;
  transfer_history_factor = new double[size_history];
  transfer_history_factor[0] = +1.0;
}

/* ----------------------------------------------------------------------
   needs a tangential model whose stiffness is 8 G* per unit contact radius
   (marshall or the mindlin family), so that k_T = 8 G* a
------------------------------------------------------------------------- */

void GranSubModTwistingMarshallJKR::init()
{
  // the Mindlin family (and tangential marshall, derived from it) holds k = 8 G*, scaled by a
  // in the force; mindlin_classic is not of that family
  if (!dynamic_cast<GranSubModTangentialMindlin *>(gm->tangential_model))
    error->all(FLERR,
               "Twisting marshall/jkr requires tangential model marshall or mindlin "
               "(stiffness 8 G* a), not {}",
               gm->tangential_model->name);
  k_tang = gm->tangential_model->get_k();
  mu_tang = gm->tangential_model->get_mu();
}

/* ----------------------------------------------------------------------
   M_t = -k_tw phi - eta_tw omega_T,  k_tw = k_T a^2 / 2 = 4 G* a^3, eta_tw = eta_T a^2 / 2
   (Marshall 2009, eqs. 29-32), |M_t| <= 3 pi a F_crit / 16 (paper eq. 4)
   (marshall_kernels.h: twisting_moment)
------------------------------------------------------------------------- */

GC_TWISTING_RESULT GranSubModTwistingMarshallJKR::calculate_forces()
{
  const double moment = MarshallKernels::twisting_moment(
      gm->history[history_index], gm->magtwist, gm->dt, gm->contact_radius, k_tang,
      gm->tangential_model->get_damp(), mu_tang * gm->normal_model->get_fncrit(),
      gm->history_update);
  gm->magtortwist = moment;
#if GC_TWISTING_RETURNS_MOMENT
  return moment;
#endif
}
