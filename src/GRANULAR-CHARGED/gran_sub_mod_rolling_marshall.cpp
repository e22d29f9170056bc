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
#include "math_extra.h"

#include <cmath>

using namespace LAMMPS_NS;
using namespace Granular_NS;
using namespace MathExtra;

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
   Rolling displacement xi = integral of v_L dt in the tangent plane, with LAMMPS's rolling
   velocity v_L = R (omega_i - omega_j) x n (Wang et al., Particuology 23, 49 (2015), eq. 31),
   history rotated into the current tangent plane keeping its length.
   Moment M_r = -k_R n x xi, k_R = 4 F_C (a/a_0)^(3/2)   (paper eq. 3; Marshall 2009)
   |xi| is capped at theta_crit R: M_r,crit = k_R theta_crit R   (paper eq. 4)
   GranularModel applies torque_i += R n x fr, so fr = -(k_R / R) xi.
------------------------------------------------------------------------- */

void GranSubModRollingMarshall::calculate_forces()
{
  double xi[3], tmp[3];
  double *history = &gm->history[history_index];
  copy3(history, xi);

  if (gm->history_update) {
    const double xin = dot3(xi, gm->nx);
    if (xin != 0.0) {
      // drop the normal part and restore the length
      const double lensq = lensq3(xi);
      scale3(xin, gm->nx, tmp);
      sub3(xi, tmp, xi);
      const double plensq = lensq3(xi);
      scale3(plensq > 0.0 ? sqrt(lensq / plensq) : 0.0, xi);
    }
    scale3(gm->dt, gm->vrl, tmp);
    add3(xi, tmp, xi);
  }

  // irreversible rolling beyond theta_crit R (R = R_eff, or the particle radius for
  // marshall/particle: 2 R_eff for a pair, R_eff = r_p at a wall)
  const double radius = (gm->contact_type == PAIR) ? pair_radius_factor * gm->Reff : gm->Reff;
  const double xi_crit = theta_crit * radius;
  const double lensq = lensq3(xi);
  if (lensq > xi_crit * xi_crit) scale3(xi_crit / sqrt(lensq), xi);

  scale3(-jkr->get_adhesive_force() / gm->Reff, xi, gm->fr);

  if (gm->history_update) copy3(xi, history);
}
