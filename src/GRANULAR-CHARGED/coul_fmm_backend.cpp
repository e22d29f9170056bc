/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "coul_fmm_backend.h"

#include "comm.h"
#include "domain.h"
#include "error.h"
#include "fix.h"
#include "force.h"
#include "group.h"
#include "kspace.h"
#include "modify.h"
#include "pair.h"
#include "atom.h"

#include "gcfmm/coulomb_backend.hpp"
#include "gcfmm/far_field.hpp"
#include "gcfmm/options.hpp"

#include <exception>
#include <utility>

using namespace LAMMPS_NS;

CoulFMMBackend::CoulFMMBackend(LAMMPS *lmp) :
    Pointers(lmp), kind(Kind::REPLICATED), boundary(-1), mpi(lmp)
{
}

CoulFMMBackend::~CoulFMMBackend() = default;

bool CoulFMMBackend::create(Kind k, const gcfmm::Options &opts, bool dipoles)
{
  const bool fresh = !backend || k != kind || boundary != (int) opts.boundary ||
      k == Kind::POLARIZABLE;
  if (!fresh) return false;
  kind = k;
  boundary = (int) opts.boundary;
  backend.reset();
  // the one sum over the ranks of the solvers that every rank runs on all atoms: each rank
  // computes its share of the work, the sum completes it (each value comes from one rank: the
  // same result as on one rank)
  const gcfmm::PartSum sum = [this](double *data, std::size_t count) {
    mpi.collectives.allreduce_sum(data, count);
  };
  try {
    if (kind == Kind::DISTRIBUTED) {
      backend = std::make_unique<gcfmm::DistributedBackend>(opts, mpi.collectives);
    } else if (kind == Kind::POLARIZABLE) {
      auto polar = std::make_unique<gcfmm::PolarizableBackend>(opts, dipoles);
      // each rank its share of the targets of every FMM evaluation
      if (comm->nprocs > 1) polar->solver().set_partition(comm->me, comm->nprocs, sum);
      backend = std::move(polar);
    } else {
      // the ranks share the far field's anterpolation, which every one of them would
      // otherwise repeat
      backend = std::make_unique<gcfmm::ReplicatedBackend>(opts, comm->me, comm->nprocs, sum);
    }
  } catch (std::exception &e) {
    error->all(FLERR, "Fix coul/fmm: FMM library: {}", e.what());
  }
  return true;
}

gcfmm::PolarizableBackend &CoulFMMBackend::polarizable()
{
  return dynamic_cast<gcfmm::PolarizableBackend &>(*backend);
}

void CoulFMMBackend::set_geometry(gcfmm::Options &o, bool bed_given)
{
  const int px = domain->xperiodic, py = domain->yperiodic, pz = domain->zperiodic;
  if (!px && !py && !pz)
    o.boundary = gcfmm::Boundary::Free;
  else if (px && py && !pz)
    o.boundary = gcfmm::Boundary::Periodic2D;
  else
    error->all(FLERR,
               "Fix coul/fmm requires boundary f f f (free space) or p p f (periodic in x "
               "and y, open in z), got periodicity {} {} {}",
               px ? "p" : "f", py ? "p" : "f", pz ? "p" : "f");
  const bool periodic = o.boundary == gcfmm::Boundary::Periodic2D;
  const bool exact = periodic && o.farfield == gcfmm::FarField::Exact;
  if (exact && o.images == 0)
    error->all(FLERR,
               "Fix coul/fmm farfield exact with boundary p p f needs images >= 1, got "
               "images 0 (the far-field kernel of the exact lattice sum is singular inside the "
               "cell then): use images >= 1, or farfield average or none");
  // the exact far field meets the requested accuracy only for cells close to square
  const double aspect = MAX(domain->xprd, domain->yprd) / MIN(domain->xprd, domain->yprd);
  if (exact && aspect > gcfmm::PeriodicFarField::kMaxAspect)
    error->all(FLERR,
               "Fix coul/fmm farfield exact supports cells with max(Lx, Ly) / min(Lx, Ly) "
               "<= {:g}, got {:g}: use farfield average or none, or a cell closer to square",
               gcfmm::PeriodicFarField::kMaxAspect, aspect);
  if (bed_given && !(periodic && o.farfield == gcfmm::FarField::Average))
    error->all(FLERR,
               "Fix coul/fmm keyword bed applies only to farfield average with boundary p p f");
}

