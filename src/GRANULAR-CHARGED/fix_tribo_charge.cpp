/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "fix_tribo_charge.h"

#include "gran_sub_mod_normal_jkr_marshall.h"
#include "marshall_kernels.h"
#include "tribo_charge_kernels.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "fix_wall_gran.h"
#include "force.h"
#include "granular_model.h"
#include "group.h"
#include "math_const.h"
#include "memory.h"
#include "modify.h"
#include "neigh_list.h"
#include "neigh_request.h"
#include "neighbor.h"
#include "pair_granular.h"
#include "update.h"

#include <cmath>
#include <cstring>
#include <limits>

using namespace LAMMPS_NS;
using namespace FixConst;
namespace MK = MarshallKernels;
namespace TK = TriboChargeKernels;

namespace {
// charge moves in whole multiples of qelectron / 2^16 (1.5e-5 e): counts of quanta add exactly
constexpr double QUANTA_PER_E = 65536.0;
// counts stay exact in a double below 2^53
constexpr double LARGEST_COUNT = 9007199254740992.0;
// fix wall/gran's "no plane" (its BIG) is 1e20; anything beyond this is no plane
constexpr double NO_PLANE = 1.0e19;
enum VectorElement { V_MOVED, V_WALL, V_EVENTS_PAIR, V_EVENTS_WALL, V_RESIDUAL, V_NELEMENTS };
enum RestartSlot { R_MOVED, R_WALL, R_EVENTS_PAIR, R_EVENTS_WALL, R_NSLOTS };
constexpr int GHOST_COLS = 9;    // position as owned (3), periodic shift (3), field (3)

// LAMMPS's fix wall/gran keeps its plane protected and has no accessor. A class derived from it
// may form pointers to those members, and a pointer to member reads them from any FixWallGran.
struct WallGranPlanes : public FixWallGran {
  static int style(const FixWallGran *f) { return f->*(&WallGranPlanes::wallstyle); }
  static double lo_of(const FixWallGran *f) { return f->*(&WallGranPlanes::lo); }
  static double hi_of(const FixWallGran *f) { return f->*(&WallGranPlanes::hi); }
};
}    // namespace

/* ---------------------------------------------------------------------- */

