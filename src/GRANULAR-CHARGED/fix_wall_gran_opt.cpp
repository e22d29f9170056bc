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
#include "granular_model.h"
#include "marshall_lanes.h"
#include "update.h"

#if GC_LAMMPS_VERSION >= 20260704
#include "fix_wall.h"
#endif

#include <algorithm>
#include <cmath>
#include <cstring>

using namespace LAMMPS_NS;
using namespace Granular_NS;
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
  // at a wall both rolling conventions limit xi at theta_crit R_eff = theta_crit r_p
  wall_coeffs = coeffs;
  wall_coeffs.roll_radius_factor = 1.0;

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
   FixWallGran::post_force() for a still flat wall: GranularModel::check_contact() and
   calculate_forces() of a WALL contact of the Marshall set, by the contact assembly of
   pair_style granular/opt (marshall_lanes.h) with the wall as a fixed partner of radius 0 at
   rest (R_eff = r_p, v_wall = omega_wall = 0, m* = m_i, torque lever arm r_p). Same history
   values at the same offsets, reset when a contact ends. The adhesive contacts go through the
   SIMD lanes, those of Hertz's law (no adhesion) through the scalar instantiation.
------------------------------------------------------------------------- */

void FixWallGranOpt::post_force_fused()
{
  namespace ML = MarshallLanes;
  // do not update history during setup
  history_update = update->setupflag ? 0 : 1;
  model->history_update = history_update;

  gather_contacts();
  jkr_root.resize(jkr_overlap.size());
  JKRScaled::roots(jkr_overlap.size(), jkr_overlap.data(), jkr_root.data());

  const std::size_t n = contacts.size();
  if (coeffs.gamma == 0.0) {
    for (const WallContact &c : contacts) {
      double in[ML::N_INPUT], out[ML::N_OUTPUT];
      pack_contact(c, 1.0, in, 1);
      ML::marshall_contact(in, out, history_update);
      unpack_contact(c, out, 1);
    }
  } else {
    // a chunk at a time: its lanes blocks stay in the L1 cache
    constexpr std::size_t CHUNK = 8 * ML::WIDTH;
    lane_in.resize(CHUNK * ML::N_INPUT);
    lane_out.resize(CHUNK * ML::N_OUTPUT);
    for (std::size_t start = 0; start < n; start += CHUNK) {
      const std::size_t m = std::min(CHUNK, n - start);
      for (std::size_t k = 0; k < m; k++)
        pack_contact(contacts[start + k], jkr_root[start + k], ML::lane_input(lane_in.data(), k),
                     ML::WIDTH);
      const std::size_t nblocks = ML::pad_last_block(lane_in.data(), m);
      ML::contacts_in_lanes(nblocks, lane_in.data(), lane_out.data(), history_update);
      for (std::size_t k = 0; k < m; k++)
        unpack_contact(contacts[start + k], ML::lane_output(lane_out.data(), k), ML::WIDTH);
    }
  }

#if GC_LAMMPS_VERSION >= 20260704
  // the wall's image for dump image (FixWallGran::post_force)
  const int axis = wallstyle;
  int m = 0;
  const int lo_side[3] = {FixWall::XLO, FixWall::YLO, FixWall::ZLO};
  const int hi_side[3] = {FixWall::XHI, FixWall::YHI, FixWall::ZHI};
  if (lo != -BIG) FixWall::update_image_plane(m++, lo_side[axis], lo, imgparms, domain);
  if (hi != BIG) FixWall::update_image_plane(m++, hi_side[axis], hi, imgparms, domain);
#endif
}

/* ----------------------------------------------------------------------
   the contact life of each atom of the group (GranularModel::check_contact, jkr/marshall
   touch, R_eff = radsum = r_p): a contact that ends has its history reset; a touching one is
   kept with, if adhesive, its scaled overlap
------------------------------------------------------------------------- */

void FixWallGranOpt::gather_contacts()
{
  const double wlo = lo;
  const double whi = hi;
  const int axis = wallstyle;
  double **x = atom->x;
  const double *radius = atom->radius;
  const int *mask = atom->mask;
  // the group of atom_modify first: its atoms come first (as in LAMMPS's integrators)
  const int nlocal = igroup == atom->firstgroup ? atom->nfirst : atom->nlocal;
  const int nhistory = size_history;
  const bool adhesive = coeffs.gamma != 0.0;
  contacts.clear();
  jkr_overlap.clear();

  for (int i = 0; i < nlocal; i++) {
    if (!(mask[i] & groupbit)) continue;

    // signed distance from the nearer plane, along the wall's axis
    const double del1 = x[i][axis] - wlo;
    const double del2 = whi - x[i][axis];
    const double dist = del1 < del2 ? del1 : -del2;

    double *history = history_one[i];
    const bool was_touching = history[0] != 0.0;
    const double rsq = dist * dist;
    const double radsum = radius[i];
    // most atoms are far from the wall: rejected before the JKR scales
    bool touching = rsq < radsum * radsum;
    if (was_touching) touching = MK::jkr_touch(true, rsq, radsum, scales_of(radsum).deltac);
    if (!touching) {
      for (int k = 0; k < nhistory; k++) history[k] = 0.0;
      continue;
    }
    history[0] = 1;
    contacts.push_back({i, dist});
    if (adhesive) jkr_overlap.push_back(MK::scaled_overlap(scales_of(radsum), radsum - sqrt(rsq)));
  }
}

/* ----------------------------------------------------------------------
   the inputs of contact c (marshall_lanes.h), input q at in[q * stride]: the wall is a fixed
   partner of radius 0 at rest; root: its JKR root (unused without adhesion)
------------------------------------------------------------------------- */

void FixWallGranOpt::pack_contact(const WallContact &c, double root, double *in, int stride)
{
  namespace ML = MarshallLanes;
  static constexpr double at_rest[3] = {0.0, 0.0, 0.0};
  const int i = c.i;
  const double radi = atom->radius[i];
  const double *history = history_one[i];
  double dx[3] = {0.0, 0.0, 0.0};
  dx[wallstyle] = c.dist;
  ML::pack_contact_state(in, stride, dx, atom->v[i], at_rest, atom->omega[i], at_rest,
                         history + coeffs.hist_tangential,
                         coeffs.rolling ? history + coeffs.hist_rolling : nullptr,
                         coeffs.twisting ? history + coeffs.hist_twisting : nullptr, root,
                         atom->rmass[i], 0.0, ML::FIXED_J);
  ML::pack_contact_model(in, stride, wall_coeffs, model->dt, radi, 0.0, radi, scales_of(radi),
                         ML::LEVER_SHIFT_WALL);
}

/* ----------------------------------------------------------------------
   the results of contact c back (output q at out[q * stride]): its histories (the sub-models
   it has), the force and the torque on its atom
------------------------------------------------------------------------- */

void FixWallGranOpt::unpack_contact(const WallContact &c, const double *out, int stride)
{
  namespace ML = MarshallLanes;
  const int i = c.i;
  double *history = history_one[i];
  ML::unpack_histories(out, stride, history + coeffs.hist_tangential,
                       coeffs.rolling ? history + coeffs.hist_rolling : nullptr,
                       coeffs.twisting ? history + coeffs.hist_twisting : nullptr);
  double force[3], torque_i[3], torque_j[3];
  ML::unpack_forces(out, stride, 1.0, force, torque_i, torque_j);
  double *f = atom->f[i], *torque = atom->torque[i];
  for (int k = 0; k < 3; k++) {
    f[k] = f[k] + force[k];
    torque[k] = torque[k] + torque_i[k];
  }
}
