// GRANULAR-CHARGED FMM core library (gcfmm): dual-tree traversal.
#include "gcfmm/interaction_lists.hpp"

#include <cmath>
#include <utility>

namespace gcfmm {

void build_lists(const Tree &tree, const std::vector<Vec3> &shifts, double theta, double pair_limit,
                 InteractionLists &L) {
  build_lists(tree, tree, shifts, theta, pair_limit, L);
}

void build_lists(const Tree &targets, const Tree &sources, const std::vector<Vec3> &shifts, double theta,
                 double pair_limit, InteractionLists &L, const std::vector<char> *multipole_only) {
  L.shifts = shifts;
  L.m2l.clear();
  L.p2p.clear();
  L.m2p.clear();
  L.p2p_pairs = 0;
  const std::size_t nn = targets.nodes.size();
  L.m2l_offset.assign(nn + 1, 0);
  L.p2p_offset.assign(nn + 1, 0);
  L.m2p_offset.assign(nn + 1, 0);
  if (nn == 0 || sources.nodes.empty()) return;
  const auto &tnodes = targets.nodes, &snodes = sources.nodes;
  const double th2 = theta * theta;
  std::vector<std::pair<std::int32_t, std::int32_t>> stack;
  stack.reserve(1024);
  for (std::size_t s = 0; s < shifts.size(); ++s) {
    const Vec3 sh = shifts[s];
    const auto si = static_cast<std::int32_t>(s);
    stack.clear();
    stack.emplace_back(0, 0);
    while (!stack.empty()) {
      const auto [a, b] = stack.back();
      stack.pop_back();
      const Node &A = tnodes[a];
      const Node &B = snodes[b];
      const double dx = A.center.x - B.center.x - sh.x, dy = A.center.y - B.center.y - sh.y,
                   dz = A.center.z - B.center.z - sh.z;
      const double d2 = dx * dx + dy * dy + dz * dz;
      const double rs = A.radius + B.radius;
      const double pairs = double(A.count()) * double(B.count());
      // a multipole-only source lacks (some of) its particles: never P2P
      const bool truncated = multipole_only && (*multipole_only)[b];
      if (rs * rs < th2 * d2) {
        if (pairs <= pair_limit && !truncated) {
          L.p2p.push_back({a, b, si});
          L.p2p_pairs += static_cast<std::size_t>(pairs);
        } else {
          L.m2l.push_back({a, b, si});
        }
      } else if (truncated && A.leaf() && B.leaf()) {
        L.m2p.push_back({a, b, si});
      } else if (A.leaf() && B.leaf()) {
        L.p2p.push_back({a, b, si});
        L.p2p_pairs += static_cast<std::size_t>(pairs);
      } else if (B.leaf() || (!A.leaf() && A.radius >= B.radius)) {
        for (int c = A.nchild - 1; c >= 0; --c) stack.emplace_back(A.child + c, b);
      } else {
        for (int c = B.nchild - 1; c >= 0; --c) stack.emplace_back(a, B.child + c);
      }
    }
  }
  // stable counting sort by target node (keeps the traversal order within a target)
  auto sort_by_target = [nn](std::vector<Interaction> &v, std::vector<std::uint32_t> &off) {
    for (const auto &e : v) ++off[e.target + 1];
    for (std::size_t i = 0; i < nn; ++i) off[i + 1] += off[i];
    std::vector<Interaction> out(v.size());
    std::vector<std::uint32_t> pos(off.begin(), off.end() - 1);
    for (const auto &e : v) out[pos[e.target]++] = e;
    v.swap(out);
  };
  sort_by_target(L.m2l, L.m2l_offset);
  sort_by_target(L.p2p, L.p2p_offset);
  sort_by_target(L.m2p, L.m2p_offset);
}

}  // namespace gcfmm