FixTriboCharge::FixTriboCharge(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), z0(0.0), field_on(true), maxcontacts(16), rowsize(0), transfers_flag(1),
    list(nullptr), coul(nullptr), quantum(0.0), coulomb(0.0), eps(0.0), row(nullptr),
    ghost(nullptr), nmax_ghost(0), comm_stage(0), moved_pair(0.0), given_wall(0.0),
    events_pair(0.0), events_wall(0.0), cached_key{-1.0, -1.0, -1.0}
{
  if (!atom->q_flag || !atom->radius_flag)
    error->all(FLERR, "Fix {} requires atom attributes q and radius (e.g. atom_style hybrid sphere charge)", style);
  if (!atom->tag_enable) error->all(FLERR, "Fix {} requires atom IDs", style);
  if (domain->triclinic) error->all(FLERR, "Fix {} requires an orthogonal box", style);

  const int ntypes = atom->ntypes;
  int iarg = 3;
  if (iarg + 2 > narg || strcmp(arg[iarg], "z0") != 0)
    error->all(FLERR, "Fix {}: expected z0 <gap> first, got {}", style, iarg < narg ? arg[iarg] : "nothing");
  z0 = utils::numeric(FLERR, arg[iarg + 1], false, lmp);
  if (!(z0 > 0.0) || !std::isfinite(z0))
    error->all(FLERR, "Fix {} z0 must be a gap > 0 (distance units), got {}", style, arg[iarg + 1]);
  iarg += 2;
  if (iarg >= narg || strcmp(arg[iarg], "potential") != 0)
    error->all(FLERR, "Fix {}: expected potential V_1 .. V_{} after z0, got {}", style, ntypes,
               iarg < narg ? arg[iarg] : "nothing");
  if (iarg + 1 + ntypes > narg)
    error->all(FLERR, "Fix {} potential needs one contact potential per atom type ({} values)", style, ntypes);
  potential_volts.assign(ntypes + 1, 0.0);
  for (int t = 1; t <= ntypes; t++) {
    if (!utils::is_double(arg[iarg + t]))
      error->all(FLERR, "Fix {} potential needs one contact potential per atom type ({} values, "
                 "volts): {} is not a number", style, ntypes, arg[iarg + t]);
    potential_volts[t] = utils::numeric(FLERR, arg[iarg + t], false, lmp);
    if (!std::isfinite(potential_volts[t]))
      error->all(FLERR, "Fix {} potential of type {} must be finite, got {}", style, t, arg[iarg + t]);
  }
  iarg += 1 + ntypes;

  while (iarg < narg) {
    if (strcmp(arg[iarg], "wall") == 0) {
      if (iarg + 3 > narg) utils::missing_cmd_args(FLERR, "fix tribo/charge wall", error);
      const double v = utils::numeric(FLERR, arg[iarg + 2], false, lmp);
      if (!std::isfinite(v))
        error->all(FLERR, "Fix {} wall {} potential must be finite, got {}", style, arg[iarg + 1], arg[iarg + 2]);
      wall_args.emplace_back(arg[iarg + 1], v);
      iarg += 3;
    } else if (strcmp(arg[iarg], "field") == 0) {
      if (iarg + 2 > narg) utils::missing_cmd_args(FLERR, "fix tribo/charge field", error);
      field_on = utils::logical(FLERR, arg[iarg + 1], false, lmp) == 1;
      iarg += 2;
    } else if (strcmp(arg[iarg], "maxcontacts") == 0) {
      if (iarg + 2 > narg) utils::missing_cmd_args(FLERR, "fix tribo/charge maxcontacts", error);
      maxcontacts = utils::inumeric(FLERR, arg[iarg + 1], false, lmp);
      if (maxcontacts < 1 || maxcontacts > 1000)
        error->all(FLERR, "Fix {} maxcontacts must be 1-1000, got {}", style, arg[iarg + 1]);
      iarg += 2;
    } else {
      error->all(FLERR, "Unknown fix {} keyword {}", style, arg[iarg]);
    }
  }

  rowsize = RECORDS + REC_SIZE * maxcontacts;
  vector_flag = 1;
  size_vector = V_NELEMENTS;
  global_freq = 1;
  extvector = 0;
  peratom_flag = 1;
  size_peratom_cols = 0;
  peratom_freq = 1;
  restart_global = 1;
  restart_peratom = 1;
  create_attribute = 1;
  comm_forward = GHOST_COLS;
  maxexchange = rowsize;

  FixTriboCharge::grow_arrays(atom->nmax);
  atom->add_callback(Atom::GROW);
  atom->add_callback(Atom::RESTART);
  for (int i = 0; i < atom->nlocal; i++) set_arrays(i);
}

FixTriboCharge::~FixTriboCharge()
{
  atom->delete_callback(id, Atom::GROW);
  atom->delete_callback(id, Atom::RESTART);
  memory->destroy(row);
  memory->destroy(ghost);
  memory->destroy(vector_atom);
}

int FixTriboCharge::setmask()
{
  return POST_FORCE;
}

/* ---------------------------------------------------------------------- */

void FixTriboCharge::init()
{
  if (utils::strmatch(update->unit_style, "^lj$"))
    error->all(FLERR, "Fix {} needs units with a volt (not lj): the contact potentials are in volts", style);
  if (domain->triclinic) error->all(FLERR, "Fix {} requires an orthogonal box", style);

  quantum = force->qelectron / QUANTA_PER_E;
  coulomb = force->qqrd2e;
  eps = 1.0 / (4.0 * MathConst::MY_PI * coulomb);
  potential.assign(potential_volts.size(), 0.0);
  for (std::size_t t = 0; t < potential.size(); t++) potential[t] = potential_volts[t] * force->qe2f;

  check_pair_model();
  find_walls();

  coul = nullptr;
  if (field_on) {
    auto fixes = modify->get_fix_by_style("^coul/fmm$");
    if (fixes.size() != 1)
      error->all(FLERR, "Fix {} field yes needs exactly one fix coul/fmm (found {}); use field no "
                 "for the field-free law", style, fixes.size());
    coul = fixes[0];
    if (modify->find_fix(coul->id) > modify->find_fix(id))
      error->all(FLERR, "Fix {} must be defined after fix coul/fmm {} (it reads the field that fix "
                 "applies in the same step)", style, coul->id);
    int outside = 0;
    for (int i = 0; i < atom->nlocal; i++)
      if ((atom->mask[i] & groupbit) && !(atom->mask[i] & coul->groupbit)) outside = 1;
    int any = 0;
    MPI_Allreduce(&outside, &any, 1, MPI_INT, MPI_MAX, world);
    if (any)
      error->all(FLERR, "Fix {}: atoms of group {} are outside the group of fix coul/fmm {}: their "
                 "field is unknown", style, group->names[igroup], coul->id);
  }

  neighbor->add_request(this, NeighConst::REQ_SIZE | NeighConst::REQ_NEWTON_OFF);
}

