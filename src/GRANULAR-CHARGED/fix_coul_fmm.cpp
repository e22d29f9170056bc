/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "fix_coul_fmm.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "force.h"
#include "group.h"
#include "memory.h"
#include "modify.h"
#include "respa.h"
#include "update.h"

#include "gcfmm/options.hpp"
#include "gcfmm/solver.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <numeric>

using namespace LAMMPS_NS;
using namespace FixConst;

/* ---------------------------------------------------------------------- */

FixCoulFMM::FixCoulFMM(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), opts(new gcfmm::Options), every(1), last_computed(-1), natoms_computed(-1),
    bed_given(false), energy_local(0.0), energy_all(0.0), energy_summed(false), field(nullptr),
    logged(false)
{
  scalar_flag = 1;
  extscalar = 1;
  vector_flag = 1;    // solver diagnostics: estimated error, order, M2L and P2P counts
  size_vector = 4;
  extvector = 0;
  global_freq = 1;
  energy_global_flag = 1;
  virial_global_flag = virial_peratom_flag = 1;
  peratom_flag = 1;
  size_peratom_cols = 4;
  peratom_freq = 1;
  dynamic_group_allow = 1;
  respa_level_support = 1;
  ilevel_respa = 0;
  create_attribute = 1;    // atoms created by other fixes get a zero stored field (set_arrays)

  opts->accuracy = 1e-4;
  opts->images = 1;
  opts->farfield = gcfmm::FarField::Exact;

  int iarg = 3;
  while (iarg < narg) {
    const std::string key = arg[iarg];
    auto need = [&](int n) {
      if (iarg + n >= narg) utils::missing_cmd_args(FLERR, "fix coul/fmm " + key, error);
    };
    if (key == "accuracy") {
      need(1);
      opts->accuracy = utils::numeric(FLERR, arg[iarg + 1], false, lmp);
      if (!(opts->accuracy > 0.0 && opts->accuracy < 1.0))
        error->all(FLERR, iarg + 1, "Fix coul/fmm accuracy must be in (0, 1), got {}",
                   arg[iarg + 1]);
      iarg += 2;
    } else if (key == "order") {
      need(1);
      opts->order = utils::inumeric(FLERR, arg[iarg + 1], false, lmp);
      if (opts->order < 1 || opts->order > gcfmm::kMaxOrder)
        error->all(FLERR, iarg + 1, "Fix coul/fmm order must be in [1, {}], got {}",
                   gcfmm::kMaxOrder, arg[iarg + 1]);
      iarg += 2;
    } else if (key == "theta") {
      need(1);
      opts->theta = utils::numeric(FLERR, arg[iarg + 1], false, lmp);
      if (!(opts->theta > 0.0 && opts->theta < 1.0))
        error->all(FLERR, iarg + 1, "Fix coul/fmm theta must be in (0, 1), got {}", arg[iarg + 1]);
      iarg += 2;
    } else if (key == "leaf") {
      need(1);
      opts->leaf = utils::inumeric(FLERR, arg[iarg + 1], false, lmp);
      if (opts->leaf < 1)
        error->all(FLERR, iarg + 1, "Fix coul/fmm leaf must be >= 1, got {}", arg[iarg + 1]);
      iarg += 2;
    } else if (key == "images") {
      need(1);
      opts->images = utils::inumeric(FLERR, arg[iarg + 1], false, lmp);
      if (opts->images < 0)
        error->all(FLERR, iarg + 1, "Fix coul/fmm images must be >= 0, got {}", arg[iarg + 1]);
      iarg += 2;
    } else if (key == "farfield") {
      need(1);
      const std::string v = arg[iarg + 1];
      if (v == "exact")
        opts->farfield = gcfmm::FarField::Exact;
      else if (v == "average")
        opts->farfield = gcfmm::FarField::Average;
      else if (v == "none")
        opts->farfield = gcfmm::FarField::None;
      else
        error->all(FLERR, iarg + 1, "Fix coul/fmm farfield must be exact, average or none, got {}",
                   v);
      iarg += 2;
    } else if (key == "bed") {
      need(2);
      opts->bed_zlo = utils::numeric(FLERR, arg[iarg + 1], false, lmp);
      opts->bed_zhi = utils::numeric(FLERR, arg[iarg + 2], false, lmp);
      if (!(opts->bed_zhi > opts->bed_zlo))
        error->all(FLERR, iarg + 1, "Fix coul/fmm bed zlo must be < zhi, got {} {}", arg[iarg + 1],
                   arg[iarg + 2]);
      bed_given = true;
      iarg += 3;
    } else if (key == "every") {
      need(1);
      every = utils::inumeric(FLERR, arg[iarg + 1], false, lmp);
      if (every < 1) error->all(FLERR, iarg + 1, "Fix coul/fmm every must be >= 1, got {}", every);
      iarg += 2;
    } else {
      error->all(FLERR, iarg, "Unknown fix coul/fmm keyword: {}", key);
    }
  }
  if (opts->images == 0 && opts->farfield == gcfmm::FarField::Exact)
    error->all(FLERR,
               "Fix coul/fmm farfield exact needs images >= 1 (the far-field kernel of "
               "the exact lattice sum is singular inside the cell for images 0)");
  try {
    opts->validate();
  } catch (std::exception &e) {
    error->all(FLERR, "Fix coul/fmm: {}", e.what());
  }

  FixCoulFMM::grow_arrays(atom->nmax);
  atom->add_callback(Atom::GROW);
  for (int i = 0; i < atom->nlocal; i++)
    for (int k = 0; k < 4; k++) field[i][k] = 0.0;
}

