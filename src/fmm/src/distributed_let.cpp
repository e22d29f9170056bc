// GRANULAR-CHARGED FMM core library (gcfmm): the local essential tree (LET) one rank sends to
// another, its byte layout and the merge of all received LETs into one source tree
// (doc/fmm-distributed.md, "LET criterion" and "Buffer layout").
#include "distributed_impl.hpp"

#include <cstring>
#include <limits>

namespace gcfmm {

namespace detail {

namespace {

// per node on the wire: centre, radius, then child, nchild, begin, end, flags
constexpr std::size_t kNodeBytes = 4 * sizeof(double) + 5 * sizeof(std::int32_t);
// flags bits: the node's particle range is incomplete (it is truncated or has a truncated
// descendant): never P2P (build_lists' multipole_only); the node is truncated (no children, no
// particles): its multipole is sent (the receiver computes all others from what it receives)
constexpr std::int32_t kMultipoleOnly = 1, kTruncated = 2;

// per particle on the wire: x, y, z, q, id
constexpr std::size_t kParticleBytes = 4 * sizeof(double) + sizeof(std::int64_t);

// the m >= 0 coefficients of an expansion (upward_pass' symmetrize() restores m < 0): (p+1)(p+2)/2 complex
inline std::size_t half_size(int p) { return static_cast<std::size_t>(p + 1) * (p + 2); }

template <class T>
void put(std::vector<unsigned char> &out, const T &v) {
  const std::size_t at = out.size();
  out.resize(at + sizeof(T));
  std::memcpy(out.data() + at, &v, sizeof(T));
}

struct Reader {
  const std::vector<unsigned char> &in;
  std::size_t at = 0;
  template <class T>
  T get() {
    if (at + sizeof(T) > in.size()) throw std::runtime_error("gcfmm: truncated LET buffer");
    T v;
    std::memcpy(&v, in.data() + at, sizeof(T));
    at += sizeof(T);
    return v;
  }
};

// One sent node: where its children and particles go in the LET being built.
struct LetNode {
  Vec3 center;
  double radius = 0.0;
  std::int32_t child = -1, nchild = 0, begin = 0, end = 0, flags = 0;
  std::int32_t source = 0;  // node of the sender's tree
};

// The traversal of the sender's tree for one receiving box (doc/fmm-distributed.md, eq. (D.1)):
// node n is sent multipole only when r_n < theta dist(c_n + s, B) for every shift s (the point
// MAC at every target the receiver can have), no particle of it can be within the coincidence
// radius of the box, and its charges would take more bytes than its multipole.
struct LetBuilder {
  const Tree &tree;
  const std::vector<std::uint32_t> &charged;
  std::size_t multipole_bytes;  // of one truncated node on the wire
  const double *q;
  const Box &box;
  const std::vector<Vec3> &shifts;
  double theta;
  std::vector<LetNode> nodes;
  std::vector<std::uint32_t> particles;  // sent particles, tree order

  bool multipole_only(const Node &A) const {
    for (const Vec3 &s : shifts) {
      const double d = box.distance(A.center + s);
      if (!(A.radius < theta * d && d - A.radius > 2.0 * kCoincidenceRadius)) return false;
    }
    return true;
  }