void FixTriboCharge::init_list(int, NeighList *ptr)
{
  list = ptr;
}

// every pair of types needs the jkr/marshall normal model (its contact radius)
void FixTriboCharge::check_pair_model()
{
  auto *pair = dynamic_cast<PairGranular *>(force->pair_match("^granular", 0));
  if (!pair)
    error->all(FLERR, "Fix {} requires pair_style granular or granular/opt (the contact area is "
               "that of its jkr/marshall normal model)", style);
  const int ntypes = atom->ntypes;
  emix.assign((ntypes + 1) * (ntypes + 1), 0.0);
  gamma.assign((ntypes + 1) * (ntypes + 1), 0.0);
  for (int it = 1; it <= ntypes; it++)
    for (int jt = 1; jt <= ntypes; jt++) {
      auto *model = pair->models_list[pair->types_indices[it][jt]];
      auto *normal = dynamic_cast<Granular_NS::GranSubModNormalJKRMarshall *>(model->normal_model);
      if (!normal)
        error->all(FLERR, "Fix {} requires the jkr/marshall normal model; types {} {} use {}",
                   style, it, jt, model->normal_model->name);
      emix[it * (ntypes + 1) + jt] = normal->get_emix();
      gamma[it * (ntypes + 1) + jt] = normal->get_surface_energy();
    }
}

void FixTriboCharge::find_walls()
{
  walls.clear();
  for (const auto &[wid, volts] : wall_args) {
    auto *f = modify->get_fix_by_id(wid);
    if (!f) error->all(FLERR, "Fix {} wall: no fix with ID {}", style, wid);
    auto *wf = dynamic_cast<FixWallGran *>(f);
    if (!wf || !utils::strmatch(f->style, "^wall/gran"))
      error->all(FLERR, "Fix {} wall {}: fix style {} is not wall/gran or wall/gran/opt", style,
                 wid, f->style);
    const int ws = WallGranPlanes::style(wf);
    if (ws < 0 || ws > 2)
      error->all(FLERR, "Fix {} wall {}: only the planes xplane, yplane, zplane charge (not a region)",
                 style, wid);
    auto *normal = dynamic_cast<Granular_NS::GranSubModNormalJKRMarshall *>(wf->model->normal_model);
    if (!normal)
      error->all(FLERR, "Fix {} wall {} requires the jkr/marshall normal model, got {}", style, wid,
                 wf->model->normal_model->name);
    Wall w;
    w.fix = wf;
    w.potential = volts * force->qe2f;
    w.emix = normal->get_emix();
    w.gamma = normal->get_surface_energy();
    w.axis = ws;
    w.lo = w.hi = 0.0;
    walls.push_back(w);
  }
}

void FixTriboCharge::setup(int)
{
  rebase_charges();
  for (int i = 0; i < atom->nlocal; i++) vector_atom[i] = row[i][GAINED] * quantum;
  // the ghosts' charges as the owners hold them
  comm_stage = 1;
  comm->forward_comm(this);
}

/* ----------------------------------------------------------------------
   a charge set by someone else since this fix last gave one (set, fix adapt, a new atom)
   becomes the atom's base: the quanta it gained are kept on top of it
------------------------------------------------------------------------- */

void FixTriboCharge::rebase_charges()
{
  double *q = atom->q;
  for (int i = 0; i < atom->nlocal; i++) {
    double *r = row[i];
    if (q[i] == r[QSET]) continue;
    r[QBASE] = q[i] - r[GAINED] * quantum;
    r[QSET] = q[i];
  }
}

