// GRANULAR-CHARGED FMM core library (gcfmm): the distributed solver's internal state (private
// header of src/distributed_*.cpp). One evaluate() on every rank (doc/fmm-distributed.md):
//   global geometry (allreduce_max) -> this rank's tree, local lists, P2M/M2M (SolverCore)
//   -> target boxes (allgather) -> LET per other rank (distributed_let.cpp) -> alltoallv
//   -> received LETs as one source tree -> remote lists -> M2L, P2P, M2P local + remote
//   -> L2L/L2P -> far field (allreduce_sum of node potentials or of the charge) -> scatter.
#ifndef GCFMM_DISTRIBUTED_IMPL_HPP
#define GCFMM_DISTRIBUTED_IMPL_HPP

#include "gcfmm/distributed_solver.hpp"

#include <exception>

#include "solver_impl.hpp"

namespace gcfmm {

namespace detail {

//! An axis-aligned box in units of h (a rank's targets); empty when lo > hi.
struct Box {
  double lo[3], hi[3];
  bool empty() const { return lo[0] > hi[0]; }
  //! distance from the point p to the box (0 inside)
  double distance(const Vec3 &p) const {
    const double c[3] = {p.x, p.y, p.z};
    double d2 = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double d = std::max({lo[k] - c[k], 0.0, c[k] - hi[k]});
      d2 += d * d;
    }
    return std::sqrt(d2);
  }
};

//! The sources received from all other ranks as one tree: node 0 is a virtual root (infinite
//! radius: never accepted, always split) whose children are the ranks' LET roots.
struct ReceivedLet {
  Tree tree;                         //!< nodes and particle positions (xs, ys, zs); perm unused
  std::vector<double> q;             //!< particle charges (all nonzero)
  std::vector<std::int64_t> ids;     //!< particle ids
  std::vector<double> multipole;     //!< ops.size() doubles per node (node 0: zero)
  std::vector<char> multipole_only;  //!< particle range incomplete (truncated or above one): never P2P
  std::vector<char> truncated;       //!< multipole received (no children, no particles)
  std::size_t nodes_received = 0, particles_received = 0;
  void clear();
  std::size_t memory_bytes() const;
};

/** The LET of `tree` (multipoles `multipole`, charges q in tree order, ids in tree order,
 *  `charged` the number of nonzero charges per node) for a rank whose targets lie in `box`,
 *  for every image shift, written to `out` (format in doc/fmm-distributed.md, "Buffer
 *  layout"). Nothing is written for an empty box or a tree without charge. */
void pack_let(const Tree &tree, const std::vector<std::uint32_t> &charged, const double *multipole, const double *q,
              const std::int64_t *ids, const Operators &ops, const Box &box, const std::vector<Vec3> &shifts,
              double theta, std::vector<unsigned char> &out);

/** All ranks' LET buffers merged into one source tree (ReceivedLet), with the multipoles of
 *  the nodes that were not truncated computed here (P2M of the received particles, M2M). */
void unpack_lets(const std::vector<std::vector<unsigned char>> &recv, int self, Operators &ops, ReceivedLet &let);

}  // namespace detail

struct DistributedSolver::Impl {
  explicit Impl(Communicator &c) : comm(c) {}
  Communicator &comm;
  detail::SolverCore core;          // this rank's particles: tree, local lists, expansions, far field
  DistributedStats stats;
  bool evaluated = false;           // the last evaluate() completed
  std::vector<std::int64_t> sorted_ids;  // ids in tree order
  std::vector<std::uint32_t> charged;  // nonzero charges per node of this rank's tree
  std::vector<double> boxes;        // every rank's target box, 6 doubles per rank (lo, hi)
  std::vector<std::vector<unsigned char>> send, recv;  // LET buffers
  detail::ReceivedLet let;
  InteractionLists remote;          // this rank's tree against the received LETs
  std::vector<double> phi;          // far-field node potentials (FarField::Exact)
  // the first coincident pair (ids, smaller first) seen by this rank, if any
  bool coincident = false;
  std::int64_t coincident_first = 0, coincident_second = 0;

  void record_coincidence(std::int64_t a, std::int64_t b);
  void mark_charged_nodes();
  void build_remote_lists();
  void find_remote_coincidences();
  void remote_m2l();
  void remote_p2p_m2p();
  std::size_t memory_bytes() const;
};

}  // namespace gcfmm

#endif
