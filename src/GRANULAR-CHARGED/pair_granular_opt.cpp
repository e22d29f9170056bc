/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "pair_granular_opt.h"

#include "marshall_lanes.h"

#include "atom.h"
#include "error.h"
#include "fix.h"
#include "fix_charge_check.h"
#include "fix_neigh_history.h"
#include "force.h"
#include "gran_sub_mod.h"
#include "granular_model.h"
#include "math_extra.h"
#include "modify.h"
#include "neigh_list.h"
#include "neighbor.h"
#include "update.h"

#include <cstddef>
#include <cmath>
#include <algorithm>
#include <cstring>

using namespace LAMMPS_NS;
using namespace Granular_NS;
using namespace MathExtra;
namespace MK = MarshallKernels;
namespace ML = MarshallLanes;

/* ---------------------------------------------------------------------- */

PairGranularOpt::PairGranularOpt(LAMMPS *lmp) :
    PairGranular(lmp), fused_ready(false), generic_only(true), any_heat(false), ncontacts(0),
    history_update(true), hist_tangential(0), hist_rolling(0), hist_twisting(0),
    history_handover(lmp)
{
}

namespace {
// a per-atom 3-vector array of Atom (memory->create: row i at [0] + 3 i) indexed without its row
// pointers: one dependent load less for each atom a contact touches
struct AtomRows {
  double *first;
  explicit AtomRows(double **rows) : first(rows ? rows[0] : nullptr) {}
  double *operator[](int i) const { return first + 3 * static_cast<std::ptrdiff_t>(i); }
};
}    // namespace

PairGranularOpt::~PairGranularOpt()
{
  history_handover.pair_deleted(fix_history);
}

/* ---------------------------------------------------------------------- */

void PairGranularOpt::init_style()
{
  // the contact history across restarts and switches of style (granular_history_handover.h)
  const bool first_init = fix_history == nullptr;
#if GC_LAMMPS_VERSION >= 20260704
  if (first_init) history_handover.adopt_stored_history(id_history);    // named per instance
#endif
  PairGranular::init_style();
  if (first_init) history_handover.history_created(fix_history);
  fused_ready = false;    // init_one() may still mix new models: set up before the first compute
  FixChargeCheck::ensure(lmp);    // charges without a Coulomb solver: warned at init
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
  bool any_fused = false;
  any_heat = false;
  for (int n = 0; n < nmodels; n++) {
    FusedMarshall &f = fused[n];
    f.on = MarshallFusedSet::of_model(models_list[n], f);
    any_fused = any_fused || f.on;
    // a heat model needs PairGranular's heat-flow bookkeeping, which the fused loop does not do
    any_heat = any_heat || models_list[n]->sub_models[HEAT]->name != "none";
    if (!f.on) continue;
    hist_tangential = f.hist_tangential;
    hist_rolling = f.hist_rolling;
    hist_twisting = f.hist_twisting;
  }
  generic_only = !any_fused || any_heat;
  fused_ready = true;
}

/* ----------------------------------------------------------------------
   PairGranular::compute() with the Marshall set fused, as a recipe: set-up, gather (the
   contacts' life decided, the pairs outside the fused set handed to PairGranular::compute on a
   list of their own), the JKR roots in one batch, each contact packed into SIMD lanes, the
   fused kernel, each contact's results unpacked (marshall_lanes.h). The fused kernel does what
   GranularModel::check_contact() and calculate_forces() do with the Marshall sub-models, in the
   same order of operations, skipping what the set does not use (relative tangential speed,
   heat, classic torque scaling). The history of a pair is the same array at the same offsets,
   so fix neigh/history, restarts and single() see no difference. Every pair of the list is
   computed, as by PairGranular, whatever fixes hold its atoms (fix freeze, fix sleep/gran).
------------------------------------------------------------------------- */

void PairGranularOpt::compute(int eflag, int vflag)
{
  if (!fused_ready) setup_fused();
  // nothing to fuse, a heat model or rigid-body masses: the sub-model path does it all
  if (generic_only || fix_rigid) {
    PairGranular::compute(eflag, vflag);
    return;
  }
  begin_step(eflag, vflag);
  gather_contacts();
  history_handover.check_fresh_history(static_cast<bigint>(contacts.size()));
  const bigint generic_contacts = generic_i.empty() ? 0 : compute_generic_pairs(eflag, vflag);
  jkr_root.resize(jkr_overlap.size());
  JKRScaled::roots(jkr_overlap.size(), jkr_overlap.data(), jkr_root.data());
  compute_fused_contacts();
  ncontacts = static_cast<bigint>(contacts.size()) + generic_contacts;
}