/* ---------------------------------------------------------------------- */

double *FixTriboCharge::find_record(int i, double key)
{
  double *r = row[i];
  const int n = (int) r[NREC];
  for (int k = 0; k < n; k++)
    if (r[RECORDS + REC_SIZE * k] == key) return &r[RECORDS + REC_SIZE * k];
  return nullptr;
}

double *FixTriboCharge::add_record(int i, double key)
{
  double *r = row[i];
  const int n = (int) r[NREC];
  if (n >= maxcontacts)
    error->one(FLERR, "Fix {}: atom {} has more than maxcontacts = {} contacts; raise maxcontacts",
               style, atom->tag[i], maxcontacts);
  double *rec = &r[RECORDS + REC_SIZE * n];
  rec[0] = key;
  rec[1] = 0.0;
  rec[2] = -1.0;
  rec[3] = -std::numeric_limits<double>::max();
  r[NREC] = n + 1;
  return rec;
}

// the records of atom i not seen touching in this step: the contact ended
void FixTriboCharge::sweep_records(int i, bigint step)
{
  double *r = row[i];
  const int n = (int) r[NREC];
  int kept = 0;
  for (int k = 0; k < n; k++) {
    const double *rec = &r[RECORDS + REC_SIZE * k];
    if (rec[2] != (double) step) continue;
    if (kept != k)
      for (int c = 0; c < REC_SIZE; c++) r[RECORDS + REC_SIZE * kept + c] = rec[c];
    kept++;
  }
  r[NREC] = kept;
}

// the JKR scales of (R_eff, gamma, E*): most contacts of a powder share them, so the last one is
// kept (two cube roots otherwise per contact and step)
const MarshallKernels::JKRScales &FixTriboCharge::scales_of(double reff, double gamma_, double emix_)
{
  if (reff != cached_key[0] || gamma_ != cached_key[1] || emix_ != cached_key[2]) {
    cached_key[0] = reff;
    cached_key[1] = gamma_;
    cached_key[2] = emix_;
    cached_scales = MK::jkr_scales(reff, gamma_, emix_);
  }
  return cached_scales;
}

const double *FixTriboCharge::field_of(int i) const
{
  return &ghost[i][6];
}

/* ----------------------------------------------------------------------
   each atom's position as its owner holds it, the periodic shift that makes its ghost and its
   field: the two ranks of a pair then compute the same separation
------------------------------------------------------------------------- */

void FixTriboCharge::exchange_inputs()
{
  if (atom->nmax > nmax_ghost) {
    nmax_ghost = atom->nmax;
    memory->destroy(ghost);
    memory->create(ghost, nmax_ghost, GHOST_COLS, "tribo/charge:ghost");
  }
  double **x = atom->x;
  double **field = coul ? coul->array_atom : nullptr;
  for (int i = 0; i < atom->nlocal; i++) {
    for (int k = 0; k < 3; k++) {
      ghost[i][k] = x[i][k];
      ghost[i][3 + k] = 0.0;
      ghost[i][6 + k] = field ? field[i][k] : 0.0;
    }
  }
  comm_stage = 0;
  comm->forward_comm(this);
}

/* ---------------------------------------------------------------------- */

void FixTriboCharge::post_force(int)
{
  const bigint step = update->ntimestep;
  rebase_charges();
  exchange_inputs();
  changed.clear();

  const int nlocal = atom->nlocal;
  int *mask = atom->mask;
  for (int ii = 0; ii < list->inum; ii++) {
    const int i = list->ilist[ii];
    if (!(mask[i] & groupbit)) continue;
    const int *jlist = list->firstneigh[i];
    for (int jj = 0; jj < list->numneigh[i]; jj++) {
      const int j = jlist[jj] & NEIGHMASK;
      if (mask[j] & groupbit) charge_pair(i, j, step, changed);
    }
  }
  if (!walls.empty()) charge_walls(step, changed);

  for (int i = 0; i < nlocal; i++)
    if (mask[i] & groupbit) sweep_records(i, step);

  double *q = atom->q;
  for (int i : changed) {
    double *r = row[i];
    if (std::fabs(r[GAINED]) >= LARGEST_COUNT)
      error->one(FLERR, "Fix {}: atom {} gained more charge than the fix counts exactly", style, atom->tag[i]);
    q[i] = r[QBASE] + r[GAINED] * quantum;
    r[QSET] = q[i];
    vector_atom[i] = r[GAINED] * quantum;
  }
  comm_stage = 1;
  comm->forward_comm(this);
}

