/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "pair_granular_opt.h"

#include "fix_sleep_gran.h"

#include "gran_sub_mod_damping_marshall.h"
#include "gran_sub_mod_normal_jkr_marshall.h"
#include "gran_sub_mod_rolling_marshall.h"
#include "gran_sub_mod_tangential_marshall.h"
#include "gran_sub_mod_twisting_marshall_jkr.h"

#include "atom.h"
#include "comm.h"
#include "error.h"
#include "fix.h"
#include "fix_neigh_history.h"
#include "force.h"
#include "gran_sub_mod.h"
#include "granular_model.h"
#include "math_extra.h"
#include "memory.h"
#include "modify.h"
#include "neigh_list.h"
#include "neighbor.h"
#include "update.h"

#include <cmath>
#include <cstring>

using namespace LAMMPS_NS;
using namespace Granular_NS;
using namespace MathExtra;
namespace MK = MarshallKernels;

/* ---------------------------------------------------------------------- */

PairGranularOpt::PairGranularOpt(LAMMPS *lmp) :
    PairGranular(lmp), fused_ready(false), generic_only(true), any_heat(false), sleep_fix(nullptr),
    active_build(-1), active_generation(-1), ncontacts(0), hist_tangential(0), hist_rolling(0), hist_twisting(0)
{
}

/* ---------------------------------------------------------------------- */

void PairGranularOpt::init_style()
{
  PairGranular::init_style();
  fused_ready = false;    // init_one() may still mix new models: set up before the first compute
  auto sleepers = modify->get_fix_by_style("^sleep/gran$");
  sleep_fix = sleepers.empty() ? nullptr : dynamic_cast<FixSleepGran *>(sleepers.front());
  if (sleepers.size() > 1) error->all(FLERR, "Only one fix sleep/gran may be defined");
  active_build = active_generation = -1;
}

/* ---------------------------------------------------------------------- */

bool PairGranularOpt::model_is_fused(int n) const
{
  return fused_ready && !generic_only && n >= 0 && n < (int) fused.size() && fused[n].on;
}

/* ----------------------------------------------------------------------
   which models the fused kernel covers: jkr/marshall + damping marshall or marshall/printed +
   tangential marshall, rolling none | marshall | marshall/particle, twisting none |
   marshall/jkr, heat none, without synchronized_verlet (LAMMPS 4Jul2026; limit_damping cannot
   be used with a cohesive model). The history offsets are those PairGranular::init_style() gave
   the sub-models: the same for every model.
------------------------------------------------------------------------- */

void PairGranularOpt::setup_fused()
{
  fused.assign(nmodels, FusedMarshall());
  for (int n = 0; n < nmodels; n++) {
    GranularModel *model = models_list[n];
    auto *normal = dynamic_cast<GranSubModNormalJKRMarshall *>(model->normal_model);
    auto *damping = dynamic_cast<GranSubModDampingMarshall *>(model->damping_model);
    auto *tangential = dynamic_cast<GranSubModTangentialMarshall *>(model->tangential_model);
    auto *rolling = dynamic_cast<GranSubModRollingMarshall *>(model->rolling_model);
    auto *twisting = dynamic_cast<GranSubModTwistingMarshallJKR *>(model->twisting_model);
    const bool rolling_ok = rolling || model->rolling_model->name == "none";
    const bool twisting_ok = twisting || model->twisting_model->name == "none";
    bool ok = normal && damping && tangential && rolling_ok && twisting_ok &&
        model->sub_models[HEAT]->name == "none" && !model->limit_damping;
#if GC_LAMMPS_VERSION >= 20260704
    ok = ok && !model->synchronized_verlet;
#endif
    if (!ok) continue;

    FusedMarshall &f = fused[n];
    f.on = true;
    f.emix = normal->get_emix();
    f.gamma = normal->get_surface_energy();
    f.alpha = damping->get_alpha();
    f.mass_factor = damping->get_mass_factor();
    f.k_t = tangential->get_k();
    f.mu = tangential->get_mu();
    f.rolling = rolling != nullptr;
    if (rolling) {
      f.theta_crit = rolling->get_theta_crit();
      f.roll_radius_factor = rolling->get_pair_radius_factor();
    }
    f.twisting = twisting != nullptr;

    hist_tangential = model->tangential_model->history_index;
    hist_rolling = model->rolling_model->history_index;
    hist_twisting = model->twisting_model->history_index;
  }
  // a heat model needs PairGranular's heat-flow bookkeeping, which the fused loop does not do
  bool any_fused = false;
  any_heat = false;
  for (int n = 0; n < nmodels; n++) {
    any_fused = any_fused || fused[n].on;
    any_heat = any_heat || models_list[n]->sub_models[HEAT]->name != "none";
  }
  generic_only = !any_fused || any_heat;
  fused_ready = true;
}

