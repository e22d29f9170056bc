/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "gran_sub_mod_normal_jkr_marshall.h"

#include "citeme.h"
#include "comm.h"
#include "error.h"
#include "fix_charge_check.h"
#include "gran_sub_mod.h"
#include "granular_model.h"
#include "math_const.h"
#include "utils.h"

#include <cmath>

using namespace LAMMPS_NS;
using namespace Granular_NS;
using namespace MarshallKernels;

// a flat wall (region radius 0) is a sphere of radius r_p's partner R = r_p; the region search
// radius is the break distance of R = 2 r_p, so that concave region walls (curvature radius
// >= 2 r_p, R <= 2 r_p) keep their contacts to delta_C; touch() decides with the wall's own R
static constexpr double REGION_SEARCH_R_FACTOR = 2.0;

static const char cite_jkr_marshall[] =
    "GRANULAR-CHARGED jkr/marshall contact model: doi:10.1016/j.jcp.2008.10.035\n\n"
    "@Article{Marshall09,\n"
    " author = {J. S. Marshall},\n"
    " title = {Discrete-Element Modeling of Particulate Aerosol Flows},\n"
    " journal = {J.~Comput.\\ Phys.},\n"
    " year = 2009, volume = 228, pages = {1541--1561}\n}\n\n";

/* ---------------------------------------------------------------------- */

GranSubModNormalJKRMarshall::GranSubModNormalJKRMarshall(GranularModel *gm, LAMMPS *lmp) :
    GranSubModNormalJKR(gm, lmp), restitution(0.0), Gmix(0.0), contact(), scales(), scales_reff(-1.0)
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
  // charges without a Coulomb solver are said at the start of a run (not from inside fix
  // wall/gran's constructor, which calls init() too: a fix cannot be added there)
  if (gm->contact_type == PAIR) FixChargeCheck::ensure(lmp);

  // by name (damping marshall and marshall/printed), so that the normal model does not depend
  // on the damping model's class
  if (!utils::strmatch(gm->sub_models[DAMPING]->name, "^marshall"))
    error->all(FLERR,
               "Normal model jkr/marshall requires damping marshall (its second coefficient is "
               "the restitution coefficient that only damping marshall uses), got damping {}",
               gm->sub_models[DAMPING]->name);

  // LAMMPS's own twisting marshall is accepted by jkr/marshall but is another model: its cap on
  // the moment is (2/3) a F_crit, 13% above the Marshall-JKR 3 pi a F_crit / 16, its stiffness
  // is per unit radius, and its history is negated on a neighbor rebuild. Said once per model
  // as declared (pair_coeff, fix wall/gran, a restart): a model mixed from two declared ones
  // was announced with them.
  if (gm->sub_models[TWISTING]->name == "marshall" && !mixed_coefficients && comm->me == 0)
    error->warning(FLERR,
                   "Twisting marshall with normal jkr/marshall is LAMMPS's built-in twisting "
                   "model, not the Marshall-JKR one (its cap on the moment is 13% higher): use "
                   "twisting marshall/jkr");
}

/* ----------------------------------------------------------------------
   contact life (Marshall 2009): forms at delta >= 0, persists until delta = -delta_C
------------------------------------------------------------------------- */

bool GranSubModNormalJKRMarshall::touch()
{
  // delta_C matters only to a contact that exists: a new one forms at delta >= 0
  if (gm->touch) use_scales(gm->Reff);
  return jkr_touch(gm->touch, gm->rsq, gm->radsum, scales.deltac);
}

void GranSubModNormalJKRMarshall::use_scales(double reff)
{
  if (reff == scales_reff) return;
  scales_reff = reff;
  scales = jkr_scales(reff, cohesion, Emix);
}

/* ----------------------------------------------------------------------
   neighbor cutoff beyond touching: delta_C (called outside compute()). radj = 0 is a wall:
   fix wall/gran/region asks pulloff_distance(r_p, 0) for its search radius
------------------------------------------------------------------------- */

double GranSubModNormalJKRMarshall::pulloff_distance(double radi, double radj)
{
  if (radj == 0.0) return critical_overlap(REGION_SEARCH_R_FACTOR * radi, cohesion, Emix);
  if (radi + radj <= 0.0) return 0.0;
  return critical_overlap(radi * radj / (radi + radj), cohesion, Emix);
}

/* ----------------------------------------------------------------------
   contact radius and force of the contact (marshall_kernels.h: jkr_normal_force), the radius
   on the stable JKR branch a = a_sep s^2 with s^4 - 4 s = 3 delta / delta_C
   (doc/theory.md, eq. (1.4a)); without adhesion Hertz's a = sqrt(delta R)
------------------------------------------------------------------------- */

double GranSubModNormalJKRMarshall::calculate_contact_radius()
{
  use_scales(gm->Reff);
  contact = jkr_normal_force(scales, cohesion, Emix, gm->delta, gm->Reff);
  return contact.a;
}

/* ----------------------------------------------------------------------
   F_ne = 4 F_C ((a/a_0)^3 - (a/a_0)^(3/2))                     (Marshall 2009, eq. 8)
        = F_C (s^6 / 9 - 2 s^3 / 3)                             (doc/theory.md, eq. (1.4a))
   of the contact whose radius calculate_contact_radius() found; without adhesion Hertz.
------------------------------------------------------------------------- */

double GranSubModNormalJKRMarshall::calculate_forces()
{
  F_pulloff = contact.pulloff;
  Fne = contact.fne;
  return Fne;
}

/* ----------------------------------------------------------------------
   F_crit = |F_ne + 2 F_C| for the friction limits (paper eq. 4)
------------------------------------------------------------------------- */

void GranSubModNormalJKRMarshall::set_fncrit()
{
  Fncrit = critical_force(contact);
}