/* ----------------------------------------------------------------------
   one pair of the list (i local, j local or ghost), in the order of their tags (a < b): the
   same operations on every rank that computes it
------------------------------------------------------------------------- */

void FixTriboCharge::charge_pair(int i, int j, bigint step, std::vector<int> &changed)
{
  const tagint *tag = atom->tag;
  const int nlocal = atom->nlocal;
  const int a = tag[i] < tag[j] ? i : j;
  const int b = a == i ? j : i;
  const double *prd = domain->prd;
  double d[3];
  for (int k = 0; k < 3; k++)
    d[k] = (ghost[b][k] - ghost[a][k]) + (ghost[b][3 + k] - ghost[a][3 + k]) * prd[k];
  const double rsq = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  const double ra = atom->radius[a], rb = atom->radius[b];
  const double radsum = ra + rb;

  double *rec_i = find_record(i, (double) tag[j]);
  double *rec_j = j < nlocal ? find_record(j, (double) tag[i]) : nullptr;
  const bool was = rec_i != nullptr;

  const int ntypes = atom->ntypes;
  const int ta = atom->type[a], tb = atom->type[b];
  const double em = emix[ta * (ntypes + 1) + tb], ga = gamma[ta * (ntypes + 1) + tb];
  const double reff = MK::effective_radius(ra, rb);
  const bool maybe = rsq < radsum * radsum;
  if (!maybe && !was) return;
  const MK::JKRScales &sc = scales_of(reff, ga, em);
  if (!MK::jkr_touch(was, rsq, radsum, sc.deltac)) return;    // unseen: swept as ended

  if (!rec_i) rec_i = add_record(i, (double) tag[j]);
  if (j < nlocal && !rec_j) rec_j = add_record(j, (double) tag[i]);
  rec_i[2] = (double) step;
  if (rec_j) rec_j[2] = (double) step;

  const double r = std::sqrt(rsq);
  // the area grows with the overlap (the stable JKR branch): no growth while the overlap stays
  // within the one charged over, and no contact radius to solve for
  const double delta = radsum - r;
  if (!(delta > rec_i[3])) return;
  const double a_contact = MK::jkr_normal_force(sc, ga, em, delta, reff).a;
  const double area = MathConst::MY_PI * a_contact * a_contact;
  rec_i[3] = delta;
  if (rec_j) rec_j[3] = delta;
  if (!(area > rec_i[1])) return;
  const double darea = area - rec_i[1];
  rec_i[1] = area;
  if (rec_j) rec_j[1] = area;

  double en = 0.0;
  if (field_on) {
    const double da = TK::contact_plane_distance(r, ra, rb);
    double ena = 0.0, enb = 0.0;
    const double *ea = field_of(a), *eb = field_of(b);
    for (int k = 0; k < 3; k++) {
      ena += ea[k] * d[k] / r;
      enb += eb[k] * d[k] / r;
    }
    const double *q = atom->q;
    en = TK::pair_normal_field(coulomb, q[a], q[b], r, da, ena, enb, q[a] != 0.0, q[b] != 0.0);
  }
  const double drive = TK::contact_drive(potential[ta] - potential[tb], en, z0, field_on);
  const double quanta = std::nearbyint(TK::condenser_charge(eps, z0, darea, drive) / quantum);
  if (quanta == 0.0) return;
  if (a < nlocal) {
    row[a][GAINED] += quanta;
    changed.push_back(a);
    // the rank of the lower tag counts the pair
    moved_pair += std::fabs(quanta);
    events_pair += 1.0;
  }
  if (b < nlocal) {
    row[b][GAINED] -= quanta;
    changed.push_back(b);
  }
}

/* ----------------------------------------------------------------------
   contacts of the local atoms with the planes of the wall fixes; a plane is a body of
   unlimited charge (grounded): the quanta a particle gains come from it
------------------------------------------------------------------------- */

