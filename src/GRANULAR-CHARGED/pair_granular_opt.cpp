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
    history_update(true), hist_tangential(0), hist_rolling(0), hist_twisting(0), one_pair(false),
    list_stale(true), list_rebuilds(0), history_handover(lmp)
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
  list_stale = true;      // models, groups or special factors may have changed
  FixChargeCheck::ensure(lmp);    // charges without a Coulomb solver: warned at init
  // fix sleep/gran with pairs awake: the pairs of two sleepers are left out
  sleep_fix_id.clear();
  for (auto *f : modify->get_fix_by_style("^sleep/gran$")) {
    int dim = 0;
    const auto *on = static_cast<const int *>(f->extract("pairs_awake", dim));
    if (on && *on) sleep_fix_id = f->id;
  }
}

/* ----------------------------------------------------------------------
   the sleeping flags (local and ghost atoms, current from fix sleep/gran's pre_force on) and
   the generation of the sleeping set when fix sleep/gran leaves out the pairs of two sleepers;
   no flags otherwise. The flags are read anew each step: the fix reallocates them as atoms come.
------------------------------------------------------------------------- */

PairGranularOpt::Sleepers PairGranularOpt::sleepers_to_skip()
{
  Sleepers s;
  if (sleep_fix_id.empty()) return s;
  Fix *f = modify->get_fix_by_id(sleep_fix_id);
  if (!f || strcmp(f->style, "sleep/gran") != 0) return s;
  int dim = 0;
  const auto *on = static_cast<const int *>(f->extract("pairs_awake", dim));
  if (!on || !*on) return s;
  const auto *generation = static_cast<const bigint *>(f->extract("generation", dim));
  s.asleep = static_cast<const double *>(f->extract("sleeping", dim));
  if (s.asleep && generation) {
    s.fix = f;
    s.generation = *generation;
  } else {
    s.asleep = nullptr;
  }
  return s;
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
   PairGranular::compute() with the Marshall set fused, as a recipe: set-up, the contact list
   (kept between neighbor-list builds), the pairs outside the fused set handed to
   PairGranular::compute on a list of their own, then a chunk of contacts at a time: their life
   decided, each touching one packed into SIMD lanes, their JKR roots in one batch, the fused
   kernel, each contact's results unpacked (marshall_lanes.h). The fused kernel does what
   GranularModel::check_contact() and calculate_forces() do with the Marshall sub-models, in the
   same order of operations, skipping what the set does not use (relative tangential speed,
   heat, classic torque scaling). The history of a pair is the same array at the same offsets,
   so fix neigh/history, restarts and single() see no difference. Every pair of the list is
   computed, as by PairGranular, whatever fixes hold its atoms (fix freeze, fix sleep/gran),
   except with fix sleep/gran ... pairs awake: the pairs of two sleepers are then left out of the
   contact list (no force, torque or virial; contact flag and history left as they are), which
   is built again whenever the sleeping set may have changed.
------------------------------------------------------------------------- */

void PairGranularOpt::compute(int eflag, int vflag)
{
  if (!fused_ready) setup_fused();
  const Sleepers sleepers = sleepers_to_skip();
  // nothing to fuse, a heat model or rigid-body masses: the sub-model path does it all (on the
  // generic list of the pairs not of two sleepers, when those are left out)
  if ((generic_only || fix_rigid) && !sleepers.asleep) {
    PairGranular::compute(eflag, vflag);
    return;
  }
  begin_step(eflag, vflag);
  if (!contact_list_current(sleepers)) build_contact_list(sleepers.asleep);
  // the pairs outside the fused set first: their forces are summed before the fused contacts'
  const bigint generic_contacts = generic_i.empty() ? 0 : compute_generic_pairs(eflag, vflag);
  const bigint fused_contacts = compute_fused_contacts();
  history_handover.check_fresh_history(fused_contacts);
  ncontacts = fused_contacts + generic_contacts;
}

/* ----------------------------------------------------------------------
   set-up of one compute(): history updates, tallies
------------------------------------------------------------------------- */

void PairGranularOpt::begin_step(int eflag, int vflag)
{
  history_update = update->setupflag == 0;
  for (int n = 0; n < nmodels; n++) models_list[n]->history_update = history_update;
  ev_init(eflag, vflag);
}

/* ----------------------------------------------------------------------
   is the contact list the one of this neighbor list, with the radii and types it was built
   from? A build of the neighbor list (neighbor->ago == 0, or another build count or list),
   another number of atoms, init_style() or any atom's new radius (fix adapt, set) or type
   makes it stale, and so does a new generation of the sleeping set when the pairs of two
   sleepers are left out.
------------------------------------------------------------------------- */

bool PairGranularOpt::contact_list_current(const Sleepers &sleepers)
{
  const int nall = atom->nlocal + atom->nghost;
  ListStamp now;
  now.list = list;
  now.ilist = list->ilist;
  now.firstneigh = list->firstneigh;
  now.firstflag = fix_history ? fix_history->firstflag : nullptr;
  now.firstvalue = fix_history ? fix_history->firstvalue : nullptr;
  now.build = neighbor->ncalls;
  now.build_step = neighbor->lastcall;
  now.sleep_fix = sleepers.fix;
  now.sleepers = sleepers.asleep ? sleepers.generation : -1;
  now.inum = list->inum;
  now.nall = nall;
  const bool current = !list_stale && neighbor->ago != 0 && now == list_stamp &&
      std::equal(atom->radius, atom->radius + nall, list_radius.begin()) &&
      std::equal(atom->type, atom->type + nall, list_type.begin());
  list_stamp = now;
  return current;
}

/* ----------------------------------------------------------------------
   per type pair: R_eff and the JKR scales, valid when all atoms (local and ghost) of both
   types have one radius each (a monodisperse packing: two cube roots per type pair and build
   of the contact list instead of per pair)
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
   type pair's if valid, else one appended for this pair (type_scales() drops those at each
   rebuild of the contact list)
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
   the contact list from the neighbor list, in list order: each pair of a fused model (with
   its R_eff and scales, special factor, contact flag and history in fix neigh/history's pages),
   and the pairs of other models for the generic list (all pairs when no model is fused, a heat
   model or rigid bodies); the radii and types it was built from. With sleeping flags (fix
   sleep/gran ... pairs awake) the pairs of two sleepers are left out: a ghost's flag is its
   owner's, so every rank that holds a pair decides alike.
------------------------------------------------------------------------- */

void PairGranularOpt::build_contact_list(const double *asleep)
{
  const int nall = atom->nlocal + atom->nghost;
  const int *type = atom->type;
  const double *radius = atom->radius;
  const double *special_lj = force->special_lj;
  const int size_hist = get_size_history();
  const bool all_generic = generic_only || fix_rigid;
  type_scales();
  candidates.clear();
  generic_i.clear();
  generic_jj.clear();
  for (int ii = 0; ii < list->inum; ii++) {
    const int i = list->ilist[ii];
    // no history: generic pairs only (a fused model keeps one)
    int *touch = fix_history ? fix_history->firstflag[i] : nullptr;
    double *allhistory = fix_history ? fix_history->firstvalue[i] : nullptr;
    const int *jlist = list->firstneigh[i];
    const int jnum = list->numneigh[i];
    const bool i_asleep = asleep && asleep[i] != 0.0;
    for (int jj = 0; jj < jnum; jj++) {
      const int j = jlist[jj] & NEIGHMASK;
      const double factor_lj = special_lj[sbmask(jlist[jj])];
      if (factor_lj == 0) continue;
      if (i_asleep && asleep[j] != 0.0) continue;
      const int model = types_indices[type[i]][type[j]];
      const FusedMarshall &fm = fused[model];
      if (all_generic || !fm.on) {
        generic_i.push_back(i);
        generic_jj.push_back(jj);
        continue;
      }
      // written field by field: a whole struct built on the stack and copied stalls the
      // store-to-load forwarding of its parts
      Candidate &c = candidates.emplace_back();
      c.i = i;
      c.j = j;
      c.model = model;
      c.scales = scales_of(i, j, fm);
      c.radsum = radius[i] + radius[j];
      c.factor_lj = factor_lj;
      c.touch = &touch[jj];
      c.history = &allhistory[size_hist * jj];
    }
  }
  // every candidate of one model and one type pair whose atoms have one radius each (a
  // monodisperse packing of one type): the shared inputs are written into every lane once
  one_pair = !candidates.empty() && pair_scales[candidates[0].scales].valid;
  for (std::size_t k = 0; k < candidates.size() && one_pair; k++)
    one_pair = candidates[k].model == candidates[0].model &&
        candidates[k].scales == candidates[0].scales;
  lane_scales.assign(lane_scales.size(), -1);    // the entries of pair_scales are new
  list_radius.assign(radius, radius + nall);
  list_type.assign(type, type + nall);
  list_stale = false;
  list_rebuilds++;
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
   cache): each candidate's contact life decided (touch flag set, or reset with its history
   when the contact ended), the touching adhesive ones packed into lanes blocks, their JKR roots
   solved together and evaluated by the lanes kernel (marshall_lanes.h) on the default SIMD
   path, the others (no adhesion: Hertz's law) by the scalar instantiation of the same kernel;
   then each contact's results unpacked and summed in list order, so the sums over contacts are
   those of a scalar loop. Returns the number of touching contacts.
------------------------------------------------------------------------- */

bigint PairGranularOpt::compute_fused_contacts()
{
  constexpr int W = ML::WIDTH;
  constexpr std::size_t CHUNK = 8 * W;
  constexpr std::size_t PREFETCH = 4;
  // candidates ahead whose atoms are fetched: farther than the unpack's contacts, since a
  // candidate's pass is shorter (a settled bed: prefetching 8 ahead measured faster than 4)
  constexpr std::size_t PREFETCH_CANDIDATE = 2 * PREFETCH;
  const std::size_t ncand = candidates.size();
  lane_in.resize(CHUNK * ML::N_INPUT);
  lane_out.resize(CHUNK * ML::N_OUTPUT);
  chunk.resize(CHUNK);
  jkr_overlap.resize(CHUNK);
  jkr_root.resize(CHUNK);
  // lane l's first input and output: block l / W, offset l % W, WIDTH apart
  auto lane_input = [&](int l) { return ML::lane_input(lane_in.data(), l); };
  auto lane_output = [&](int l) { return ML::lane_output(lane_out.data(), l); };

  const AtomRows x(atom->x), v(atom->v), omega(atom->omega), f(atom->f), torque(atom->torque);
  const double *radius = atom->radius, *rmass = atom->rmass;
  const int *mask = atom->mask;
  const int nlocal = atom->nlocal;
  const int newton_pair = force->newton_pair;
  const int size_hist = get_size_history();
  // a contact's inputs (marshall_lanes.h) in two parts: those of its atoms and history (s: its
  // JKR root, unused without adhesion) and those of its model and type pair, the same for every
  // contact of one type pair of one radius each
  auto pack_state = [&](const Candidate &c, const double *dx, double s, double *in, int stride) {
    const int i = c.i, j = c.j;
    const FusedMarshall &fm = fused[c.model];
    const double *history = c.history;
    double fixed = ML::FIXED_NONE;
    if (mask[i] & freeze_group_bit) fixed = ML::FIXED_I;
    if (mask[j] & freeze_group_bit) fixed = ML::FIXED_J;
    ML::pack_contact_state(in, stride, dx, v[i], v[j], omega[i], omega[j],
                           history + hist_tangential, fm.rolling ? history + hist_rolling : nullptr,
                           fm.twisting ? history + hist_twisting : nullptr, s, rmass[i], rmass[j],
                           fixed);
  };
  auto pack_model = [&](const Candidate &c, double *in, int stride) {
    const PairScales &ps = pair_scales[c.scales];
    ML::pack_contact_model(in, stride, fused[c.model], model_dt[c.model], radius[c.i],
                           radius[c.j], ps.reff, ps.scales, ML::LEVER_SHIFT_PAIR);
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
  auto unpack_contact = [&](const Candidate &c, const double *dx, const double *out, int stride) {
    const int i = c.i, j = c.j;
    const FusedMarshall &fm = fused[c.model];
    double *history = c.history;
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
      ev_tally_xyz(i, j, nlocal, newton_pair, 0.0, 0.0, forces[0], forces[1], forces[2], dx[0],
                   dx[1], dx[2]);
  };

  lane_scales.resize(CHUNK, -1);
  model_dt.resize(nmodels);
  for (int m = 0; m < nmodels; m++) {
    if (model_dt[m] != models_list[m]->dt) lane_scales.assign(CHUNK, -1);
    model_dt[m] = models_list[m]->dt;
  }
  if (one_pair)
    for (int l = 0; l < static_cast<int>(CHUNK); l++) pack_model(candidates[0], lane_input(l), W);
  bigint touching = 0;
  std::size_t next = 0;    // the next candidate to decide
  while (next < ncand) {
    // up to CHUNK touching contacts: life decided, adhesive ones packed (root still to come)
    std::size_t m = 0;
    int nlanes = 0;
    for (; next < ncand && m < CHUNK; next++) {
      // the data of a candidate a few ahead: its loads overlap with this one's work
      if (next + PREFETCH_CANDIDATE < ncand) {
        const int jn = candidates[next + PREFETCH_CANDIDATE].j;
        __builtin_prefetch(x[jn]);
        __builtin_prefetch(v[jn]);
        __builtin_prefetch(omega[jn]);
        __builtin_prefetch(rmass + jn);
        __builtin_prefetch(mask + jn);
      }
      const Candidate &c = candidates[next];
      double dx[3];
      sub3(x[c.i], x[c.j], dx);
      const double rsq = lensq3(dx);
      const double radsum = c.radsum;
      // most neighbors of a deposition do not touch: reject those before the scales
      // (their history is zero already: zeroed when the contact ended, or new from the list)
      const bool was_touching = *c.touch != 0;
      if (!was_touching && rsq >= radsum * radsum) continue;
      const MK::JKRScales &sc = pair_scales[c.scales].scales;
      if (!MK::jkr_touch(was_touching, rsq, radsum, sc.deltac)) {
        *c.touch = 0;
        for (int k = 0; k < size_hist; k++) c.history[k] = 0.0;
        continue;
      }
      *c.touch = 1;
      ChunkContact &cc = chunk[m++];
      cc.candidate = static_cast<int>(next);
      copy3(dx, cc.dx);
      if (fused[c.model].gamma == 0.0) {
        cc.lane = -1;
        continue;
      }
      cc.lane = nlanes;
      jkr_overlap[nlanes] = MK::scaled_overlap(sc, radsum - sqrt(rsq));
      pack_state(c, dx, 0.0, lane_input(nlanes), W);
      if (!one_pair && lane_scales[nlanes] != c.scales) {
        pack_model(c, lane_input(nlanes), W);
        lane_scales[nlanes] = c.scales;
      }
      nlanes++;
    }
    touching += static_cast<bigint>(m);
    JKRScaled::roots(nlanes, jkr_overlap.data(), jkr_root.data());
    for (int l = 0; l < nlanes; l++) lane_input(l)[ML::ROOT * W] = jkr_root[l];
    // a short last block: its other lanes evaluate copies of its first contact, not scattered
    const std::size_t nblocks = ML::pad_last_block(lane_in.data(), nlanes);
    for (std::size_t l = nlanes; l < nblocks * W; l++) lane_scales[l] = lane_scales[l - l % W];
    ML::contacts_in_lanes(nblocks, lane_in.data(), lane_out.data(), history_update);

    for (std::size_t k = 0; k < m; k++) {
      const ChunkContact &cc = chunk[k];
      const Candidate &c = candidates[cc.candidate];
      if (k + PREFETCH < m) {
        const int jn = candidates[chunk[k + PREFETCH].candidate].j;
        __builtin_prefetch(f[jn], 1);
        __builtin_prefetch(torque[jn], 1);
      }
      if (cc.lane >= 0) {
        unpack_contact(c, cc.dx, lane_output(cc.lane), W);
      } else {
        double in[ML::N_INPUT], out[ML::N_OUTPUT];
        pack_state(c, cc.dx, 1.0, in, 1);
        pack_model(c, in, 1);
        ML::marshall_contact(in, out, history_update);
        unpack_contact(c, cc.dx, out, 1);
      }
    }
  }
  store_sums();
  return touching;
}