/* ---------------------------------------------------------------------- */

FixCoulFMM::~FixCoulFMM()
{
  if (copymode) return;
  atom->delete_callback(id, Atom::GROW);
  memory->destroy(field);
}

/* ---------------------------------------------------------------------- */

int FixCoulFMM::setmask()
{
  return POST_FORCE | POST_FORCE_RESPA | MIN_POST_FORCE;
}

/* ----------------------------------------------------------------------
   context checks: charges, 3d, orthogonal box, free space or periodic in x and y only
------------------------------------------------------------------------- */

void FixCoulFMM::init()
{
  if (!atom->q_flag) error->all(FLERR, "Fix coul/fmm requires an atom style with charge (q)");
  // results are matched to atoms by ID; without IDs every atom would get atom 1's field
  if (!atom->tag_enable)
    error->all(FLERR, "Fix coul/fmm requires atom IDs (atom_modify id yes)");
  if (domain->dimension != 3) error->all(FLERR, "Fix coul/fmm requires a 3d simulation");
  if (domain->triclinic) error->all(FLERR, "Fix coul/fmm does not support triclinic boxes");
  const int px = domain->xperiodic, py = domain->yperiodic, pz = domain->zperiodic;
  if (!px && !py && !pz) {
    opts->boundary = gcfmm::Boundary::Free;
  } else if (px && py && !pz) {
    opts->boundary = gcfmm::Boundary::Periodic2D;
  } else {
    error->all(FLERR,
               "Fix coul/fmm requires boundary f f f (free space) or p p f (periodic in x and y, "
               "open in z), got periodicity {} {} {}",
               px ? "p" : "f", py ? "p" : "f", pz ? "p" : "f");
  }
  if (force->kspace && comm->me == 0)
    error->warning(FLERR,
                   "Fix coul/fmm is used together with a kspace style: Coulomb "
                   "interactions may be counted twice");
  if (bed_given && !(opts->boundary == gcfmm::Boundary::Periodic2D &&
                     opts->farfield == gcfmm::FarField::Average))
    error->all(FLERR,
               "Fix coul/fmm keyword bed applies only to farfield average with boundary p p f");
  if (thermo_virial && opts->boundary == gcfmm::Boundary::Periodic2D && comm->me == 0)
    error->warning(FLERR,
                   "Fix coul/fmm {} with boundary p p f contributes only the zz component of the "
                   "virial (the in-plane components of sum x_i F_i are not the lattice virial)",
                   id);
  check_other_coul_fmm_fixes();

  if (utils::strmatch(update->integrate_style, "^respa")) {
    ilevel_respa = (dynamic_cast<Respa *>(update->integrate))->nlevels - 1;
    if (respa_level >= 0) ilevel_respa = MIN(respa_level, ilevel_respa);
  }
  try {
    solver = std::make_unique<gcfmm::Solver>(*opts);
  } catch (std::exception &e) {
    error->all(FLERR, "Fix coul/fmm: FMM library: {}", e.what());
  }
  logged = false;
  last_computed = -1;
}

