// GRANULAR-CHARGED FMM core library (gcfmm).
// The collective operations DistributedSolver needs, as an abstract interface the caller
// implements (the LAMMPS fix with MPI; the tests with threads). gcfmm itself never links MPI.
#ifndef GCFMM_COMMUNICATOR_HPP
#define GCFMM_COMMUNICATOR_HPP

#include <cstddef>
#include <vector>

namespace gcfmm {

/** @brief A group of ranks and the five collectives of DistributedSolver::evaluate().
 *  Every call is collective: all ranks of the group make it, in the same order, with the same
 *  `count`. Implementations must give every rank the same result of a reduction (an
 *  MPI_Allreduce does). Byte buffers (alltoallv) are the only variable-size exchange; the
 *  receiver learns the sizes from the implementation (MPI: an MPI_Alltoall of the counts
 *  first), so the interface carries no separate size exchange. */
class Communicator {
 public:
  virtual ~Communicator() = default;
  virtual int rank() const = 0;  //!< this rank, 0 <= rank() < size()
  virtual int size() const = 0;  //!< number of ranks
  //! element-wise sum over all ranks, in place, the same result on every rank
  virtual void allreduce_sum(double *data, std::size_t count) = 0;
  //! element-wise maximum over all ranks, in place (minima: pass -x)
  virtual void allreduce_max(double *data, std::size_t count) = 0;
  //! `count` doubles from every rank, concatenated in rank order into all[0 .. size() count)
  virtual void allgather(const double *mine, std::size_t count, double *all) = 0;
  /** send[r]: the bytes for rank r (send.size() == size(); send[rank()] may be empty);
   *  recv is resized to size() and recv[r] receives rank r's bytes to this rank. */
  virtual void alltoallv(const std::vector<std::vector<unsigned char>> &send,
                         std::vector<std::vector<unsigned char>> &recv) = 0;
};

//! One rank: the reductions are the identity, alltoallv copies send[0] into recv[0].
class SerialCommunicator final : public Communicator {
 public:
  int rank() const override { return 0; }
  int size() const override { return 1; }
  void allreduce_sum(double *, std::size_t) override {}
  void allreduce_max(double *, std::size_t) override {}
  void allgather(const double *mine, std::size_t count, double *all) override {
    for (std::size_t i = 0; i < count; ++i) all[i] = mine[i];
  }
  void alltoallv(const std::vector<std::vector<unsigned char>> &send,
                 std::vector<std::vector<unsigned char>> &recv) override {
    recv.assign(1, send.empty() ? std::vector<unsigned char>{} : send[0]);
  }
};

}  // namespace gcfmm

#endif