void CoulFMMBackend::check_counted_once(Fix *self)
{
  const bool me0 = comm->me == 0;
  if (force->kspace && me0)
    error->warning(FLERR,
                   "Fix coul/fmm is used together with a kspace style: Coulomb "
                   "interactions may be counted twice");
  // a pair style with a Coulomb part (coul/cut, lj/cut/coul/long, ... or a hybrid sub-style)
  // adds the same interactions again for the pairs within its cutoff
  int dim = 0;
  if (force->pair && me0 && (force->pair->extract("cut_coul", dim) || force->pair_match("coul", 0)))
    error->warning(FLERR,
                   "Fix coul/fmm {} is used together with pair style {}, which computes "
                   "Coulomb interactions too: they are counted twice within its cutoff (use a pair "
                   "style without a coul part)",
                   self->id, force->pair_style);
  // fixes on disjoint groups are allowed, but do not see each other
  for (auto *other : modify->get_fix_by_style("^coul/fmm$")) {
    if (other == self) continue;
    const int both = self->groupbit | group->bitmask[other->igroup];
    double shared = 0.0;
    for (int i = 0; i < atom->nlocal; i++)
      if ((atom->mask[i] & both) == both && atom->q[i] != 0.0) shared += 1.0;
    mpi.sum(&shared, 1);
    if (shared > 0.0)
      error->all(FLERR,
                 "Fix coul/fmm {} and fix coul/fmm {} share {} charged atoms: their "
                 "Coulomb interactions would be counted twice",
                 self->id, other->id, (bigint) shared);
    if (me0)
      error->warning(FLERR,
                     "Fix coul/fmm {} and fix coul/fmm {} act on disjoint groups: charges "
                     "of one group do not interact with those of the other",
                     self->id, other->id);
  }
}

CoulFMMCell CoulFMMBackend::cell() const
{
  CoulFMMCell c;
  c.periodic = domain->xperiodic && domain->yperiodic;
  c.xlo = domain->boxlo[0];
  c.ylo = domain->boxlo[1];
  c.lx = domain->xprd;
  c.ly = domain->yprd;
  c.zlo = domain->boxlo[2];
  c.zhi = domain->boxhi[2];
  return c;
}

void CoulFMMBackend::set_cell()
{
  cell().apply_to(*backend);
}

double CoulFMMBackend::scale() const
{
  return force->qqrd2e;
}

// "" or what failed, in LAMMPS terms
std::string CoulFMMBackend::failure_of(const std::function<void()> &evaluation,
                                       const std::function<tagint(size_t)> &tag_of) const
{
  try {
    evaluation();
  } catch (Failure &e) {
    return e.what();
  } catch (gcfmm::CoincidentParticles &e) {
    return fmt::format("atoms {} and {} are at the same position (closer than {:g} of the "
                       "solver's length unit): their Coulomb force is not defined",
                       tag_of(e.first()), tag_of(e.second()), gcfmm::kCoincidenceRadius);
  } catch (gcfmm::FarFieldTooLarge &e) {
    // the column's height (box or charges) sets the cost of the exact far field
    return fmt::format("{}. In LAMMPS terms: the charged column (or the box in z, with "
                       "boundary p p f) is {:.3g} times the cell side; use farfield average or "
                       "none, a box or a wall that keeps the particles lower (a lid), or "
                       "remove escaping particles (e.g. fix evaporate)",
                       e.what(), e.height_over_side());
  } catch (std::exception &e) {
    const std::string what = e.what();
    return what.empty() ? "unknown error" : what;
  }
  return "";
}

void CoulFMMBackend::run(const std::function<void()> &evaluation,
                         const std::function<tagint(size_t)> &tag_of, bool same_on_all_ranks,
                         const std::function<std::string()> &explain)
{
  std::string failure = failure_of(evaluation, tag_of);
  if (!same_on_all_ranks) failure = mpi.first_failure(failure);
  if (failure.empty()) return;
  const std::string better = explain ? explain() : std::string();
  error->all(FLERR, Error::NOLASTLINE, "Fix coul/fmm: FMM library: {}",
             better.empty() ? failure : better);
}