void FixTriboCharge::charge_walls(bigint step, std::vector<int> &changed)
{
  double **x = atom->x;
  const double *radius = atom->radius, *q = atom->q;
  const int *mask = atom->mask, *type = atom->type;
  for (std::size_t w = 0; w < walls.size(); w++) {
    Wall &wall = walls[w];
    const double lo = WallGranPlanes::lo_of(wall.fix), hi = WallGranPlanes::hi_of(wall.fix);
    const int axis = wall.axis;
    const int wallbit = wall.fix->groupbit;
    for (int i = 0; i < atom->nlocal; i++) {
      if (!(mask[i] & groupbit) || !(mask[i] & wallbit)) continue;
      for (int side = 0; side < 2; side++) {
        const double plane = side == 0 ? lo : hi;
        if (std::fabs(plane) > NO_PLANE) continue;
        const double dist = side == 0 ? x[i][axis] - plane : plane - x[i][axis];
        const double key = -1.0 - (double) (2 * w + side);
        double *rec = find_record(i, key);
        const double rad = radius[i];
        const bool was = rec != nullptr;
        if (!was && dist >= rad) continue;
        const MK::JKRScales &sc = scales_of(rad, wall.gamma, wall.emix);
        if (!MK::jkr_touch(was, dist * dist, rad, sc.deltac)) continue;
        if (!rec) rec = add_record(i, key);
        rec[2] = (double) step;
        const double delta = rad - dist;
        if (!(delta > rec[3])) continue;
        rec[3] = delta;
        const double a_contact = MK::jkr_normal_force(sc, wall.gamma, wall.emix, delta, rad).a;
        const double area = MathConst::MY_PI * a_contact * a_contact;
        if (!(area > rec[1])) continue;
        const double darea = area - rec[1];
        rec[1] = area;
        double en = 0.0;
        if (field_on) {
          // n from the centre to the plane: -axis for lo, +axis for hi
          const double en_solver = q[i] != 0.0 ? (side == 0 ? -1.0 : 1.0) * field_of(i)[axis] : 0.0;
          en = TK::wall_normal_field(coulomb, q[i], dist, en_solver);
        }
        const double drive = TK::contact_drive(potential[type[i]] - wall.potential, en, z0, field_on);
        const double quanta = std::nearbyint(TK::condenser_charge(eps, z0, darea, drive) / quantum);
        if (quanta == 0.0) continue;
        row[i][GAINED] += quanta;
        changed.push_back(i);
        given_wall += quanta;
        events_wall += 1.0;
      }
    }
  }
}

/* ---------------------------------------------------------------------- */

double FixTriboCharge::compute_vector(int n)
{
  if (n == V_RESIDUAL) {
    double mine = 0.0;
    for (int i = 0; i < atom->nlocal; i++)
      if (atom->mask[i] & groupbit) mine += row[i][GAINED];
    double sums[2] = {mine, given_wall}, all[2];
    MPI_Allreduce(sums, all, 2, MPI_DOUBLE, MPI_SUM, world);
    return all[0] - all[1];
  }
  const double mine[4] = {moved_pair, given_wall, events_pair, events_wall};
  double all = 0.0;
  MPI_Allreduce(&mine[n], &all, 1, MPI_DOUBLE, MPI_SUM, world);
  return (n == V_MOVED || n == V_WALL) ? all * quantum : all;
}

void *FixTriboCharge::extract(const char *name, int &dim)
{
  dim = 0;
  if (strcmp(name, "charge_transfers") == 0) return &transfers_flag;
  return nullptr;
}

double FixTriboCharge::memory_usage()
{
  return ((double) atom->nmax * (rowsize + 1) + (double) nmax_ghost * GHOST_COLS) * sizeof(double);
}

/* ----------------------------------------------------------------------
   per-atom rows
------------------------------------------------------------------------- */

void FixTriboCharge::grow_arrays(int nmax)
{
  memory->grow(row, nmax, rowsize, "tribo/charge:row");
  memory->grow(vector_atom, nmax, "tribo/charge:vector_atom");
}