/* ----------------------------------------------------------------------
   PairGranular::compute() with the Marshall set fused. The generic branch is PairGranular's
   loop body; the fused branch does what GranularModel::check_contact() and calculate_forces()
   do with the Marshall sub-models, in the same order of operations, skipping what the set does
   not use (relative tangential speed, heat, classic torque scaling). The history of a pair is
   the same array at the same offsets, so fix neigh/history, restarts and single() see no
   difference.
------------------------------------------------------------------------- */

void PairGranularOpt::compute(int eflag, int vflag)
{
  if (!fused_ready) setup_fused();

  if (sleep_fix && (any_heat || fix_rigid))
    error->all(FLERR, "Fix sleep/gran cannot be used with a heat model or rigid bodies");
  if (!sleep_fix && (generic_only || fix_rigid)) {
    // nothing to fuse, a heat model, or rigid-body masses: the sub-model path does it all
    PairGranular::compute(eflag, vflag);
    return;
  }

  const bool history_update = update->setupflag == 0;
  for (int n = 0; n < nmodels; n++) models_list[n]->history_update = history_update;

  ev_init(eflag, vflag);

  int *type = atom->type;
  double **x = atom->x;
  double **v = atom->v;
  double **f = atom->f;
  double **omega = atom->omega;
  double **torque = atom->torque;
  double *radius = atom->radius;
  double *rmass = atom->rmass;
  int *mask = atom->mask;
  const int nlocal = atom->nlocal;
  const int newton_pair = force->newton_pair;
  double *special_lj = force->special_lj;
  const int size_hist = get_size_history();

  const int inum = list->inum;
  int *ilist = list->ilist;
  int *numneigh = list->numneigh;
  int **firstneigh = list->firstneigh;
  int **firsttouch = use_history ? fix_history->firstflag : nullptr;
  double **firsthistory = use_history ? fix_history->firstvalue : nullptr;

  // sleepers: pairs of two sleepers are skipped (history kept); the sleeper's share of a pair
  // with an awake atom is also summed into the fix's push array (its wake test)
  const double *asleep = sleep_fix ? sleep_fix->sleeping() : nullptr;
  double **push = sleep_fix ? sleep_fix->awake_push() : nullptr;
  double *ncontact = sleep_fix ? sleep_fix->contact_count() : nullptr;
  if (asleep) update_active(asleep);
  const int nactive = asleep ? static_cast<int>(active.size()) : inum;
  bigint contacts = 0;

  // pass 1: the pairs that interact, in list order, their contact life decided (touch and
  // history of an ended contact reset); the adhesive fused contacts' scaled overlaps collected
  contact_i.clear();
  contact_jj.clear();
  jkr_overlap.clear();
  for (int aa = 0; aa < nactive; aa++) {
    const int ii = asleep ? active[aa] : aa;
    const int i = ilist[ii];
    const int itype = type[i];
    int *touch = use_history ? firsttouch[i] : nullptr;
    double *allhistory = use_history ? firsthistory[i] : nullptr;
    int *jlist = firstneigh[i];
    const int jnum = numneigh[i];

    for (int jj = 0; jj < jnum; jj++) {
      int j = jlist[jj];
      if (special_lj[sbmask(j)] == 0) continue;
      j &= NEIGHMASK;
      if (asleep && asleep[i] != 0.0 && asleep[j] != 0.0) continue;
      const int imodel = types_indices[itype][type[j]];
      if (fused[imodel].on) {
        FusedMarshall &fm = fused[imodel];
        // contact geometry and life (GranularModel::check_contact, jkr/marshall touch)
        double dx[3];
        sub3(x[i], x[j], dx);
        const double rsq = lensq3(dx);
        const double radsum = radius[i] + radius[j];
        // most neighbors of a deposition do not touch: reject those before R_eff and the scales
        // (their history is zero already: zeroed when the contact ended, or new from the list)
        if (!touch[jj] && rsq >= radsum * radsum) continue;
        use_radii(fm, radius[i], radius[j]);
        if (!MK::jkr_touch(touch[jj] != 0, rsq, radsum, fm.scales.deltac)) {
          touch[jj] = 0;
          double *history = &allhistory[size_hist * jj];
          for (int k = 0; k < size_hist; k++) history[k] = 0.0;
          continue;
        }
        touch[jj] = 1;
        if (fm.gamma != 0.0) jkr_overlap.push_back(MK::scaled_overlap(fm.scales, radsum - sqrt(rsq)));
      }
      contact_i.push_back(i);
      contact_jj.push_back(jj);
    }
  }

  // the JKR roots of all adhesive contacts in one vectorised call
  jkr_root.resize(jkr_overlap.size());
  JKRScaled::roots(jkr_overlap.size(), jkr_overlap.data(), jkr_root.data());

  // pass 2: the forces, pair by pair in list order (the sums of the one-pass loop)
  std::size_t next_root = 0;
  const std::size_t npairs = contact_i.size();
  for (std::size_t c = 0; c < npairs; c++) {
    const int i = contact_i[c];
    const int jj = contact_jj[c];
    const int itype = type[i];
    int *touch = use_history ? firsttouch[i] : nullptr;
    double *allhistory = use_history ? firsthistory[i] : nullptr;
    int j = firstneigh[i][jj];
    const double factor_lj = special_lj[sbmask(j)];
    j &= NEIGHMASK;

    const int jtype = type[j];
    const int imodel = types_indices[itype][jtype];
    GranularModel *model = models_list[imodel];
    double *history = use_history ? &allhistory[size_hist * jj] : nullptr;

    double forces[3], torquesi[3], torquesj[3], dx[3];
    if (fused[imodel].on) {
      FusedMarshall &fm = fused[imodel];
      sub3(x[i], x[j], dx);
      const double rsq = lensq3(dx);
      const double radi = radius[i];
      const double radj = radius[j];
      const double radsum = radi + radj;
      use_radii(fm, radi, radj);
      const double reff = fm.reff;

      const double mi = rmass[i];
      const double mj = rmass[j];
      if (mi != fm.mi || mj != fm.mj) {
        fm.mi = mi;
        fm.mj = mj;
        fm.meff = mi * mj / (mi + mj);
      }
      double meff = fm.meff;
      if (mask[i] & freeze_group_bit) meff = mj;
      if (mask[j] & freeze_group_bit) meff = mi;
      if (asleep) sleeper_mass(asleep[i], asleep[j], mi, mj, meff);
      if (meff != fm.sqrt_mass_of) {
        fm.sqrt_mass_of = meff;
        fm.sqrt_mass = MK::damping_sqrt_mass(fm.mass_factor, meff);
      }
      const double dt = model->dt;

      // kinematics (GranularModel::calculate_forces)
      const double r = sqrt(rsq);
      const double rinv = 1.0 / r;
      const double delta = radsum - r;
      double vr[3], nx[3], vn[3], vt[3], wr[3], temp[3], vtr[3];
      sub3(v[i], v[j], vr);
      scale3(rinv, dx, nx);
      const double vnnr = dot3(vr, nx);
      scale3(vnnr, nx, vn);
      sub3(vr, vn, vt);
      scaleadd3(radi, omega[i], radj, omega[j], wr);
      cross3(wr, nx, temp);
      sub3(vt, temp, vtr);

      // normal: JKR with Marshall damping (the root from pass 1)
      const MK::NormalForce nf = (fm.gamma != 0.0)
          ? MK::jkr_normal_force_of_root(fm.scales, jkr_root[next_root++])
          : MK::jkr_normal_force(fm.scales, fm.gamma, fm.emix, delta, reff);
      const double damp_prefactor = MK::damping_prefactor(fm.alpha, fm.sqrt_mass, nf);
      const double fntot = nf.fne + (-damp_prefactor * vnnr);
      const double fncrit = MK::critical_force(nf);

      // sliding
      double fs[3];
      MK::tangential_force(&history[hist_tangential], nx, vtr, dt, fm.k_t * nf.a,
                           damp_prefactor, fncrit * fm.mu, history_update, fs);

      scale3(fntot, nx, forces);
      add3(forces, fs, forces);
      cross3(nx, fs, torquesi);
      scale3(-1, torquesi);
      copy3(torquesi, torquesj);
      scale3(radi - 0.5 * delta, torquesi);
      scale3(radj - 0.5 * delta, torquesj);

      if (fm.rolling || fm.twisting) {
        double relrot[3];
        sub3(omega[i], omega[j], relrot);
        if (fm.rolling) {
          // rolling velocity, eq. 31 of Wang et al, Particuology 23, 49 (2015)
          double vrl[3], fr[3], torroll[3];
          vrl[0] = reff * (relrot[1] * nx[2] - relrot[2] * nx[1]);
          vrl[1] = reff * (relrot[2] * nx[0] - relrot[0] * nx[2]);
          vrl[2] = reff * (relrot[0] * nx[1] - relrot[1] * nx[0]);
          MK::rolling_force(&history[hist_rolling], nx, vrl, dt,
                            fm.theta_crit * (fm.roll_radius_factor * reff), nf.adhesive / reff,
                            history_update, fr);
          cross3(nx, fr, torroll);
          scale3(reff, torroll);
          add3(torquesi, torroll, torquesi);
          sub3(torquesj, torroll, torquesj);
        }
        if (fm.twisting) {
          // omega_T (eq. 29 of Marshall 2009)
          const double magtwist = dot3(relrot, nx);
          const double moment = MK::twisting_moment(history[hist_twisting], magtwist, dt, nf.a,
                                                    fm.k_t, damp_prefactor, fm.mu * fncrit,
                                                    history_update);
          double tortwist[3];
          scale3(moment, nx, tortwist);
          add3(torquesi, tortwist, torquesi);
          sub3(torquesj, tortwist, torquesj);
        }
      }
    } else {
      // PairGranular's sub-model path for this pair
      model->xi = x[i];
      model->xj = x[j];
      model->radi = radius[i];
      model->radj = radius[j];
      model->i = i;
      model->j = j;
      model->itype = itype;
      model->jtype = jtype;
      if (use_history) model->touch = touch[jj];
      if (!model->check_contact()) {
        if (use_history) {
          touch[jj] = 0;
          for (int k = 0; k < size_hist; k++) history[k] = 0.0;
        }
        continue;
      }
      if (use_history) touch[jj] = 1;

      const double mi = rmass[i];
      const double mj = rmass[j];
      double meff = mi * mj / (mi + mj);
      if (mask[i] & freeze_group_bit) meff = mj;
      if (mask[j] & freeze_group_bit) meff = mi;
      if (asleep) sleeper_mass(asleep[i], asleep[j], mi, mj, meff);
      model->meff = meff;
      model->vi = v[i];
      model->vj = v[j];
      model->omegai = omega[i];
      model->omegaj = omega[j];
      model->history = history;
      model->calculate_forces();
      copy3(model->forces, forces);
      copy3(model->torquesi, torquesi);
      copy3(model->torquesj, torquesj);
      copy3(model->dx, dx);
    }

    // apply forces & torques
    contacts++;
    scale3(factor_lj, forces);
    add3(f[i], forces, f[i]);
    scale3(factor_lj, torquesi);
    add3(torque[i], torquesi, torque[i]);
    if (newton_pair || j < nlocal) {
      sub3(f[j], forces, f[j]);
      scale3(factor_lj, torquesj);
      add3(torque[j], torquesj, torque[j]);
    }
    if (evflag)
      ev_tally_xyz(i, j, nlocal, newton_pair, 0.0, 0.0, forces[0], forces[1], forces[2], dx[0],
                   dx[1], dx[2]);
    if (asleep) {
      ncontact[i] += 1.0;
      if (newton_pair || j < nlocal) ncontact[j] += 1.0;
      if (asleep[i] != 0.0) add3(push[i], forces, push[i]);
      if (asleep[j] != 0.0 && (newton_pair || j < nlocal)) sub3(push[j], forces, push[j]);
    }
  }
  ncontacts = contacts;
}

