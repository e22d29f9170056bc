/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#include "coul_fmm_collectives.h"

#include "comm.h"
#include "error.h"
#include "lammps.h"
#include "lmptype.h"

#include <algorithm>

using namespace LAMMPS_NS;

/* ----------------------------------------------------------------------
   gcfmm::Communicator over the world communicator. alltoallv first exchanges the byte counts
   (MPI_Alltoall), then the bytes in one MPI_Alltoallv; counts and offsets are int, so one
   rank's messages must stay below 2 GiB in total (an error otherwise).
------------------------------------------------------------------------- */

CoulFMMCollectives::CoulFMMCollectives(LAMMPS *lmp_in) :
    lmp(lmp_in), world(lmp_in->world), me(lmp_in->comm->me), nprocs(lmp_in->comm->nprocs)
{
}

void CoulFMMCollectives::allreduce_sum(double *data, std::size_t count)
{
  MPI_Allreduce(MPI_IN_PLACE, data, (int) count, MPI_DOUBLE, MPI_SUM, world);
  if (nprocs > 1) received += (double) count * sizeof(double);
}

void CoulFMMCollectives::allreduce_max(double *data, std::size_t count)
{
  MPI_Allreduce(MPI_IN_PLACE, data, (int) count, MPI_DOUBLE, MPI_MAX, world);
  if (nprocs > 1) received += (double) count * sizeof(double);
}

void CoulFMMCollectives::allgather(const double *mine, std::size_t count, double *out)
{
  MPI_Allgather(mine, (int) count, MPI_DOUBLE, out, (int) count, MPI_DOUBLE, world);
  received += (double) count * (nprocs - 1) * sizeof(double);
}

void CoulFMMCollectives::alltoallv(const std::vector<std::vector<unsigned char>> &send,
                                   std::vector<std::vector<unsigned char>> &recv)
{
  std::vector<int> scount(nprocs), rcount(nprocs), sdispl(nprocs), rdispl(nprocs);
  double stotal = 0.0, rtotal = 0.0;
  for (int p = 0; p < nprocs; p++) {
    scount[p] = p < (int) send.size() ? (int) send[p].size() : 0;
    stotal += scount[p];
  }
  MPI_Alltoall(scount.data(), 1, MPI_INT, rcount.data(), 1, MPI_INT, world);
  for (int p = 0; p < nprocs; p++) rtotal += rcount[p];
  const double limit = (double) MAXSMALLINT;
  int too_large = (stotal > limit || rtotal > limit) ? 1 : 0, any = 0;
  MPI_Allreduce(&too_large, &any, 1, MPI_INT, MPI_MAX, world);
  if (any)
    lmp->error->all(
        FLERR,
        "Fix coul/fmm: a rank would exchange more than 2 GiB of local essential "
        "tree in one evaluation (sent {:.3g}, received {:.3g} bytes here): use more ranks",
        stotal, rtotal);
  int soff = 0, roff = 0;
  for (int p = 0; p < nprocs; p++) {
    sdispl[p] = soff;
    rdispl[p] = roff;
    soff += scount[p];
    roff += rcount[p];
  }
  bytes_out.resize(soff);
  for (int p = 0; p < nprocs; p++)
    if (scount[p]) std::copy(send[p].begin(), send[p].end(), bytes_out.begin() + sdispl[p]);
  bytes_in.resize(roff);
  MPI_Alltoallv(bytes_out.data(), scount.data(), sdispl.data(), MPI_UNSIGNED_CHAR, bytes_in.data(),
                rcount.data(), rdispl.data(), MPI_UNSIGNED_CHAR, world);
  recv.resize(nprocs);
  for (int p = 0; p < nprocs; p++)
    recv[p].assign(bytes_in.begin() + rdispl[p], bytes_in.begin() + rdispl[p] + rcount[p]);
  received += rtotal - rcount[me] + (double) (nprocs - 1) * sizeof(int);
}

double CoulFMMCollectives::take_received_bytes()
{
  const double bytes = received;
  received = 0.0;
  return bytes;
}