/* ----------------------------------------------------------------------
   set-up of one compute(): history updates, tallies, the JKR scales of each type pair when every atom of a type has the same radius
------------------------------------------------------------------------- */

void PairGranularOpt::begin_step(int eflag, int vflag)
{
  history_update = update->setupflag == 0;
  for (int n = 0; n < nmodels; n++) models_list[n]->history_update = history_update;
  ev_init(eflag, vflag);
  type_scales();
}

/* ----------------------------------------------------------------------
   per type pair: R_eff and the JKR scales, valid when all atoms (local and ghost) of both
   types have one radius each (a monodisperse packing: two cube roots per type pair and step
   instead of per contact)
------------------------------------------------------------------------- */

void PairGranularOpt::type_scales()
{
  const int ntypes = atom->ntypes;
  const int nall = atom->nlocal + atom->nghost;
  const int *type = atom->type;
  const double *radius = atom->radius;
  type_radius.assign(ntypes + 1, -1.0);
  std::vector<char> mixed(ntypes + 1, 0);
  for (int i = 0; i < nall; i++) {
    double &r = type_radius[type[i]];
    if (r < 0.0)
      r = radius[i];
    else if (r != radius[i])
      mixed[type[i]] = 1;
  }
  pair_scales.assign(static_cast<size_t>(ntypes + 1) * (ntypes + 1), PairScales());
  for (int it = 1; it <= ntypes; it++)
    for (int jt = 1; jt <= ntypes; jt++) {
      const FusedMarshall &fm = fused[types_indices[it][jt]];
      if (!fm.on || mixed[it] || mixed[jt] || type_radius[it] <= 0.0 || type_radius[jt] <= 0.0)
        continue;
      PairScales &ps = pair_scales[it * (ntypes + 1) + jt];
      ps.valid = true;
      ps.reff = MK::effective_radius(type_radius[it], type_radius[jt]);
      ps.scales = MK::jkr_scales(ps.reff, fm.gamma, fm.emix);
    }
}

/* ----------------------------------------------------------------------
   the entry of pair_scales with R_eff and the JKR scales of pair i, j of a fused model: its
   type pair's if valid, else one appended for this pair (type_scales() drops those each step)
------------------------------------------------------------------------- */

inline int PairGranularOpt::scales_of(int i, int j, const FusedMarshall &fm)
{
  const int ntypes = atom->ntypes;
  const int type_pair = atom->type[i] * (ntypes + 1) + atom->type[j];
  if (pair_scales[type_pair].valid) return type_pair;
  PairScales &mine = pair_scales.emplace_back();
  mine.reff = MK::effective_radius(atom->radius[i], atom->radius[j]);
  mine.scales = MK::jkr_scales(mine.reff, fm.gamma, fm.emix);
  return static_cast<int>(pair_scales.size()) - 1;
}

/* ----------------------------------------------------------------------
   the pairs that interact, in list order: a fused pair's contact life decided (touch and
   history of an ended contact reset), its R_eff and scales and (adhesive) scaled overlap kept;
   a pair of another model copied with its contact flag and history to the generic list
------------------------------------------------------------------------- */