/* ---------------------------------------------------------------------- */

void FixCoulFMM::setup(int vflag)
{
  last_computed = -1;    // always a fresh field at the start of a run (restart-safe)
  if (utils::strmatch(update->integrate_style, "^verlet")) {
    post_force(vflag);
  } else {
    auto *respa = dynamic_cast<Respa *>(update->integrate);
    respa->copy_flevel_f(ilevel_respa);
    post_force_respa(vflag, ilevel_respa, 0);
    respa->copy_f_flevel(ilevel_respa);
  }
}

void FixCoulFMM::post_force_respa(int vflag, int ilevel, int /*iloop*/)
{
  if (ilevel == ilevel_respa) post_force(vflag);
}

void FixCoulFMM::min_setup(int vflag)
{
  if (every > 1 && comm->me == 0)
    error->warning(FLERR,
                   "Fix coul/fmm {}: every {} is ignored during minimization (a minimizer needs "
                   "forces and energy of the current positions)",
                   id, every);
  min_post_force(vflag);
}

/* ----------------------------------------------------------------------
   a line search evaluates several trial positions within one step: always recompute
------------------------------------------------------------------------- */

void FixCoulFMM::min_post_force(int vflag)
{
  v_init(vflag);
  compute_field();
  last_computed = update->ntimestep;
  natoms_computed = atom->natoms;
  apply_field(vflag);
}

/* ----------------------------------------------------------------------
   two coul/fmm fixes sharing charged atoms would count their interactions twice; fixes on
   disjoint groups are allowed, but do not see each other
------------------------------------------------------------------------- */

void FixCoulFMM::check_other_coul_fmm_fixes()
{
  for (auto *other : modify->get_fix_by_style("^coul/fmm$")) {
    if (other == this) continue;
    const int both = groupbit | group->bitmask[other->igroup];
    int shared = 0, shared_all = 0;
    for (int i = 0; i < atom->nlocal; i++)
      if ((atom->mask[i] & both) == both && atom->q[i] != 0.0) shared++;
    MPI_Allreduce(&shared, &shared_all, 1, MPI_INT, MPI_SUM, world);
    if (shared_all > 0)
      error->all(FLERR,
                 "Fix coul/fmm {} and fix coul/fmm {} share {} charged atoms: their Coulomb "
                 "interactions would be counted twice",
                 id, other->id, shared_all);
    if (comm->me == 0)
      error->warning(FLERR,
                     "Fix coul/fmm {} and fix coul/fmm {} act on disjoint groups: charges of one "
                     "group do not interact with those of the other",
                     id, other->id);
  }
}

/* ---------------------------------------------------------------------- */

void FixCoulFMM::post_force(int vflag)
{
  v_init(vflag);
  const bigint step = update->ntimestep;
  // recompute on schedule, and whenever atoms were added or removed (e.g. fix deposit): a new
  // atom must feel, and exert, the Coulomb force from its first step
  if (last_computed < 0 || step - last_computed >= every || atom->natoms != natoms_computed) {
    compute_field();
    last_computed = step;
    natoms_computed = atom->natoms;
  }
  apply_field(vflag);
}

/* ----------------------------------------------------------------------
   gather the charged atoms of the group on every rank, sorted by atom ID, so that every rank
   builds the same tree and the result does not depend on the domain decomposition
------------------------------------------------------------------------- */

