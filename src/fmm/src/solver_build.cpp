// GRANULAR-CHARGED FMM core library (gcfmm): the build() phases of the solver
// (src/solver_impl.hpp).
#include "solver_impl.hpp"

namespace gcfmm {

using namespace detail;

// Positions of a periodic system are wrapped into the primary cell first; all positions are
// then expressed in the length unit h (the cell's for Periodic2D, the particles' extent in
// free space), so the tree, the lists and the expansions see coordinates of order 1.
void Solver::Impl::build_tree(const double *x, const double *y, const double *z) {
  if (periodic()) {
    h = length_unit(std::max(lx, ly));
  } else {
    double extent = 0.0;
    if (n > 0)
      for (const double *c : {x, y, z}) {
        const auto [lo, hi] = std::minmax_element(c, c + n);
        extent = std::max(extent, *hi - *lo);
      }
    h = length_unit(extent);
  }
  inv_h = 1.0 / h;
  sx0 = x0 * inv_h;
  sy0 = y0 * inv_h;
  slx = lx * inv_h;
  sly = ly * inv_h;
  scaled_x.resize(n);
  scaled_y.resize(n);
  scaled_z.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    scaled_x[i] = (periodic() ? wrap(x[i], x0, lx) : x[i]) * inv_h;
    scaled_y[i] = (periodic() ? wrap(y[i], y0, ly) : y[i]) * inv_h;
    scaled_z[i] = z[i] * inv_h;
  }
  tree.build(n, scaled_x.data(), scaled_y.data(), scaled_z.data(), res.leaf);
  zmin = zmax = 0.0;
  if (n > 0) {
    const auto [lo, hi] = std::minmax_element(tree.zs.begin(), tree.zs.end());
    zmin = *lo;
    zmax = *hi;
  }
}

// The source tree shifted by every image shift of the near block (doc/theory.md, eq. (4.1)).
void Solver::Impl::build_interaction_lists() {
  std::vector<Vec3> shifts;
  if (periodic()) {
    const int k = opts.images;
    for (int nx = -k; nx <= k; ++nx)
      for (int ny = -k; ny <= k; ++ny) shifts.push_back({nx * slx, ny * sly, 0.0});
  } else {
    shifts.push_back({0.0, 0.0, 0.0});
  }
  build_lists(tree, shifts, res.theta, m2l_cost(res.order, ops->simd_path()), lists);
}

void Solver::Impl::allocate_storage() {
  const std::size_t nn = tree.nodes.size();
  multipole.assign(nn * expansion_size(), 0.0);
  local.assign(nn * expansion_size(), 0.0);
  has_local.assign(nn, 0);
  std::size_t maxm2l = 0;
  for (std::size_t i = 0; i < nn; ++i)
    maxm2l = std::max<std::size_t>(maxm2l, lists.m2l_offset[i + 1] - lists.m2l_offset[i]);
  batch_m.assign(maxm2l, nullptr);
  batch_r.assign(maxm2l, Vec3{});
  for (auto *v : {&sorted_q, &sorted_pot, &sorted_ex, &sorted_ey, &sorted_ez, &sorted_average_pot}) v->assign(n, 0.0);
}

// Estimated cost per particle (eq. (3.16)), summed over leaves: the work partitions cut this
// prefix sum into equal parts.
void Solver::Impl::estimate_partition_costs() {
  const int p = res.order;
  std::vector<double> cost(n, l2p_cost(p));
  const auto &nodes = tree.nodes;
  for (const auto &e : lists.p2p) {
    const Node &A = nodes[e.target];
    const double c = nodes[e.source].count();
    for (std::uint32_t k = A.begin; k < A.end; ++k) cost[k] += c;
  }
  for (const auto &e : lists.m2l) {
    const Node &A = nodes[e.target];
    const double c = m2l_cost(p, ops->simd_path()) / A.count();
    for (std::uint32_t k = A.begin; k < A.end; ++k) cost[k] += c;
  }
  leaf_prefix.assign(tree.leaves.size() + 1, 0.0);
  for (std::size_t l = 0; l < tree.leaves.size(); ++l) {
    const Node &A = nodes[tree.leaves[l]];
    double c = 0.0;
    for (std::uint32_t k = A.begin; k < A.end; ++k) c += cost[k];
    leaf_prefix[l + 1] = leaf_prefix[l] + c;
  }
}

// Pairs closer than the coincidence radius (kCoincidenceRadius h, solver.hpp), periodic
// images included. Such a pair lies in one leaf or in a P2P list entry (an M2L pair of
// nodes at that distance would need both nodes smaller than the radius and holding more
// particles than the P2P threshold (3.16), i.e. coincident pairs inside them as well), so
// the P2P entries whose bounding boxes come that close are searched pair by pair.
void Solver::Impl::find_coincident_pairs() {
  coincident.clear();
  const auto &xs = tree.xs, &ys = tree.ys, &zs = tree.zs;
  const double r2 = kCoincidenceRadius * kCoincidenceRadius;
  auto gap = [](double alo, double ahi, double blo, double bhi) {
    return std::max({alo - bhi, blo - ahi, 0.0});
  };
  for (const Interaction &e : lists.p2p) {
    const Bounds &A = tree.bounds[e.target], &B = tree.bounds[e.source];
    const Vec3 &s = lists.shifts[e.shift];
    const double gx = gap(A.lo.x, A.hi.x, B.lo.x + s.x, B.hi.x + s.x);
    const double gy = gap(A.lo.y, A.hi.y, B.lo.y + s.y, B.hi.y + s.y);
    const double gz = gap(A.lo.z, A.hi.z, B.lo.z + s.z, B.hi.z + s.z);
    if (gx * gx + gy * gy + gz * gz > r2) continue;
    const Node &NA = tree.nodes[e.target], &NB = tree.nodes[e.source];
    const bool same = e.target == e.source && s.x == 0.0 && s.y == 0.0;
    for (std::uint32_t a = NA.begin; a < NA.end; ++a)
      for (std::uint32_t b = same ? a + 1 : NB.begin; b < NB.end; ++b) {
        const double dx = xs[a] - xs[b] - s.x, dy = ys[a] - ys[b] - s.y, dz = zs[a] - zs[b];
        if (dx * dx + dy * dy + dz * dz <= r2) coincident.emplace_back(std::min(a, b), std::max(a, b));
      }
  }
  // each pair once (a pair in two entries, A-B and B-A, is found twice)
  std::sort(coincident.begin(), coincident.end());
  coincident.erase(std::unique(coincident.begin(), coincident.end()), coincident.end());
}

void Solver::Impl::setup_far_field() {
  if (!periodic() || opts.farfield != FarField::Exact) return;
  // the lattice sum accepts accuracies down to 1e-8 (its far field is smooth and tiny anyway)
  const double facc = std::max(opts.accuracy, 1e-8);
  if (far.needs_setup(sx0, sy0, slx, sly, zmin, zmax, opts.images, facc))
    far.setup(sx0, sy0, slx, sly, zmin, zmax, opts.images, facc);
  stats.estimated_error += far.estimated_error();
}

}  // namespace gcfmm
