/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "gran_sub_mod_normal_jkr_marshall.h"

#include "gran_sub_mod_damping_marshall.h"
#include "jkr_scaled.h"

#include "citeme.h"
#include "error.h"
#include "granular_model.h"
#include "math_const.h"

#include <cmath>

using namespace LAMMPS_NS;
using namespace Granular_NS;
using MathConst::MY_PI;

// delta_C = a_0^2 / (2 6^(1/3) R) with a_0^3 = 9 pi gamma R^2 / E
//         = DELTAC_PREFIX * (R gamma^2 / E^2)^(1/3)
static constexpr double DELTAC_PREFIX = 2.5537664411075656;    // (9 pi)^(2/3) / (2 6^(1/3))

static const char cite_jkr_marshall[] =
    "GRANULAR-CHARGED jkr/marshall contact model: doi:10.1016/j.jcp.2008.10.035\n\n"
    "@Article{Marshall09,\n"
    " author = {J. S. Marshall},\n"
    " title = {Discrete-Element Modeling of Particulate Aerosol Flows},\n"
    " journal = {J.~Comput.\\ Phys.},\n"
    " year = 2009, volume = 228, pages = {1541--1561}\n}\n\n";

/* ---------------------------------------------------------------------- */

GranSubModNormalJKRMarshall::GranSubModNormalJKRMarshall(GranularModel *gm, LAMMPS *lmp) :
    GranSubModNormalJKR(gm, lmp), restitution(0.0), Gmix(0.0), F_adhesive(0.0), s_contact(1.0)
{
  if (lmp->citeme) lmp->citeme->add(cite_jkr_marshall);
}

/* ----------------------------------------------------------------------
   coeffs: E (Young's modulus), e (restitution), nu (Poisson's ratio), gamma (surface energy)
------------------------------------------------------------------------- */

void GranSubModNormalJKRMarshall::coeffs_to_local()
{
  Emod = coeffs[0];           // Young's modulus
  restitution = coeffs[1];    // coefficient of restitution, used by damping marshall
  poiss = coeffs[2];          // Poisson's ratio
  cohesion = coeffs[3];       // surface energy gamma per surface (work of adhesion 2 gamma)
  damp = restitution;         // what damping models read through get_damp()
  scales_reff = -1.0;         // the scales depend on the coefficients: recompute them

  if (!(Emod > 0.0))
    error->all(FLERR, "Illegal jkr/marshall normal model, Young's modulus must be > 0, got {}",
               Emod);
  if (!(restitution >= 0.0 && restitution <= 1.0))
    error->all(FLERR,
               "Illegal jkr/marshall normal model, restitution coefficient must be in [0, 1], "
               "got {}",
               restitution);
  if (!(poiss > -1.0 && poiss <= 0.5))
    error->all(FLERR,
               "Illegal jkr/marshall normal model, Poisson's ratio must be in (-1, 0.5], got {}",
               poiss);
  if (!(cohesion >= 0.0))
    error->all(FLERR, "Illegal jkr/marshall normal model, surface energy must be >= 0, got {}",
               cohesion);

  if (!mixed_coefficients) {
    if (gm->contact_type == PAIR) {
      Emix = mix_stiffnessE(Emod, Emod, poiss, poiss);
      Gmix = mix_stiffnessG(Emod, Emod, poiss, poiss);
    } else {
      Emix = mix_stiffnessE_wall(Emod, poiss);
      Gmix = mix_stiffnessG_wall(Emod, poiss);
    }
  }
  k = 4.0 / 3.0 * Emix;
}

/* ----------------------------------------------------------------------
   unlike types: E* and G* from both materials (doc/theory.md, eq. (1.1)), surface energy and
   restitution by geometric mean (work of adhesion 2 sqrt(gamma_i gamma_j), Berthelot-like)
------------------------------------------------------------------------- */

void GranSubModNormalJKRMarshall::mix_coeffs(double *icoeffs, double *jcoeffs)
{
  Emix = mix_stiffnessE(icoeffs[0], jcoeffs[0], icoeffs[2], jcoeffs[2]);
  Gmix = mix_stiffnessG(icoeffs[0], jcoeffs[0], icoeffs[2], jcoeffs[2]);
  coeffs[0] = mix_geom(icoeffs[0], jcoeffs[0]);
  coeffs[1] = mix_geom(icoeffs[1], jcoeffs[1]);
  coeffs[2] = mix_mean(icoeffs[2], jcoeffs[2]);
  coeffs[3] = mix_geom(icoeffs[3], jcoeffs[3]);
  mixed_coefficients = 1;
  coeffs_to_local();
}

