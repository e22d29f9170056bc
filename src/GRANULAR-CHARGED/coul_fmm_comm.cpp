/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "coul_fmm_comm.h"

#include "atom.h"
#include "comm.h"
#include "error.h"
#include "lammps.h"

#include <algorithm>
#include <numeric>

using namespace LAMMPS_NS;

/* ----------------------------------------------------------------------
   sorted by atom ID, so that every rank builds the same tree and the result does not depend on
   the domain decomposition
------------------------------------------------------------------------- */

void CoulFMMComm::gather(const std::function<bool(int)> &take, GatheredCharges &out,
                         const double *radius)
{
  double **x = atom->x;
  double *q = atom->q;
  tagint *tag = atom->tag;
  const int per = radius ? 6 : 5;
  buf.clear();
  for (int i = 0; i < atom->nlocal; i++) {
    if (!take(i)) continue;
    buf.insert(buf.end(), {(double) tag[i], x[i][0], x[i][1], x[i][2], q[i]});
    if (radius) buf.push_back(radius[i]);
  }

  const int nprocs = comm->nprocs;
  std::vector<int> counts(nprocs), displs(nprocs);
  int mine = (int) buf.size(), total = 0;
  MPI_Allgather(&mine, 1, MPI_INT, counts.data(), 1, MPI_INT, world);
  for (int p = 0; p < nprocs; p++) {
    displs[p] = total;
    total += counts[p];
  }
  all.resize(total);
  MPI_Allgatherv(buf.data(), mine, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE,
                 world);
  out.counts.resize(nprocs);
  for (int p = 0; p < nprocs; p++) out.counts[p] = counts[p] / per;
  collectives.count_received((double) (total - mine) * sizeof(double));

  const size_t n = total / per;
  out.order.resize(n);
  std::iota(out.order.begin(), out.order.end(), 0);
  std::sort(out.order.begin(), out.order.end(), [&](size_t a, size_t b) {
    return all[per * a] < all[per * b];
  });
  out.tag.resize(n);
  out.x.resize(n);
  out.y.resize(n);
  out.z.resize(n);
  out.q.resize(n);
  out.radius.resize(radius ? n : 0);
  for (size_t k = 0; k < n; k++) {
    const double *r = &all[per * out.order[k]];
    out.tag[k] = (tagint) r[0];
    out.x[k] = r[1];
    out.y[k] = r[2];
    out.z[k] = r[3];
    out.q[k] = r[4];
    if (radius) out.radius[k] = r[5];
  }
}

/* ----------------------------------------------------------------------
   a reduce-scatter in the order of the gather sums the ranks' parts and hands each rank its
   own atoms only
------------------------------------------------------------------------- */

void CoulFMMComm::return_to_owners(const GatheredCharges &g, const std::vector<double> &values,
                                   std::vector<double> &mine)
{
  const size_t n = g.size();
  sorted.resize(4 * n);
  for (size_t k = 0; k < n; k++)
    std::copy(&values[4 * k], &values[4 * k] + 4, &sorted[4 * g.order[k]]);
  std::vector<int> counts(g.counts.size());
  for (size_t p = 0; p < counts.size(); p++) counts[p] = 4 * g.counts[p];
  mine.resize(counts[comm->me]);
  MPI_Reduce_scatter(sorted.data(), mine.data(), counts.data(), MPI_DOUBLE, MPI_SUM, world);
  // what any reduce-scatter algorithm must receive: the other ranks' parts of this block
  collectives.count_received((double) (comm->nprocs - 1) * counts[comm->me] * sizeof(double));
}

std::string CoulFMMComm::first_failure(const std::string &failure)
{
  int bad = failure.empty() ? comm->nprocs : comm->me, first = 0;
  MPI_Allreduce(&bad, &first, 1, MPI_INT, MPI_MIN, world);
  if (first == comm->nprocs) return std::string();
  std::string message = failure;
  int len = (int) message.size();
  MPI_Bcast(&len, 1, MPI_INT, first, world);
  message.resize(len);
  MPI_Bcast(&message[0], len, MPI_CHAR, first, world);
  return message;
}

void CoulFMMComm::sum(double *values, int n)
{
  MPI_Allreduce(MPI_IN_PLACE, values, n, MPI_DOUBLE, MPI_SUM, world);
}

void CoulFMMComm::sum(uint64_t *values, int n)
{
  MPI_Allreduce(MPI_IN_PLACE, values, n, MPI_UINT64_T, MPI_SUM, world);
}

bool CoulFMMComm::any(bool flag)
{
  int mine = flag ? 1 : 0, all_flags = 0;
  MPI_Allreduce(&mine, &all_flags, 1, MPI_INT, MPI_MAX, world);
  return all_flags != 0;
}