void PairGranularOpt::gather_contacts()
{
  int *type = atom->type;
  const AtomRows x(atom->x);
  double *radius = atom->radius;
  double *special_lj = force->special_lj;
  const int size_hist = get_size_history();
  const int inum = list->inum;
  contacts.clear();
  jkr_overlap.clear();
  generic_i.clear();
  generic_jj.clear();
  for (int ii = 0; ii < inum; ii++) {
    const int i = list->ilist[ii];
    int *touch = use_history ? fix_history->firstflag[i] : nullptr;
    double *allhistory = use_history ? fix_history->firstvalue[i] : nullptr;
    const int *jlist = list->firstneigh[i];
    const int jnum = list->numneigh[i];
    // i's data held in registers over its neighbors (the stores to touch flags, histories and
    // contacts would otherwise make the compiler read them again for each)
    const double xi[3] = {x[i][0], x[i][1], x[i][2]};
    const double radi = radius[i];
    const int *models_of_i = types_indices[type[i]];
    const FusedMarshall *fused_models = fused.data();
    for (int jj = 0; jj < jnum; jj++) {
      const int j = jlist[jj] & NEIGHMASK;
      const double factor_lj = special_lj[sbmask(jlist[jj])];
      if (factor_lj == 0) continue;
      const int model = models_of_i[type[j]];
      const FusedMarshall &fm = fused_models[model];
      if (!fm.on) {
        generic_i.push_back(i);
        generic_jj.push_back(jj);
        continue;
      }
      double dx[3];
      sub3(xi, x[j], dx);
      const double rsq = lensq3(dx);
      const double radsum = radi + radius[j];
      // most neighbors of a deposition do not touch: reject those before R_eff and the scales
      // (their history is zero already: zeroed when the contact ended, or new from the list)
      if (!touch[jj] && rsq >= radsum * radsum) continue;
      const int scales = scales_of(i, j, fm);
      const MK::JKRScales &sc = pair_scales[scales].scales;
      if (!MK::jkr_touch(touch[jj] != 0, rsq, radsum, sc.deltac)) {
        touch[jj] = 0;
        double *history = &allhistory[size_hist * jj];
        for (int k = 0; k < size_hist; k++) history[k] = 0.0;
        continue;
      }
      touch[jj] = 1;
      if (fm.gamma != 0.0) jkr_overlap.push_back(MK::scaled_overlap(sc, radsum - sqrt(rsq)));
      // written field by field: a whole struct built on the stack and copied stalls the
      // store-to-load forwarding of its parts
      Contact &c = contacts.emplace_back();
      c.i = i;
      c.jj = jj;
      c.j = j;
      c.model = model;
      c.scales = scales;
      c.factor_lj = factor_lj;
      copy3(dx, c.dx);
    }
  }
}

/* ----------------------------------------------------------------------
   the pairs outside the fused set by PairGranular::compute itself, on a neighbor list (and
   contact flags and histories) holding only them; their flags and histories are copied back.
   Returns the number of those pairs that touch.
------------------------------------------------------------------------- */

bigint PairGranularOpt::compute_generic_pairs(int eflag, int vflag)
{
  build_generic_list();
  NeighList *full = list;
  int **flags = use_history ? fix_history->firstflag : nullptr;
  double **values = use_history ? fix_history->firstvalue : nullptr;
  list = generic_list.get();
  if (use_history) {
    fix_history->firstflag = generic_firsttouch.data();
    fix_history->firstvalue = generic_firsthistory.data();
  }
  PairGranular::compute(eflag, vflag);
  list = full;
  if (!use_history) return 0;
  fix_history->firstflag = flags;
  fix_history->firstvalue = values;
  const int size_hist = get_size_history();
  bigint touching = 0;
  for (size_t k = 0; k < generic_i.size(); k++) {
    const int i = generic_i[k], jj = generic_jj[k];
    flags[i][jj] = generic_touch[k];
    touching += generic_touch[k] != 0;
    std::copy(&generic_history[size_hist * k], &generic_history[size_hist * (k + 1)],
              &values[i][size_hist * jj]);
  }
  return touching;
}

/* ----------------------------------------------------------------------
   the neighbor list of the pairs outside the fused set (generic_i, generic_jj) with copies of
   their contact flags and histories: arrays of this style, in the layout of the full list's
------------------------------------------------------------------------- */

