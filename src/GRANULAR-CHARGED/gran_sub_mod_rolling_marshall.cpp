/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "gran_sub_mod_rolling_marshall.h"

#include "error.h"
#include "gran_sub_mod_normal_jkr_marshall.h"
#include "granular_model.h"
#include "marshall_kernels.h"

using namespace LAMMPS_NS;
using namespace Granular_NS;

/* ---------------------------------------------------------------------- */

GranSubModRollingMarshall::GranSubModRollingMarshall(GranularModel *gm, LAMMPS *lmp) :
    GranSubModRolling(gm, lmp), jkr(nullptr), theta_crit(0.0), pair_radius_factor(1.0)
{
  num_coeffs = 1;
  size_history = 3;
  contact_radius_flag = 1;
  // xi does not change sign when i and j swap (v_L = R (w_i - w_j) x n is symmetric), so a
  // neighbor rebuild that stores the pair as (j,i) must copy it, not negate it (LAMMPS's
  // default). The built-in rolling sds negates it (measured: results depend on rebuilds).
  nondefault_history_transfer = 1;
  transfer_history_factor = new double[size_history];
  for (int i = 0; i < size_history; i++) transfer_history_factor[i] = +1.0;
}

GranSubModRollingMarshallParticle::GranSubModRollingMarshallParticle(GranularModel *gm,
                                                                     LAMMPS *lmp) :
    GranSubModRollingMarshall(gm, lmp)
{
  pair_radius_factor = 2.0;
}

/* ----------------------------------------------------------------------
   coeffs: theta_crit (critical rolling angle, radians)
------------------------------------------------------------------------- */

void GranSubModRollingMarshall::coeffs_to_local()
{
  theta_crit = coeffs[0];    // critical rolling angle
  if (!(theta_crit > 0.0))
    error->all(FLERR, "Illegal marshall rolling model, theta_crit must be > 0, got {}", theta_crit);
}

/* ---------------------------------------------------------------------- */

void GranSubModRollingMarshall::mix_coeffs(double *icoeffs, double *jcoeffs)
{
  coeffs[0] = mix_geom(icoeffs[0], jcoeffs[0]);
  coeffs_to_local();
}

/* ---------------------------------------------------------------------- */

void GranSubModRollingMarshall::init()
{
  jkr = dynamic_cast<GranSubModNormalJKRMarshall *>(gm->normal_model);
  if (!jkr)
    error->all(FLERR,
               "Rolling marshall requires normal model jkr/marshall (its stiffness is "
               "4 F_C (a/a_0)^(3/2)), not {}",
               gm->normal_model->name);
}

/* ----------------------------------------------------------------------
   Rolling displacement xi = integral of v_L dt in the tangent plane, moment
   M_r = -k_R n x xi, k_R = 4 F_C (a/a_0)^(3/2), |xi| capped at theta_crit R  (paper eqs. 3-4;
   marshall_kernels.h: rolling_force). R = R_eff, or the particle radius for marshall/particle:
   2 R_eff for a pair, R_eff = r_p at a wall.
------------------------------------------------------------------------- */

void GranSubModRollingMarshall::calculate_forces()
{
  const double radius = (gm->contact_type == PAIR) ? pair_radius_factor * gm->Reff : gm->Reff;
  MarshallKernels::rolling_force(&gm->history[history_index], gm->nx, gm->vrl, gm->dt,
                                 theta_crit * radius, jkr->get_adhesive_force() / gm->Reff,
                                 gm->history_update, gm->fr);
}
