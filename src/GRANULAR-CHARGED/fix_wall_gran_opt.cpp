/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "fix_wall_gran_opt.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "gran_sub_mod.h"
#include "granular_model.h"
#include "math_extra.h"
#include "update.h"

#if GC_LAMMPS_VERSION >= 20260704
#include "fix_wall.h"
#endif

#include <cstring>

using namespace LAMMPS_NS;
using namespace Granular_NS;
using namespace MathExtra;
namespace MK = MarshallKernels;

// FixWallGran's wall styles (fix_wall_gran.cpp: "XYZ PLANE need to be 0,1,2") and its value of
// a NULL plane
static constexpr int XPLANE = 0, YPLANE = 1, ZPLANE = 2;
static constexpr double BIG = 1.0e20;

/* ---------------------------------------------------------------------- */

FixWallGranOpt::FixWallGranOpt(LAMMPS *lmp, int narg, char **arg) :
    FixWallGran(lmp, narg, arg), fused(false), reported(false), scales_radius(-1.0)
{
}

/* ----------------------------------------------------------------------
   Modify hands the per-atom data of a restart file to a new fix only if its ID and style
   equal those written (the style in full, suffix included). The variant therefore carries
   wall/gran's name: either style reads the other's restart file, history included. Called
   after the suffix is appended and before the restart data are handed out.
------------------------------------------------------------------------- */

void FixWallGranOpt::post_constructor()
{
  FixWallGran::post_constructor();
  delete[] style;
  style = utils::strdup("wall/gran");
}

/* ----------------------------------------------------------------------
   the fused loop covers a still flat wall of the Marshall set without the options that need
   FixWallGran's own bookkeeping (heat, rigid-body masses, the contacts output)
------------------------------------------------------------------------- */

void FixWallGranOpt::init()
{
  FixWallGran::init();    // sets the sub-models' history offsets and fix_rigid

  const bool flat = wallstyle == XPLANE || wallstyle == YPLANE || wallstyle == ZPLANE;
  fused = flat && !wiggle && !wshear && !heat_flag && !peratom_flag && !fix_rigid &&
      use_history && model->beyond_contact && model->contact_type == WALL &&
      MarshallFusedSet::of_model(model, coeffs);
  // the touch flag is the history's first value, the sub-models' values follow it
  if (fused && (coeffs.hist_tangential < 1 || coeffs.hist_tangential + 3 > size_history))
    fused = false;
  scales_radius = -1.0;

  if (comm->me == 0 && !reported) {
    utils::logmesg(lmp, "fix {} (wall/gran/opt): {}\n", id,
                   fused ? "fused flat wall of the Marshall set"
                         : "wall/gran's sub-model path (not a still flat wall of the Marshall set)");
    reported = true;
  }
}

/* ---------------------------------------------------------------------- */

void FixWallGranOpt::post_force(int vflag)
{
  if (fused)
    post_force_fused();
  else
    FixWallGran::post_force(vflag);
}

/* ----------------------------------------------------------------------
   delta_C, a_sep, F_C and sqrt(k_N) scales of R_eff = reff, recomputed when it changes
------------------------------------------------------------------------- */

const MK::JKRScales &FixWallGranOpt::scales_of(double reff)
{
  if (reff != scales_radius) {
    scales_radius = reff;
    scales = MK::jkr_scales(reff, coeffs.gamma, coeffs.emix);
  }
  return scales;
}

/* ----------------------------------------------------------------------
   FixWallGran::post_force() for a still flat wall, with what GranularModel::check_contact()
   and calculate_forces() do for a WALL contact of the Marshall set (the sub-models'
   marshall_kernels.h calls) in the same order of operations: the wall is a body of radius 0
   at rest (R_eff = r_p, v_wall = omega_wall = 0, meff = m_i), the torque's lever arm r_p.
   Same history values at the same offsets, reset when a contact ends.
------------------------------------------------------------------------- */