/* ----------------------------------------------------------------------
   the second coefficient is a restitution coefficient, which only damping marshall reads as
   such: every other damping model would take e (through get_damp()) as its own damping
   constant and silently give other collisions (e.g. elastic ones for viscoelastic)
------------------------------------------------------------------------- */

void GranSubModNormalJKRMarshall::init()
{
  if (!dynamic_cast<GranSubModDampingMarshall *>(gm->damping_model))
    error->all(FLERR,
               "Normal model jkr/marshall requires damping marshall (its second coefficient is "
               "the restitution coefficient that only damping marshall uses), got damping {}",
               gm->damping_model->name);
}

/* ---------------------------------------------------------------------- */

double GranSubModNormalJKRMarshall::critical_overlap(double reff) const
{
  if (cohesion == 0.0 || reff <= 0.0) return 0.0;
  return DELTAC_PREFIX * cbrt(reff * cohesion * cohesion / (Emix * Emix));
}

/* ----------------------------------------------------------------------
   delta_C, a_sep = a_0 / 6^(2/3) = (pi gamma R^2 / (4 E*))^(1/3) and F_C of radius R
   (doc/theory.md, eqs. (1.2) and (1.4a)), kept until R changes
------------------------------------------------------------------------- */

void GranSubModNormalJKRMarshall::set_scales(double reff)
{
  scales_reff = reff;
  scale_deltac = critical_overlap(reff);
  scale_inv_deltac = (scale_deltac > 0.0) ? 1.0 / scale_deltac : 0.0;
  scale_asep = cbrt(MY_PI * cohesion * reff * reff / (4.0 * Emix));
  scale_fc = 3.0 * MY_PI * cohesion * reff;
}

/* ----------------------------------------------------------------------
   contact life (Marshall 2009): forms at delta >= 0, persists until delta = -delta_C
------------------------------------------------------------------------- */

bool GranSubModNormalJKRMarshall::touch()
{
  if (gm->touch) {
    use_scales(gm->Reff);
    const double dist_break = gm->radsum + scale_deltac;
    return gm->rsq < dist_break * dist_break;
  }
  return gm->rsq < gm->radsum * gm->radsum;
}

/* ----------------------------------------------------------------------
   neighbor cutoff beyond touching: delta_C (called outside compute())
------------------------------------------------------------------------- */

double GranSubModNormalJKRMarshall::pulloff_distance(double radi, double radj)
{
  if (radi + radj <= 0.0) return 0.0;
  return critical_overlap(radi * radj / (radi + radj));
}

/* ----------------------------------------------------------------------
   contact radius on the stable JKR branch: a = a_sep s^2 with s the root of
   s^4 - 4 s = 3 delta / delta_C (doc/theory.md, eq. (1.4a); jkr_scaled.h). Same a as
   GranSubModNormalJKR's closed form, without its cube root and four square roots.
   Without adhesion the law is Hertz's, which the closed form handles.
------------------------------------------------------------------------- */

double GranSubModNormalJKRMarshall::calculate_contact_radius()
{
  if (cohesion == 0.0) return GranSubModNormalJKR::calculate_contact_radius();
  use_scales(gm->Reff);
  s_contact = JKRScaled::root(gm->delta * scale_inv_deltac);
  return scale_asep * s_contact * s_contact;
}

/* ----------------------------------------------------------------------
   F_ne = 4 F_C ((a/a_0)^3 - (a/a_0)^(3/2))                     (Marshall 2009, eq. 8)
        = F_C (s^6 / 9 - 2 s^3 / 3)                             (doc/theory.md, eq. (1.4a))
   F_adhesive = 4 F_C (a/a_0)^(3/2) = 2 F_C s^3 / 3 is kept for rolling marshall.
   Without adhesion: Hertz, F_ne = 4 E* a^3 / (3 R).
------------------------------------------------------------------------- */

double GranSubModNormalJKRMarshall::calculate_forces()
{
  if (cohesion == 0.0) {
    const double a = gm->contact_radius;
    F_adhesive = 0.0;
    F_pulloff = 0.0;
    Fne = k * a * a * a / gm->Reff;
    return Fne;
  }
  F_adhesive = JKRScaled::adhesive_over_fc(s_contact) * scale_fc;
  Fne = JKRScaled::force_over_fc(s_contact) * scale_fc;
  F_pulloff = scale_fc;
  return Fne;
}
