// Adaptive octree of gcfmm: partition of the particles into leaves and adaptivity.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "gcfmm/tree.hpp"
#include "fmm_test_util.hpp"

using namespace gcfmm;

namespace {

// Structural invariants: perm is a permutation, leaves tile [0, n) in order, children tile
// their parent, every particle lies in its node's cube and within the node radius.
void check_tree(const Tree &t, std::size_t n, const double *x, const double *y, const double *z, int leaf) {
  ASSERT_EQ(t.perm.size(), n);
  std::vector<int> seen(n, 0);
  for (auto i : t.perm) ++seen[i];
  for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(seen[i], 1) << "particle " << i;
  // every particle in exactly one leaf: leaves are contiguous, disjoint, cover [0, n)
  std::vector<int> inleaf(n, 0);
  std::uint32_t next = 0;
  for (auto li : t.leaves) {
    const Node &L = t.nodes[li];
    EXPECT_TRUE(L.leaf());
    EXPECT_EQ(L.begin, next);
    next = L.end;
    EXPECT_GT(L.count(), 0u);
    EXPECT_LE(L.count(), static_cast<std::uint32_t>(leaf));
    for (std::uint32_t k = L.begin; k < L.end; ++k) ++inleaf[k];
  }
  EXPECT_EQ(next, n);
  for (std::size_t k = 0; k < n; ++k) EXPECT_EQ(inleaf[k], 1);
  std::size_t nleaves = 0;
  for (std::size_t i = 0; i < t.nodes.size(); ++i) {
    const Node &A = t.nodes[i];
    if (A.leaf()) {
      ++nleaves;
      continue;
    }
    std::uint32_t b = A.begin;
    for (int c = 0; c < A.nchild; ++c) {
      const Node &C = t.nodes[A.child + c];
      EXPECT_EQ(C.parent, static_cast<std::int32_t>(i));
      EXPECT_GT(A.child + c, static_cast<std::int32_t>(i));  // children after parents
      EXPECT_EQ(C.begin, b);
      b = C.end;
      EXPECT_EQ(C.level, A.level + 1);
    }
    EXPECT_EQ(b, A.end);
  }
  EXPECT_EQ(nleaves, t.leaves.size());
  for (const Node &A : t.nodes)
    for (std::uint32_t k = A.begin; k < A.end; ++k) {
      const std::size_t i = t.perm[k];
      EXPECT_EQ(t.xs[k], x[i]);
      EXPECT_EQ(t.zs[k], z[i]);
      const double dx = x[i] - A.center.x, dy = y[i] - A.center.y, dz = z[i] - A.center.z;
      EXPECT_LE(std::sqrt(dx * dx + dy * dy + dz * dz), A.radius * (1.0 + 1e-12) + 1e-300);
    }
}

}  // namespace

TEST(Tree, EveryParticleInExactlyOneLeaf) {
  auto p = gcfmm_test::random_cube(3000, 11);
  for (int leaf : {1, 7, 32, 5000}) {
    Tree t;
    t.build(p.size(), p.x.data(), p.y.data(), p.z.data(), leaf);
    check_tree(t, p.size(), p.x.data(), p.y.data(), p.z.data(), leaf);
    if (leaf == 5000) {
      EXPECT_EQ(t.nodes.size(), 1u);
    }
  }
}

TEST(Tree, DepositionBedAndSparseColumnAreAdaptive) {
  auto p = gcfmm_test::deposition(20000, 3);
  const int leaf = 32;
  Tree t;
  t.build(p.size(), p.x.data(), p.y.data(), p.z.data(), leaf);
  check_tree(t, p.size(), p.x.data(), p.y.data(), p.z.data(), leaf);
  // adaptive: O(N / leaf) nodes; a uniform octree down to the bed's depth over the whole
  // 160-high cube would need ~8^depth nodes instead
  EXPECT_LT(t.nodes.size(), 8u * p.size() / 10u);
  // leaves in the sparse region are larger (shallower) than leaves in the dense bed
  const double lx = gcfmm_test::deposition_width(p.size());
  const double zbed = 1.0 + 18000 * (4.0 / 3.0 * M_PI) / (0.3 * lx * lx);
  int dmax_bed = 0, dmax_top = 0;
  double avg_bed = 0, avg_top = 0;
  int nbed = 0, ntop = 0;
  for (auto li : t.leaves) {
    const Node &L = t.nodes[li];
    if (L.center.z < zbed) {
      dmax_bed = std::max(dmax_bed, L.level);
      avg_bed += L.level;
      ++nbed;
    } else if (L.center.z > zbed + 10) {
      dmax_top = std::max(dmax_top, L.level);
      avg_top += L.level;
      ++ntop;
    }
  }
  ASSERT_GT(nbed, 0);
  ASSERT_GT(ntop, 0);
  EXPECT_LT(avg_top / ntop, avg_bed / nbed);
  EXPECT_LE(dmax_top, dmax_bed);
  // the sparse particles do not multiply the node count: their leaves hold few nodes each
  EXPECT_LT(ntop, 2000 / 2);
}

TEST(Tree, FarParticleAddsOnlyAFewNodes) {
  auto p = gcfmm_test::deposition(4000, 5);
  Tree t0;
  t0.build(p.size(), p.x.data(), p.y.data(), p.z.data(), 32);
  p.x.push_back(10.0);
  p.y.push_back(10.0);
  p.z.push_back(1.0e6);  // a particle very far above the bed
  p.q.push_back(1.0);
  Tree t1;
  t1.build(p.size(), p.x.data(), p.y.data(), p.z.data(), 32);
  check_tree(t1, p.size(), p.x.data(), p.y.data(), p.z.data(), 32);
  // the bed now sits deep in a huge root cube: only the chain of nodes down to it is new
  // (one node per extra level plus the far particle's own leaves)
  EXPECT_LT(t1.nodes.size(), t0.nodes.size() + 3 * static_cast<std::size_t>(t1.levels));
}

TEST(Tree, CoincidentPointsTerminate) {
  std::vector<double> x(50, 0.5), y(50, 0.5), z(50, 0.5);
  x[0] = 0.0;
  Tree t;
  t.build(x.size(), x.data(), y.data(), z.data(), 4);
  // 49 coincident points cannot be split below 4 per leaf: the depth limit stops the split
  std::size_t total = 0;
  for (auto li : t.leaves) total += t.nodes[li].count();
  EXPECT_EQ(total, x.size());
  EXPECT_LT(t.levels, 64);
}

TEST(Tree, EmptyAndSingle) {
  Tree t;
  t.build(0, nullptr, nullptr, nullptr, 8);
  EXPECT_TRUE(t.nodes.empty());
  EXPECT_TRUE(t.leaves.empty());
  double x = 1, y = 2, z = 3;
  t.build(1, &x, &y, &z, 8);
  ASSERT_EQ(t.nodes.size(), 1u);
  EXPECT_EQ(t.leaves.size(), 1u);
  EXPECT_EQ(t.nodes[0].radius, 0.0);
}
