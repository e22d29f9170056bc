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
// collectives of the distributed solver (CoulFMMCollectives, coul_fmm_collectives.h).

#ifndef LMP_COUL_FMM_COMM_H
#define LMP_COUL_FMM_COMM_H

#include "pointers.h"

#include <mpi.h>

#include "coul_fmm_collectives.h"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace LAMMPS_NS {

// atoms of all ranks, sorted by atom ID (identical on every rank)
struct GatheredCharges {
  std::vector<double> x, y, z, q;
  std::vector<double> radius;    // the atoms' radii if gather() was asked for them (else empty)
  std::vector<tagint> tag;
  std::vector<size_t> order;    // sorted position -> position in the gather (rank blocks)
  std::vector<int> counts;      // atoms of each rank
  size_t size() const { return tag.size(); }
};

class CoulFMMComm : protected Pointers {
 public:
  explicit CoulFMMComm(class LAMMPS *lmp) : Pointers(lmp), collectives(lmp) {}

  // for gcfmm::DistributedSolver; its byte count includes gather() and return_to_owners()
  CoulFMMCollectives collectives;

  // the local atoms i with take(i) of every rank into `out`, and radius[i] into out.radius if
  // given
  void gather(const std::function<bool(int)> &take, GatheredCharges &out,
              const double *radius = nullptr);
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
