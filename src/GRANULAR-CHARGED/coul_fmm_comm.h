/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

// The MPI communication of fix coul/fmm in one place: gathering a set of charged atoms on every
// rank (sorted by atom ID, the same set and order everywhere), returning per-atom results to
// their owners, agreeing on a failure seen by one rank, the global sums the fix needs, and the
// collectives of the distributed solver (gcfmm::Communicator over the LAMMPS world).

#ifndef LMP_COUL_FMM_COMM_H
#define LMP_COUL_FMM_COMM_H

#include "pointers.h"

#include <mpi.h>

#include "gcfmm/communicator.hpp"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace LAMMPS_NS {

// atoms of all ranks, sorted by atom ID (identical on every rank)
struct GatheredCharges {
  std::vector<double> x, y, z, q;
  std::vector<double> extra;    // gather()'s optional per-atom value (empty without one)
  std::vector<tagint> tag;
  std::vector<size_t> order;    // sorted position -> position in the gather (rank blocks)
  std::vector<int> counts;      // atoms of each rank
  size_t size() const { return tag.size(); }
};

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

class CoulFMMComm : protected Pointers {
 public:
  explicit CoulFMMComm(class LAMMPS *lmp) : Pointers(lmp), collectives(lmp) {}

  // for gcfmm::DistributedSolver; its byte count includes gather() and return_to_owners()
  CoulFMMCollectives collectives;

  // the local atoms i with take(i) of every rank into `out`, and extra[i] into out.extra if given
  void gather(const std::function<bool(int)> &take, GatheredCharges &out,
              const double *extra = nullptr);
  // values[4 k .. 4 k + 3] of gathered atom k, each computed by one rank and zero on the others:
  // summed over the ranks, and this rank's atoms handed back in the order gather() took them
  void return_to_owners(const GatheredCharges &g, const std::vector<double> &values,
                        std::vector<double> &mine);

  // the message of the lowest rank whose `failure` is not empty, on every rank ("" if none)
  std::string first_failure(const std::string &failure);

  void sum(double *values, int n);
  void sum(uint64_t *values, int n);
  bool any(bool flag);

 private:
  std::vector<double> buf, all, sorted;
};

}    // namespace LAMMPS_NS

#endif
