/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "gran_sub_mod_tangential_marshall.h"

#include "error.h"
#include "gran_sub_mod_normal.h"
#include "gran_sub_mod_normal_jkr_marshall.h"
#include "gran_sub_mod_damping.h"
#include "granular_model.h"
#include "marshall_kernels.h"

using namespace LAMMPS_NS;
using namespace Granular_NS;

/* ---------------------------------------------------------------------- */

GranSubModTangentialMarshall::GranSubModTangentialMarshall(GranularModel *gm, LAMMPS *lmp) :
    GranSubModTangentialMindlin(gm, lmp)
{
  num_coeffs = 1;
  size_history = 3;
  contact_radius_flag = 1;
  mindlin_force = 0;      // history holds the tangential displacement
  mindlin_rescale = 0;    // no Mindlin unloading rescale in Marshall's model
}

/* ----------------------------------------------------------------------
   coeffs: mu (sliding friction coefficient)
------------------------------------------------------------------------- */

void GranSubModTangentialMarshall::coeffs_to_local()
{
  mu = coeffs[0];    // sliding friction coefficient
  xt = 1.0;          // eta_T = eta_N (Marshall 2009)
  k = 0.0;           // 8 G*, set in init() once the normal model is known
  if (!(mu >= 0.0))
    error->all(FLERR,
               "Illegal marshall tangential model, friction coefficient must be >= 0, got {}", mu);
}

/* ---------------------------------------------------------------------- */

void GranSubModTangentialMarshall::mix_coeffs(double *icoeffs, double *jcoeffs)
{
  coeffs[0] = mix_geom(icoeffs[0], jcoeffs[0]);
  coeffs_to_local();
}

/* ----------------------------------------------------------------------
   k_T = 8 G* a (Marshall 2009, eq. 24); k holds 8 G*, scaled by a in calculate_forces()
------------------------------------------------------------------------- */

void GranSubModTangentialMarshall::init()
{
  auto *jkr = dynamic_cast<GranSubModNormalJKRMarshall *>(gm->normal_model);
  if (jkr) {
    k = 8.0 * jkr->get_gmix();
  } else {
    // other normal models with material properties: G* from their E and nu (like mindlin)
    if (!gm->normal_model->get_material_properties())
      error->all(FLERR,
                 "Tangential marshall requires a normal model with material properties "
                 "(E, nu), not {}",
                 gm->normal_model->name);
    const double E = gm->normal_model->get_emod();
    const double nu = gm->normal_model->get_poiss();
    k = 8.0 *
        (gm->contact_type == PAIR ? mix_stiffnessG(E, E, nu, nu) : mix_stiffnessG_wall(E, nu));
  }
}

/* ----------------------------------------------------------------------
   F_t = -k_T h - eta_T v_t, |F_t| <= mu F_crit (marshall_kernels.h: tangential_force)
------------------------------------------------------------------------- */

void GranSubModTangentialMarshall::calculate_forces()
{
#if GC_LAMMPS_VERSION >= 20260704
  // the half-step normal of synchronized verlet is the built-in model's business
  if (gm->synchronized_verlet == 1) {
    GranSubModTangentialMindlin::calculate_forces();
    return;
  }
#endif
  damp = xt * gm->damping_model->get_damp_prefactor();
  MarshallKernels::tangential_force(&gm->history[history_index], gm->nx, gm->vtr, gm->dt,
                                    k * gm->contact_radius, damp,
                                    gm->normal_model->get_fncrit() * mu, gm->history_update,
                                    gm->fs);
}
