// GRANULAR-CHARGED FMM core library (gcfmm): the evaluate() phases of the solver
// (src/solver_impl.hpp).
#include "solver_impl.hpp"

namespace gcfmm {

using namespace detail;

void Solver::Impl::sort_charges(const double *q) {
  const auto &perm = tree.perm;
  for (std::size_t k = 0; k < n; ++k) sorted_q[k] = q[perm[k]];
  for (const auto &c : coincident)
    if (sorted_q[c.first] != 0.0 || sorted_q[c.second] != 0.0) {
      const std::size_t i = std::min(perm[c.first], perm[c.second]), j = std::max(perm[c.first], perm[c.second]);
      throw CoincidentParticles(i, j, "gcfmm: particles " + std::to_string(i) + " and " + std::to_string(j) +
                                          " are at the same position (closer than " +
                                          std::to_string(kCoincidenceRadius * h) + ")");
    }
}

// Upward pass: P2M at leaves (eq. (3.9)), M2M to parents (eq. (3.10)) (detail::upward_pass).
// Done for all nodes by every part: splitting the P2M would need the leaf multipoles summed
// over the parts, and at N = 200,000 that sum (~all nodes x expansion size doubles) cost more
// than the P2M it saved (doc/benchmarks.md, "2 MPI ranks").
void Solver::Impl::upward() { upward_pass(tree, sorted_q.data(), *ops, multipole); }

// M2L (eq. (3.11)) into the local expansions of the nodes that hold targets of this part.
void Solver::Impl::m2l(const TargetRange &t) {
  const auto &nodes = tree.nodes;
  std::fill(has_local.begin(), has_local.end(), 0);
  for_target_nodes(t, [&](std::size_t i, const Node &A) {
    const std::uint32_t e0 = lists.m2l_offset[i], e1 = lists.m2l_offset[i + 1];
    double *Li = local_of(i);
    std::fill(Li, Li + expansion_size(), 0.0);
    if (e1 == e0) return;
    for (std::uint32_t e = e0; e < e1; ++e) {
      const Interaction &it = lists.m2l[e];
      const Node &B = nodes[it.source];
      batch_m[e - e0] = multipole_of(it.source);
      batch_r[e - e0] = A.center - (B.center + lists.shifts[it.shift]);
    }
    ops->m2l_batch(e1 - e0, batch_m.data(), batch_r.data(), Li);
    has_local[i] = 1;
  });
}

// P2P (eq. (3.1)): per target, contributions in list order, so independent of the partition.
void Solver::Impl::p2p(const TargetRange &t) {
  const auto &nodes = tree.nodes;
  const auto &xs = tree.xs, &ys = tree.ys, &zs = tree.zs;
  for_target_nodes(t, [&](std::size_t i, const Node &A) {
    const std::size_t a = t.first(A), b = t.last(A);
    for (std::uint32_t e = lists.p2p_offset[i]; e < lists.p2p_offset[i + 1]; ++e) {
      const Interaction &it = lists.p2p[e];
      const Node &B = nodes[it.source];
      const Vec3 &sh = lists.shifts[it.shift];
      gcfmm::p2p(b - a, xs.data() + a, ys.data() + a, zs.data() + a, B.count(), xs.data() + B.begin,
                 ys.data() + B.begin, zs.data() + B.begin, sorted_q.data() + B.begin, sh.x, sh.y, sh.z,
                 sorted_pot.data() + a, sorted_ex.data() + a, sorted_ey.data() + a, sorted_ez.data() + a,
                 kCoincidenceRadius * kCoincidenceRadius);
    }
  });
}

// Downward pass: L2L from the parent (eq. (3.12)), L2P at leaves (eq. (3.13)).
void Solver::Impl::downward(const TargetRange &t) {
  const auto &nodes = tree.nodes;
  const auto &xs = tree.xs, &ys = tree.ys, &zs = tree.zs;
  for_target_nodes(t, [&](std::size_t i, const Node &A) {
    double *Li = local_of(i);
    if (A.parent >= 0 && has_local[A.parent]) {
      ops->l2l(local_of(A.parent), A.center - nodes[A.parent].center, Li);
      has_local[i] = 1;
    }
    if (!has_local[i]) return;
    ops->symmetrize(Li);
    if (A.leaf()) {
      const std::size_t a = t.first(A), b = t.last(A);
      ops->l2p_batch(Li, A.center, b - a, xs.data() + a, ys.data() + a, zs.data() + a, sorted_pot.data() + a,
                     sorted_ex.data() + a, sorted_ey.data() + a, sorted_ez.data() + a);
    }
  });
}

// The image cells beyond the near block (doc/theory.md, eq. (4.1)): exact (eq. (4.6)) or the
// average field (eq. (4.7)).
void Solver::Impl::far_field(const TargetRange &t, int part, int nparts, const PartSum &sum) {
  if (!periodic()) return;
  const auto &xs = tree.xs, &ys = tree.ys, &zs = tree.zs;
  if (opts.farfield == FarField::Exact) {
    far.evaluate(n, xs.data(), ys.data(), zs.data(), sorted_q.data(), t.begin, t.end, sorted_pot.data(),
                 sorted_ex.data(), sorted_ey.data(), sorted_ez.data(), part, nparts, sum);
  } else if (opts.farfield == FarField::Average) {
    double blo, bhi;
    if (!average_bed(opts, inv_h, n, zs.data(), sorted_q.data(), slx, sly, blo, bhi)) return;
    // the potential part apart, for energy_potential() (eq. (4.10))
    std::fill(sorted_average_pot.begin() + t.begin, sorted_average_pot.begin() + t.end, 0.0);
    average_far_field(n, xs.data(), ys.data(), zs.data(), sorted_q.data(), sx0, sy0, slx, sly, opts.images, blo, bhi,
                      t.begin, t.end, sorted_average_pot.data(), sorted_ex.data(), sorted_ey.data(),
                      sorted_ez.data());
    for (std::size_t k = t.begin; k < t.end; ++k) sorted_pot[k] += sorted_average_pot[k];
  }
}

}  // namespace gcfmm