void PairGranularOpt::build_generic_list()
{
  const int nall = atom->nlocal + atom->nghost;
  const int size_hist = use_history ? get_size_history() : 0;
  const size_t n = generic_i.size();
  generic_neigh.resize(n);
  generic_touch.assign(n, 0);
  generic_history.assign(n * size_hist, 0.0);
  generic_atoms.clear();
  generic_numneigh.assign(nall, 0);
  generic_firstneigh.assign(nall, nullptr);
  generic_firsttouch.assign(nall, nullptr);
  generic_firsthistory.assign(nall, nullptr);
  for (size_t k = 0; k < n; k++) {
    const int i = generic_i[k], jj = generic_jj[k];
    generic_neigh[k] = list->firstneigh[i][jj];
    if (use_history) {
      generic_touch[k] = fix_history->firstflag[i][jj];
      const double *h = &fix_history->firstvalue[i][size_hist * jj];
      std::copy(h, h + size_hist, &generic_history[size_hist * k]);
    }
    if (generic_numneigh[i]++ > 0) continue;    // the entries of one atom are consecutive
    generic_atoms.push_back(i);
    generic_firstneigh[i] = &generic_neigh[k];
    generic_firsttouch[i] = &generic_touch[k];
    generic_firsthistory[i] = &generic_history[size_hist * k];
  }
  if (!generic_list) {
    generic_list = std::make_unique<NeighList>(lmp);
    generic_list->copymode = 1;    // its arrays are this style's vectors: never freed by it
  }
  generic_list->inum = static_cast<int>(generic_atoms.size());
  generic_list->ilist = generic_atoms.data();
  generic_list->numneigh = generic_numneigh.data();
  generic_list->firstneigh = generic_firstneigh.data();
}

/* ----------------------------------------------------------------------
   the fused contacts in list order, a chunk at a time (its lanes blocks stay in the L1
   cache): the adhesive contacts packed into lanes blocks and evaluated by the lanes kernel
   (marshall_lanes.h) on the default SIMD path, the others (no adhesion: Hertz's law) by the
   scalar instantiation of the same kernel; then each contact's results unpacked and summed in
   list order, so the sums over contacts are those of a scalar loop
------------------------------------------------------------------------- */