  // fill LET node `slot` from tree node `src`; children get contiguous slots, particles are
  // appended depth-first, so every node's particles are contiguous
  void emit(std::int32_t src, std::size_t slot) {
    const Node &A = tree.nodes[src];
    LetNode out;
    out.center = A.center;
    out.radius = A.radius;
    out.source = src;
    out.begin = static_cast<std::int32_t>(particles.size());
    // a node of few charges is cheaper sent as their particles (a leaf of the LET) than as a
    // multipole; a leaf's particles are always sent when it is not truncated
    const bool few = charged[src] * kParticleBytes <= multipole_bytes;
    if (!few && multipole_only(A)) {
      out.flags = kMultipoleOnly | kTruncated;
    } else if (A.leaf() || few) {
      for (std::uint32_t k = A.begin; k < A.end; ++k)
        if (q[k] != 0.0) particles.push_back(k);  // zero charges are sources of nothing
    } else {
      std::int32_t kept = 0;
      for (int c = 0; c < A.nchild; ++c) kept += charged[A.child + c] ? 1 : 0;
      const std::size_t first = nodes.size();
      nodes.resize(first + kept);
      out.child = static_cast<std::int32_t>(first);
      out.nchild = kept;
      std::size_t next = first;
      for (int c = 0; c < A.nchild; ++c)
        if (charged[A.child + c]) emit(A.child + c, next++);
      for (std::size_t k = first; k < next; ++k) out.flags |= nodes[k].flags & kMultipoleOnly;
    }
    out.end = static_cast<std::int32_t>(particles.size());
    nodes[slot] = out;
  }
};

}  // namespace

void pack_let(const Tree &tree, const std::vector<std::uint32_t> &charged, const double *multipole, const double *q,
              const std::int64_t *ids, const Operators &ops, const Box &box, const std::vector<Vec3> &shifts,
              double theta, std::vector<unsigned char> &out) {
  out.clear();
  if (box.empty() || tree.nodes.empty() || !charged[0]) return;
  LetBuilder b{tree, charged, half_size(ops.order()) * sizeof(double), q, box, shifts, theta, {}, {}};
  b.nodes.resize(1);
  b.emit(0, 0);
  const int p = ops.order();
  const std::size_t S = ops.size() / 2, half = half_size(p);
  const std::size_t nn = b.nodes.size(), np = b.particles.size();
  std::size_t truncated = 0;
  for (const LetNode &n : b.nodes) truncated += (n.flags & kTruncated) ? 1 : 0;
  out.reserve(2 * sizeof(std::int64_t) + nn * kNodeBytes + truncated * half * sizeof(double) +
              np * kParticleBytes);
  put(out, static_cast<std::int64_t>(nn));
  put(out, static_cast<std::int64_t>(np));
  for (const LetNode &n : b.nodes) {
    for (double v : {n.center.x, n.center.y, n.center.z, n.radius}) put(out, v);
    for (std::int32_t v : {n.child, n.nchild, n.begin, n.end, n.flags}) put(out, v);
  }
  for (const LetNode &n : b.nodes) {
    if (!(n.flags & kTruncated)) continue;
    const double *M = multipole + static_cast<std::size_t>(n.source) * ops.size();
    for (std::size_t part = 0; part < 2; ++part)  // real parts, then imaginary parts
      for (int k = 0; k <= p; ++k)
        for (int m = 0; m <= k; ++m) put(out, M[part * S + k * k + k + m]);
  }
  for (const auto *v : {&tree.xs, &tree.ys, &tree.zs})
    for (std::uint32_t k : b.particles) put(out, (*v)[k]);
  for (std::uint32_t k : b.particles) put(out, q[k]);
  for (std::uint32_t k : b.particles) put(out, ids[k]);
}

void ReceivedLet::clear() {
  tree.nodes.clear();
  tree.xs.clear();
  tree.ys.clear();
  tree.zs.clear();
  q.clear();
  ids.clear();
  multipole.clear();
  multipole_only.clear();
  truncated.clear();
  nodes_received = particles_received = 0;
}

std::size_t ReceivedLet::memory_bytes() const {
  return tree_bytes(tree) + vector_bytes(q) + vector_bytes(ids) + vector_bytes(multipole) +
         vector_bytes(multipole_only) + vector_bytes(truncated);
}

void unpack_lets(const std::vector<std::vector<unsigned char>> &recv, int self, Operators &ops, ReceivedLet &let) {
  let.clear();
  // sizes first: the virtual root, the ranks' roots contiguous after it, then their other nodes
  std::size_t roots = 0, total_nodes = 1, total_particles = 0;
  for (int r = 0; r < static_cast<int>(recv.size()); ++r) {
    if (r == self || recv[r].empty()) continue;
    Reader rd{recv[r]};
    const auto nn = rd.get<std::int64_t>(), np = rd.get<std::int64_t>();
    if (nn <= 0) continue;
    ++roots;
    total_nodes += static_cast<std::size_t>(nn);
    total_particles += static_cast<std::size_t>(np);
  }
  let.nodes_received = total_nodes - 1;
  let.particles_received = total_particles;
  if (roots == 0) return;
  const int p = ops.order();
  const std::size_t size = ops.size(), S = size / 2;
  auto &nodes = let.tree.nodes;
  nodes.assign(total_nodes, Node{});
  let.multipole.assign(total_nodes * size, 0.0);
  let.multipole_only.assign(total_nodes, 0);
  let.truncated.assign(total_nodes, 0);
  let.tree.xs.resize(total_particles);
  let.tree.ys.resize(total_particles);
  let.tree.zs.resize(total_particles);
  let.q.resize(total_particles);
  let.ids.resize(total_particles);
  Node &root = nodes[0];
  root.radius = std::numeric_limits<double>::infinity();
  root.begin = 0;
  root.end = static_cast<std::uint32_t>(total_particles);
  root.child = 1;
  root.nchild = static_cast<std::int32_t>(roots);
  std::size_t slot = 1, base = 1 + roots, pbase = 0;
  for (int r = 0; r < static_cast<int>(recv.size()); ++r) {
    if (r == self || recv[r].empty()) continue;
    Reader rd{recv[r]};
    const auto nn = static_cast<std::size_t>(rd.get<std::int64_t>());
    const auto np = static_cast<std::size_t>(rd.get<std::int64_t>());
    if (nn == 0) continue;
    // the sender's node j: its root to this rank's slot, the others after the roots
    auto place = [&](std::int64_t j) { return j == 0 ? slot : base + static_cast<std::size_t>(j) - 1; };
    for (std::size_t j = 0; j < nn; ++j) {
      Node &A = nodes[place(j)];
      A.center.x = rd.get<double>();
      A.center.y = rd.get<double>();
      A.center.z = rd.get<double>();
      A.radius = rd.get<double>();
      const auto child = rd.get<std::int32_t>(), nchild = rd.get<std::int32_t>();
      const auto begin = rd.get<std::int32_t>(), end = rd.get<std::int32_t>(), flags = rd.get<std::int32_t>();
      A.child = nchild > 0 ? static_cast<std::int32_t>(place(child)) : -1;
      A.nchild = nchild;
      A.begin = static_cast<std::uint32_t>(pbase + begin);
      A.end = static_cast<std::uint32_t>(pbase + end);
      A.parent = -1;  // the roots' (no M2M into the virtual root); the children's below
      let.multipole_only[place(j)] = (flags & kMultipoleOnly) ? 1 : 0;
      let.truncated[place(j)] = (flags & kTruncated) ? 1 : 0;
    }
    for (std::size_t j = 0; j < nn; ++j) {
      const Node &A = nodes[place(j)];
      for (int c = 0; c < A.nchild; ++c) nodes[A.child + c].parent = static_cast<std::int32_t>(place(j));
    }
    for (std::size_t j = 0; j < nn; ++j) {
      if (!let.truncated[place(j)]) continue;
      double *M = let.multipole.data() + place(j) * size;
      for (std::size_t part = 0; part < 2; ++part)
        for (int k = 0; k <= p; ++k)
          for (int m = 0; m <= k; ++m) M[part * S + k * k + k + m] = rd.get<double>();
    }
    for (auto *v : {&let.tree.xs, &let.tree.ys, &let.tree.zs, &let.q})
      for (std::size_t k = 0; k < np; ++k) (*v)[pbase + k] = rd.get<double>();
    for (std::size_t k = 0; k < np; ++k) let.ids[pbase + k] = rd.get<std::int64_t>();
    ++slot;
    base += nn - 1;
    pbase += np;
  }
  // the other multipoles from the received particles and multipoles (eqs. (3.9), (3.10))
  upward_pass(let.tree, let.q.data(), ops, let.multipole, &let.truncated);
}

}  // namespace detail

}  // namespace gcfmm