void FixCoulFMM::gather_charges()
{
  const int nlocal = atom->nlocal;
  double **x = atom->x;
  double *q = atom->q;
  int *mask = atom->mask;
  tagint *tag = atom->tag;

  buf.clear();
  for (int i = 0; i < nlocal; i++) {
    if (!(mask[i] & groupbit) || q[i] == 0.0) continue;
    buf.insert(buf.end(), {(double) tag[i], x[i][0], x[i][1], x[i][2], q[i]});
  }
  const int nprocs = comm->nprocs;
  std::vector<int> counts(nprocs), displs(nprocs);
  int mine = (int) buf.size();
  MPI_Allgather(&mine, 1, MPI_INT, counts.data(), 1, MPI_INT, world);
  int total = 0;
  for (int p = 0; p < nprocs; p++) {
    displs[p] = total;
    total += counts[p];
  }
  std::vector<double> all(total);
  MPI_Allgatherv(buf.data(), mine, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE,
                 world);

  const size_t n = total / 5;
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return all[5 * a] < all[5 * b];
  });
  gtag.resize(n);
  gx.resize(n);
  gy.resize(n);
  gz.resize(n);
  gq.resize(n);
  for (size_t k = 0; k < n; k++) {
    const double *r = &all[5 * order[k]];
    gtag[k] = (tagint) r[0];
    gx[k] = r[1];
    gy[k] = r[2];
    gz[k] = r[3];
    gq[k] = r[4];
  }
}

/* ----------------------------------------------------------------------
   evaluate the field at every charged atom: each rank computes one work partition of the
   targets, an Allreduce assembles the result (every target is computed by exactly one rank,
   so 1 and N ranks agree to the last bit for the same atom order)
------------------------------------------------------------------------- */

void FixCoulFMM::compute_field()
{
  gather_charges();
  const size_t n = gtag.size();
  const int nlocal = atom->nlocal;
  for (int i = 0; i < nlocal; i++)
    for (int k = 0; k < 4; k++) field[i][k] = 0.0;
  if (n == 0) return;

  result.assign(4 * n, 0.0);
  double *pot = result.data(), *ex = pot + n, *ey = pot + 2 * n, *ez = pot + 3 * n;

  std::string failure;
  try {
    if (opts->boundary == gcfmm::Boundary::Periodic2D)
      solver->set_box(domain->boxlo[0], domain->boxlo[1], domain->xprd, domain->yprd);
    solver->build(n, gx.data(), gy.data(), gz.data());
    solver->evaluate(gq.data(), pot, ex, ey, ez, comm->me, comm->nprocs);
  } catch (std::exception &e) {
    failure = e.what();
    if (failure.empty()) failure = "unknown error";
  }
  // a failure may be seen by one rank only (it owns the offending targets): agree on it
  int bad = failure.empty() ? comm->nprocs : comm->me, first = 0;
  MPI_Allreduce(&bad, &first, 1, MPI_INT, MPI_MIN, world);
  if (first < comm->nprocs) {
    int len = (int) failure.size();
    MPI_Bcast(&len, 1, MPI_INT, first, world);
    failure.resize(len);
    MPI_Bcast(&failure[0], len, MPI_CHAR, first, world);
    error->all(FLERR, Error::NOLASTLINE, "Fix coul/fmm: FMM library: {}", failure);
  }

  if (comm->nprocs > 1)
    MPI_Allreduce(MPI_IN_PLACE, result.data(), 4 * n, MPI_DOUBLE, MPI_SUM, world);

  // bare 1/r kernel -> LAMMPS units: qqrd2e includes the dielectric constant
  const double c = force->qqrd2e;
  int *mask = atom->mask;
  double *q = atom->q;
  tagint *tag = atom->tag;
  for (int i = 0; i < nlocal; i++) {
    if (!(mask[i] & groupbit) || q[i] == 0.0) continue;
    const size_t k = std::lower_bound(gtag.begin(), gtag.end(), tag[i]) - gtag.begin();
    field[i][0] = c * ex[k];
    field[i][1] = c * ey[k];
    field[i][2] = c * ez[k];
    field[i][3] = c * pot[k];
  }

  if (!logged && comm->me == 0) {
    const auto &st = solver->stats();
    static const char *ffname[] = {"none", "average", "exact"};
    utils::logmesg(lmp,
                   "FMM Coulomb (fix coul/fmm {}): {} charged atoms, {}\n"
                   "  order = {}, theta = {:.3g}, leaf = {}, levels = {}{}\n"
                   "  estimated relative RMS force error = {:.3g} (requested accuracy {:.3g})\n",
                   id, n,
                   opts->boundary == gcfmm::Boundary::Free ? "free space" : "periodic in x y",
                   st.order, st.theta, st.leaf, st.levels,
                   opts->boundary == gcfmm::Boundary::Free
                       ? std::string()
                       : fmt::format(", images = {}, farfield = {}", opts->images,
                                     ffname[(int) opts->farfield]),
                   st.estimated_error, opts->accuracy);
  }
  logged = true;
}