void FixWallGranOpt::post_force_fused()
{
  // do not update history during setup
  history_update = update->setupflag ? 0 : 1;
  model->history_update = history_update;

  const double wlo = lo;
  const double whi = hi;
  const int axis = wallstyle;
  const double vwall[3] = {0.0, 0.0, 0.0};
  const double w0[3] = {0.0, 0.0, 0.0};
  const double rwall = 0.0;

  double **x = atom->x;
  double **v = atom->v;
  double **f = atom->f;
  double **omega = atom->omega;
  double **torque = atom->torque;
  double *radius = atom->radius;
  double *rmass = atom->rmass;
  int *mask = atom->mask;
  const int nlocal = atom->nlocal;
  const int nhistory = size_history;
  const double dtm = model->dt;
  const MarshallFusedSet::Coeffs &c = coeffs;

  for (int i = 0; i < nlocal; i++) {
    if (!(mask[i] & groupbit)) continue;

    // signed distance from the nearer plane, along the wall's axis
    double dx[3] = {0.0, 0.0, 0.0};
    const double del1 = x[i][axis] - wlo;
    const double del2 = whi - x[i][axis];
    if (del1 < del2)
      dx[axis] = del1;
    else
      dx[axis] = -del2;

    // contact life (GranularModel::check_contact, jkr/marshall touch): R_eff = radsum = r_p
    double *history = history_one[i];
    const bool was_touching = history[0] != 0.0;
    const double rsq = lensq3(dx);
    const double radi = radius[i];
    const double radsum = radi;
    // most atoms are far from the wall: rejected before the JKR scales
    bool touching = rsq < radsum * radsum;
    if (was_touching) touching = MK::jkr_touch(true, rsq, radsum, scales_of(radi).deltac);
    if (!touching) {
      for (int k = 0; k < nhistory; k++) history[k] = 0.0;
      continue;
    }
    history[0] = 1;

    const double reff = radi;
    const MK::JKRScales &sc = scales_of(reff);
    const double meff = rmass[i];

    // kinematics (GranularModel::calculate_forces)
    const double r = sqrt(rsq);
    const double rinv = 1.0 / r;
    const double delta = radsum - r;
    double vr[3], nx[3], vn[3], vt[3], wr[3], temp[3], vtr[3];
    sub3(v[i], vwall, vr);
    scale3(rinv, dx, nx);
    const double vnnr = dot3(vr, nx);
    scale3(vnnr, nx, vn);
    sub3(vr, vn, vt);
    scaleadd3(radi, omega[i], rwall, w0, wr);
    cross3(wr, nx, temp);
    sub3(vt, temp, vtr);

    // normal: JKR with Marshall damping
    const MK::NormalForce nf = MK::jkr_normal_force(sc, c.gamma, c.emix, delta, reff);
    const double damp_prefactor =
        MK::damping_prefactor(c.alpha, MK::damping_sqrt_mass(c.mass_factor, meff), nf);
    const double fntot = nf.fne + (-damp_prefactor * vnnr);
    const double fncrit = MK::critical_force(nf);

    // sliding
    double fs[3];
    MK::tangential_force(&history[c.hist_tangential], nx, vtr, dtm, c.k_t * nf.a, damp_prefactor,
                         fncrit * c.mu, history_update, fs);

    double forces[3], torquesi[3];
    scale3(fntot, nx, forces);
    add3(forces, fs, forces);
    cross3(nx, fs, torquesi);
    scale3(-1, torquesi);
    scale3(radi, torquesi);

    if (c.rolling || c.twisting) {
      double relrot[3];
      sub3(omega[i], w0, relrot);
      if (c.rolling) {
        // rolling velocity, eq. 31 of Wang et al, Particuology 23, 49 (2015); at a wall both
        // rolling conventions limit xi at theta_crit R_eff = theta_crit r_p
        double vrl[3], fr[3], torroll[3];
        vrl[0] = reff * (relrot[1] * nx[2] - relrot[2] * nx[1]);
        vrl[1] = reff * (relrot[2] * nx[0] - relrot[0] * nx[2]);
        vrl[2] = reff * (relrot[0] * nx[1] - relrot[1] * nx[0]);
        MK::rolling_force(&history[c.hist_rolling], nx, vrl, dtm, c.theta_crit * reff,
                          nf.adhesive / reff, history_update, fr);
        cross3(nx, fr, torroll);
        scale3(reff, torroll);
        add3(torquesi, torroll, torquesi);
      }
      if (c.twisting) {
        // omega_T (eq. 29 of Marshall 2009)
        const double magtwist = dot3(relrot, nx);
        const double moment = MK::twisting_moment(history[c.hist_twisting], magtwist, dtm, nf.a,
                                                  c.k_t, damp_prefactor, c.mu * fncrit,
                                                  history_update);
        double tortwist[3];
        scale3(moment, nx, tortwist);
        add3(torquesi, tortwist, torquesi);
      }
    }

    add3(f[i], forces, f[i]);
    add3(torque[i], torquesi, torque[i]);
  }

#if GC_LAMMPS_VERSION >= 20260704
  // the wall's image for dump image (FixWallGran::post_force)
  int m = 0;
  const int lo_side[3] = {FixWall::XLO, FixWall::YLO, FixWall::ZLO};
  const int hi_side[3] = {FixWall::XHI, FixWall::YHI, FixWall::ZHI};
  if (lo != -BIG) FixWall::update_image_plane(m++, lo_side[axis], wlo, imgparms, domain);
  if (hi != BIG) FixWall::update_image_plane(m++, hi_side[axis], whi, imgparms, domain);
#endif
}