/* ----------------------------------------------------------------------
   the list entries that can hold a computed pair: an awake atom, or a sleeper with an awake
   neighbor
------------------------------------------------------------------------- */

void PairGranularOpt::update_active(const double *asleep)
{
  if (active_build == neighbor->lastcall && active_generation == sleep_fix->generation()) return;
  active_build = neighbor->lastcall;
  active_generation = sleep_fix->generation();
  active.clear();
  const int inum = list->inum;
  for (int ii = 0; ii < inum; ii++) {
    const int i = list->ilist[ii];
    bool keep = asleep[i] == 0.0;
    const int *jlist = list->firstneigh[i];
    for (int jj = 0; !keep && jj < list->numneigh[i]; jj++) keep = asleep[jlist[jj] & NEIGHMASK] == 0.0;
    if (keep) active.push_back(ii);
  }
}

/* ---------------------------------------------------------------------- */

void PairGranularOpt::mark_touching_sleepers(const double *flag, double *mark) const
{
  double **x = atom->x;
  double *radius = atom->radius;
  for (int ii = 0; ii < list->inum; ii++) {
    const int i = list->ilist[ii];
    const int *jlist = list->firstneigh[i];
    const int *touch = use_history ? fix_history->firstflag[i] : nullptr;
    for (int jj = 0; jj < list->numneigh[i]; jj++) {
      const int j = jlist[jj] & NEIGHMASK;
      const bool pushed_sleeper = (flag[i] < 0.0 && flag[j] > 0.0) || (flag[j] < 0.0 && flag[i] > 0.0);
      if (!pushed_sleeper) continue;
      bool touching;
      if (touch) {
        touching = touch[jj] != 0;
      } else {
        double dx[3];
        sub3(x[i], x[j], dx);
        const double radsum = radius[i] + radius[j];
        touching = lensq3(dx) < radsum * radsum;
      }
      if (!touching) continue;
      if (flag[i] > 0.0) mark[i] = 1.0;
      if (flag[j] > 0.0) mark[j] = 1.0;
    }
  }
}