/* ----------------------------------------------------------------------
   F_i = q_i E_i; energy 1/2 sum q_i phi_i; virial sum x_i F_i (see the doc for its scope)
------------------------------------------------------------------------- */

void FixCoulFMM::apply_field(int /*vflag*/)
{
  const int nlocal = atom->nlocal;
  double **x = atom->x;
  double **f = atom->f;
  double *q = atom->q;
  int *mask = atom->mask;
  energy_local = 0.0;
  energy_summed = false;
  double v[6];
  const bool periodic_xy = opts->boundary == gcfmm::Boundary::Periodic2D;
  for (int i = 0; i < nlocal; i++) {
    if (!(mask[i] & groupbit) || q[i] == 0.0) continue;
    const double fx = q[i] * field[i][0], fy = q[i] * field[i][1], fz = q[i] * field[i][2];
    f[i][0] += fx;
    f[i][1] += fy;
    f[i][2] += fz;
    energy_local += 0.5 * q[i] * field[i][3];
    if (evflag) {
      // with x and y periodic only the zz term of sum x_i F_i is the virial of the lattice
      // (image shifts have no z component); the in-plane terms are left out
      const bool in_plane = !periodic_xy;
      v[0] = in_plane ? fx * x[i][0] : 0.0;
      v[1] = in_plane ? fy * x[i][1] : 0.0;
      v[2] = fz * x[i][2];
      v[3] = in_plane ? fy * x[i][0] : 0.0;
      v[4] = in_plane ? fz * x[i][0] : 0.0;
      v[5] = in_plane ? fz * x[i][1] : 0.0;
      v_tally(i, v);
    }
  }
}

/* ---------------------------------------------------------------------- */

double FixCoulFMM::compute_scalar()
{
  if (!energy_summed) {
    MPI_Allreduce(&energy_local, &energy_all, 1, MPI_DOUBLE, MPI_SUM, world);
    energy_summed = true;
  }
  return energy_all;
}

/* ----------------------------------------------------------------------
   1: estimated relative RMS force error, 2: expansion order, 3: M2L interactions,
   4: particle pairs summed directly (all of the last evaluation, the same on every rank)
------------------------------------------------------------------------- */

double FixCoulFMM::compute_vector(int n)
{
  if (!solver) return 0.0;
  const auto &st = solver->stats();
  switch (n) {
    case 0:
      return st.estimated_error;
    case 1:
      return st.order;
    case 2:
      return (double) st.m2l_count;
    case 3:
      return (double) st.p2p_pairs;
    default:
      return 0.0;
  }
}

/* ---------------------------------------------------------------------- */

double FixCoulFMM::memory_usage()
{
  double bytes = 4.0 * atom->nmax * sizeof(double);
  bytes += (double) (gx.capacity() * 9) * sizeof(double);    // gathered atoms and results
  return bytes;
}

/* ---------------------------------------------------------------------- */

void FixCoulFMM::grow_arrays(int nmax)
{
  memory->grow(field, nmax, 4, "coul/fmm:field");
  array_atom = field;
}

void FixCoulFMM::copy_arrays(int i, int j, int /*delflag*/)
{
  for (int k = 0; k < 4; k++) field[j][k] = field[i][k];
}

void FixCoulFMM::set_arrays(int i)
{
  for (int k = 0; k < 4; k++) field[i][k] = 0.0;
}

int FixCoulFMM::pack_exchange(int i, double *buf_out)
{
  for (int k = 0; k < 4; k++) buf_out[k] = field[i][k];
  return 4;
}

int FixCoulFMM::unpack_exchange(int nlocal, double *buf_in)
{
  for (int k = 0; k < 4; k++) field[nlocal][k] = buf_in[k];
  return 4;
}
