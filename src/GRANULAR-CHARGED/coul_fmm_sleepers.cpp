/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "coul_fmm_sleepers.h"

#include "coul_fmm_comm.h"

#include "atom.h"
#include "comm.h"

#include "gcfmm/options.hpp"
#include "gcfmm/static_field.hpp"


using namespace LAMMPS_NS;

namespace {
// the static part's share of the requested accuracy: the awake atoms' field is the sum of two
// approximations (Solver over the awake charges, static field of the sleepers), each with its
// own error; at half the accuracy each, the sum meets it (measured in test_sleep_gran,
// CoulombSleepersAreAStaticSource: 1.5e-6 at 1e-6 with the full accuracy for both parts)
gcfmm::Options static_options(const gcfmm::Options &opts)
{
  gcfmm::Options o = opts;
  o.accuracy = 0.5 * opts.accuracy;
  return o;
}
}    // namespace

CoulFMMSleepers::CoulFMMSleepers(LAMMPS *lmp, const gcfmm::Options &opts, int groupbit_in) :
    Pointers(lmp), field(new gcfmm::StaticSourceField(static_options(opts))), groupbit(groupbit_in),
    flags(nullptr), generation(-1), built_generation(-2)
{
}

CoulFMMSleepers::~CoulFMMSleepers() = default;

void CoulFMMSleepers::use(const double *asleep, bigint gen)
{
  flags = asleep;
  generation = gen;
}

// the charged sleepers of the group on every rank, sorted by atom ID
void CoulFMMSleepers::gather()
{
  int *mask = atom->mask;
  double *q = atom->q;
  CoulFMMComm(lmp).gather(
      [&](int i) {
        return (mask[i] & groupbit) && q[i] != 0.0 && asleep(i);
      },
      sources);
}

void CoulFMMSleepers::prepare(const CoulFMMCell &cell)
{
  if (generation == built_generation && cell == built_cell) return;
  gather();
  cell.apply_to(*field);
  field->set_sources(sources.size(), sources.x.data(), sources.y.data(), sources.z.data(),
                     sources.q.data());
  built_generation = generation;
  built_cell = cell;
}

double CoulFMMSleepers::add_field(const double *x, const double *y, const double *z,
                                  const double *q, size_t first, size_t last, double *pot,
                                  double *ex, double *ey, double *ez)
{
  if (last <= first || sources.size() == 0) return 0.0;
  const size_t m = last - first;
  std::vector<double> r(4 * m);
  field->evaluate(m, x + first, y + first, z + first, r.data(), r.data() + m, r.data() + 2 * m,
                  r.data() + 3 * m);
  double qpot = 0.0;
  for (size_t k = 0; k < m; k++) {
    pot[first + k] += r[k];
    ex[first + k] += r[m + k];
    ey[first + k] += r[2 * m + k];
    ez[first + k] += r[3 * m + k];
    qpot += q[first + k] * r[k];
  }
  return qpot;
}

double CoulFMMSleepers::source_energy()
{
  return sources.size() == 0 ? 0.0 : field->source_energy();
}

double CoulFMMSleepers::memory_usage() const
{
  return (double) field->memory_bytes() + 5.0 * sizeof(double) * sources.size();
}