void FixTriboCharge::copy_arrays(int i, int j, int)
{
  for (int k = 0; k < rowsize; k++) row[j][k] = row[i][k];
  vector_atom[j] = vector_atom[i];
}

// a new atom: nothing gained, no contacts; its charge becomes its base when first seen
void FixTriboCharge::set_arrays(int i)
{
  for (int k = 0; k < rowsize; k++) row[i][k] = 0.0;
  row[i][QSET] = std::numeric_limits<double>::quiet_NaN();
  vector_atom[i] = 0.0;
}

int FixTriboCharge::pack_exchange(int i, double *buf)
{
  for (int k = 0; k < rowsize; k++) buf[k] = row[i][k];
  return rowsize;
}

int FixTriboCharge::unpack_exchange(int nlocal, double *buf)
{
  for (int k = 0; k < rowsize; k++) row[nlocal][k] = buf[k];
  vector_atom[nlocal] = row[nlocal][GAINED] * quantum;
  return rowsize;
}

int FixTriboCharge::pack_forward_comm(int n, int *list_send, double *buf, int pbc_flag, int *pbc)
{
  int m = 0;
  if (comm_stage == 1) {
    for (int i = 0; i < n; i++) buf[m++] = atom->q[list_send[i]];
    return m;
  }
  for (int i = 0; i < n; i++) {
    const double *g = ghost[list_send[i]];
    for (int k = 0; k < 3; k++) buf[m++] = g[k];
    for (int k = 0; k < 3; k++) buf[m++] = g[3 + k] + (pbc_flag ? (double) pbc[k] : 0.0);
    for (int k = 0; k < 3; k++) buf[m++] = g[6 + k];
  }
  return m;
}

void FixTriboCharge::unpack_forward_comm(int n, int first, double *buf)
{
  int m = 0;
  if (comm_stage == 1) {
    for (int i = first; i < first + n; i++) atom->q[i] = buf[m++];
    return;
  }
  for (int i = first; i < first + n; i++)
    for (int k = 0; k < GHOST_COLS; k++) ghost[i][k] = buf[m++];
}

/* ----------------------------------------------------------------------
   restart: the totals (global) and each atom's row
------------------------------------------------------------------------- */

void FixTriboCharge::write_restart(FILE *fp)
{
  double mine[R_NSLOTS] = {moved_pair, given_wall, events_pair, events_wall}, all[R_NSLOTS];
  MPI_Allreduce(mine, all, R_NSLOTS, MPI_DOUBLE, MPI_SUM, world);
  if (comm->me == 0) {
    int size = R_NSLOTS * sizeof(double);
    fwrite(&size, sizeof(int), 1, fp);
    fwrite(all, sizeof(double), R_NSLOTS, fp);
  }
}

void FixTriboCharge::restart(char *buf)
{
  const auto *list_in = (const double *) buf;
  // the totals live on rank 0, so that their sums over the ranks stay right
  const bool here = comm->me == 0;
  moved_pair = here ? list_in[R_MOVED] : 0.0;
  given_wall = here ? list_in[R_WALL] : 0.0;
  events_pair = here ? list_in[R_EVENTS_PAIR] : 0.0;
  events_wall = here ? list_in[R_EVENTS_WALL] : 0.0;
}

int FixTriboCharge::pack_restart(int i, double *buf)
{
  buf[0] = rowsize + 1;
  for (int k = 0; k < rowsize; k++) buf[k + 1] = row[i][k];
  return rowsize + 1;
}

void FixTriboCharge::unpack_restart(int nlocal, int nth)
{
  double **extra = atom->extra;
  int m = 0;
  for (int i = 0; i < nth; i++) m += static_cast<int>(extra[nlocal][m]);
  const int count = static_cast<int>(extra[nlocal][m]) - 1;
  if (count != rowsize)
    error->one(FLERR, "Fix {}: the restart file holds {} values per atom, this fix (maxcontacts {}) "
               "needs {}: use the maxcontacts of the run that wrote it", style, count, maxcontacts, rowsize);
  for (int k = 0; k < rowsize; k++) row[nlocal][k] = extra[nlocal][m + 1 + k];
}

int FixTriboCharge::size_restart(int)
{
  return rowsize + 1;
}

int FixTriboCharge::maxsize_restart()
{
  return rowsize + 1;
}
