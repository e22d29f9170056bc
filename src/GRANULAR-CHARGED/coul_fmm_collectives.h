/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

// gcfmm::Communicator (the collectives of gcfmm::DistributedSolver) over the LAMMPS world.

#ifndef LMP_COUL_FMM_COLLECTIVES_H
#define LMP_COUL_FMM_COLLECTIVES_H

#include <mpi.h>

#include "gcfmm/communicator.hpp"

#include <vector>

namespace LAMMPS_NS {

// gcfmm::Communicator (the collectives of gcfmm::DistributedSolver) over the LAMMPS world,
// counting the bytes this rank receives
class CoulFMMCollectives : public gcfmm::Communicator {
 public:
  explicit CoulFMMCollectives(class LAMMPS *lmp);
  int rank() const override { return me; }
  int size() const override { return nprocs; }
  void allreduce_sum(double *data, std::size_t count) override;
  void allreduce_max(double *data, std::size_t count) override;
  void allgather(const double *mine, std::size_t count, double *all) override;
  void alltoallv(const std::vector<std::vector<unsigned char>> &send,
                 std::vector<std::vector<unsigned char>> &recv) override;
  // bytes of other ranks' data received here since the last call (then reset to 0)
  double take_received_bytes();
  void count_received(double bytes) { received += bytes; }

 private:
  class LAMMPS *lmp;
  MPI_Comm world;
  int me, nprocs;
  std::vector<unsigned char> bytes_in, bytes_out;
  double received = 0.0;
};

}    // namespace LAMMPS_NS

#endif