void PairGranularOpt::compute_fused_contacts()
{
  constexpr int W = ML::WIDTH;
  constexpr std::size_t CHUNK = 8 * W;
  constexpr std::size_t PREFETCH = 4;
  const std::size_t n = contacts.size();
  lane_in.resize(CHUNK * ML::N_INPUT);
  lane_out.resize(CHUNK * ML::N_OUTPUT);
  lane_of.resize(CHUNK);
  // lane l's first input and output: block l / W, offset l % W, WIDTH apart
  auto lane_input = [&](int l) { return ML::lane_input(lane_in.data(), l); };
  auto lane_output = [&](int l) { return ML::lane_output(lane_out.data(), l); };

  const AtomRows v(atom->v), omega(atom->omega), f(atom->f), torque(atom->torque);
  const double *radius = atom->radius, *rmass = atom->rmass;
  const int *mask = atom->mask;
  const int nlocal = atom->nlocal;
  const int newton_pair = force->newton_pair;
  double **allhistory = fix_history->firstvalue;
  const int size_hist = get_size_history();
  // a contact's inputs (marshall_lanes.h) in two parts: those of its atoms and history (s: its
  // JKR root, unused without adhesion) and those of its model and type pair, the same for every
  // contact of one type pair of one radius each
  auto pack_state = [&](const Contact &c, double s, double *in, int stride) {
    const int i = c.i, j = c.j;
    const FusedMarshall &fm = fused[c.model];
    const double *history = &allhistory[i][size_hist * c.jj];
    double fixed = ML::FIXED_NONE;
    if (mask[i] & freeze_group_bit) fixed = ML::FIXED_I;
    if (mask[j] & freeze_group_bit) fixed = ML::FIXED_J;
    ML::pack_contact_state(in, stride, c.dx, v[i], v[j], omega[i], omega[j],
                           history + hist_tangential, fm.rolling ? history + hist_rolling : nullptr,
                           fm.twisting ? history + hist_twisting : nullptr, s, rmass[i], rmass[j],
                           fixed);
  };
  auto pack_model = [&](const Contact &c, double *in, int stride) {
    const PairScales &ps = pair_scales[c.scales];
    ML::pack_contact_model(in, stride, fused[c.model], model_dt[c.model], radius[c.i],
                           radius[c.j], ps.reff, ps.scales, ML::LEVER_SHIFT_PAIR);
  };
  auto pack_contact = [&](const Contact &c, double s, double *in, int stride) {
    pack_state(c, s, in, stride);
    pack_model(c, in, stride);
  };
  // the force and torque on atom i summed in registers over its consecutive contacts (those of
  // one entry of the neighbor list, none of which has i as its neighbor j): f[i] and torque[i]
  // are read at the first and written after the last, the same additions in the same order
  struct SumsOfI {
    int i = -1;
    double f[3], torque[3];
  } sums;
  auto store_sums = [&]() {
    if (sums.i < 0) return;
    copy3(sums.f, f[sums.i]);
    copy3(sums.torque, torque[sums.i]);
  };
  // a contact's results: its histories (the sub-models it has), forces and torques times
  // factor_lj to the atoms, the tallies
  auto unpack_contact = [&](const Contact &c, const double *out, int stride) {
    const int i = c.i, j = c.j;
    const FusedMarshall &fm = fused[c.model];
    double *history = &allhistory[i][size_hist * c.jj];
    ML::unpack_histories(out, stride, history + hist_tangential,
                         fm.rolling ? history + hist_rolling : nullptr,
                         fm.twisting ? history + hist_twisting : nullptr);
    if (i != sums.i) {
      store_sums();
      sums.i = i;
      copy3(f[i], sums.f);
      copy3(torque[i], sums.torque);
    }
    double forces[3], torque_i[3], torque_j[3];
    ML::unpack_forces(out, stride, c.factor_lj, forces, torque_i, torque_j);
    for (int k = 0; k < 3; k++) {
      sums.f[k] = sums.f[k] + forces[k];
      sums.torque[k] = sums.torque[k] + torque_i[k];
    }
    if (newton_pair || j < nlocal)
      for (int k = 0; k < 3; k++) {
        f[j][k] = f[j][k] - forces[k];
        torque[j][k] = torque[j][k] + torque_j[k];
      }
    if (evflag)
      ev_tally_xyz(i, j, nlocal, newton_pair, 0.0, 0.0, forces[0], forces[1], forces[2], c.dx[0],
                   c.dx[1], c.dx[2]);
  };

  model_dt.resize(nmodels);
  for (int m = 0; m < nmodels; m++) model_dt[m] = models_list[m]->dt;
  // every contact of one model and one type pair whose atoms have one radius each (a
  // monodisperse packing of one type): the shared inputs are written into every lane once
  bool one_pair = n > 0 && pair_scales[contacts[0].scales].valid;
  for (std::size_t k = 0; k < n && one_pair; k++)
    one_pair = contacts[k].model == contacts[0].model && contacts[k].scales == contacts[0].scales;
  if (one_pair)
    for (int l = 0; l < static_cast<int>(CHUNK); l++) pack_model(contacts[0], lane_input(l), W);
  std::size_t next_root = 0;
  for (std::size_t start = 0; start < n; start += CHUNK) {
    const std::size_t m = std::min(CHUNK, n - start);
    int nlanes = 0;
    for (std::size_t k = 0; k < m; k++) {
      const Contact &c = contacts[start + k];
      // the neighbor's data a few contacts ahead: each contact's loads then overlap with the
      // packing of the previous ones
      if (start + k + PREFETCH < n) {
        const int jn = contacts[start + k + PREFETCH].j;
        __builtin_prefetch(v[jn]);
        __builtin_prefetch(omega[jn]);
      }
      if (fused[c.model].gamma == 0.0) {
        lane_of[k] = -1;
        continue;
      }
      lane_of[k] = nlanes;
      if (one_pair)
        pack_state(c, jkr_root[next_root++], lane_input(nlanes), W);
      else
        pack_contact(c, jkr_root[next_root++], lane_input(nlanes), W);
      nlanes++;
    }
    // a short last block: its other lanes evaluate copies of its first contact, not scattered
    const std::size_t nblocks = ML::pad_last_block(lane_in.data(), nlanes);
    ML::contacts_in_lanes(nblocks, lane_in.data(), lane_out.data(), history_update);

    for (std::size_t k = 0; k < m; k++) {
      const Contact &c = contacts[start + k];
      if (k + PREFETCH < m) {
        const int jn = contacts[start + k + PREFETCH].j;
        __builtin_prefetch(f[jn], 1);
        __builtin_prefetch(torque[jn], 1);
      }
      if (lane_of[k] >= 0) {
        unpack_contact(c, lane_output(lane_of[k]), W);
      } else {
        double in[ML::N_INPUT], out[ML::N_OUTPUT];
        pack_contact(c, 1.0, in, 1);
        ML::marshall_contact(in, out, history_update);
        unpack_contact(c, out, 1);
      }
    }
  }
  store_sums();
}
