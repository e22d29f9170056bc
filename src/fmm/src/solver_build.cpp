// GRANULAR-CHARGED FMM core library (gcfmm): the build() phases of the solver
// (src/solver_impl.hpp).
#include "solver_impl.hpp"

#include <array>

namespace gcfmm {

using namespace detail;

void SolverCore::configure(const Options &o) {
  o.validate();
  opts = o;
  res = resolve(o);
  opts.order = res.order;
  opts.theta = res.theta;
  opts.leaf = res.leaf;
  ops.reset(new Operators(res.order));
  p2p_kernel = p2p_kernel_within(p2p_term_tolerance(o), ops->simd_path());
  stats.order = res.order;
  stats.theta = res.theta;
  stats.leaf = res.leaf;
  stats.estimated_error = res.estimated_error;
}

void SolverCore::set_box(double xlo, double ylo, double cell_x, double cell_y) {
  if (opts.boundary != Boundary::Periodic2D)
    throw std::invalid_argument("gcfmm: set_box() is only for Boundary::Periodic2D");
  if (!(std::isfinite(xlo) && std::isfinite(ylo) && std::isfinite(cell_x) && std::isfinite(cell_y)) ||
      !(cell_x > 0.0) || !(cell_y > 0.0))
    throw std::invalid_argument("gcfmm: set_box() needs finite xlo, ylo and lx, ly > 0");
  x0 = xlo;
  y0 = ylo;
  lx = cell_x;
  ly = cell_y;
  box_set = true;
  built = false;
}

void SolverCore::set_z_range(double zlo, double zhi) {
  if (opts.boundary != Boundary::Periodic2D)
    throw std::invalid_argument("gcfmm: set_z_range() is only for Boundary::Periodic2D");
  if (!(std::isfinite(zlo) && std::isfinite(zhi)) || !(zhi >= zlo))
    throw std::invalid_argument("gcfmm: set_z_range() needs finite zlo <= zhi");
  zhint_lo = zlo;
  zhint_hi = zhi;
}

// Positions of a periodic system are wrapped into the primary cell first; all positions are
// then expressed in the length unit h (the cell's for Periodic2D, the particles' extent in
// free space), so the tree, the lists and the expansions see coordinates of order 1.
void SolverCore::build_tree(const double *x, const double *y, const double *z) {
  choose_length_unit(x, y, z);
  build_scaled_tree(x, y, z);
}

void SolverCore::choose_length_unit(const double *x, const double *y, const double *z) {
  double extent = 0.0;
  if (!periodic() && n > 0)
    for (const double *c : {x, y, z}) {
      const auto [lo, hi] = std::minmax_element(c, c + n);
      extent = std::max(extent, *hi - *lo);
    }
  set_length_unit(periodic() ? length_unit(std::max(lx, ly)) : length_unit(extent));
}

void SolverCore::set_length_unit(double unit) {
  h = unit;
  inv_h = 1.0 / h;
  sx0 = x0 * inv_h;
  sy0 = y0 * inv_h;
  slx = lx * inv_h;
  sly = ly * inv_h;
}

void SolverCore::build_scaled_tree(const double *x, const double *y, const double *z) {
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

// The phases of build() after the tree but the far field, with the stats they determine.
void SolverCore::build_after_tree() {
  build_interaction_lists();
  allocate_storage();
  estimate_partition_costs();
  find_coincident_pairs();
  stats.levels = tree.levels;
  stats.nodes = tree.nodes.size();
  stats.leaves = tree.leaves.size();
  stats.m2l_count = lists.m2l.size();
  stats.p2p_pairs = lists.p2p_pairs;
  stats.estimated_error = res.estimated_error;
}

// The source tree shifted by every image shift of the near block (doc/theory.md, eq. (4.1)).
void SolverCore::build_interaction_lists() {
  build_lists(tree, image_shifts(periodic(), opts.images, slx, sly), res.theta, m2l_cost(res.order, ops->simd_path()),
              lists);
}

void SolverCore::allocate_storage() {
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
void SolverCore::estimate_partition_costs() {
  // cost per particle of each node's own list entries, then summed down the tree (a
  // particle pays for the entries of every node that contains it; parents come first)
  const int p = res.order;
  const double m2l = m2l_cost(p, ops->simd_path());
  const auto &nodes = tree.nodes;
  std::vector<double> own(nodes.size(), 0.0);
  for (const auto &e : lists.p2p) own[e.target] += nodes[e.source].count();
  for (const auto &e : lists.m2l) own[e.target] += m2l / nodes[e.target].count();
  for (std::size_t i = 0; i < nodes.size(); ++i)
    if (nodes[i].parent >= 0) own[i] += own[nodes[i].parent];
  leaf_target_cost.resize(tree.leaves.size());
  for (std::size_t l = 0; l < tree.leaves.size(); ++l) leaf_target_cost[l] = l2p_cost(p) + own[tree.leaves[l]];
  weigh_leaves(n);
}

// the cost of a leaf is that of its targets: with sources that are not targets (an
// electrode's images) the work partitions then split the targets' work, not the particles
void SolverCore::weigh_leaves(std::size_t targets) {
  const auto &nodes = tree.nodes;
  leaf_prefix.assign(tree.leaves.size() + 1, 0.0);
  for (std::size_t l = 0; l < tree.leaves.size(); ++l) {
    const Node &leaf = nodes[tree.leaves[l]];
    std::size_t count = leaf.count();
    if (targets < n) {
      count = 0;
      for (std::uint32_t k = leaf.begin; k < leaf.end; ++k) count += tree.perm[k] < targets;
    }
    leaf_prefix[l + 1] = leaf_prefix[l] + double(count) * leaf_target_cost[l];
  }
  weighed_targets = std::min(targets, n);
}

// Pairs closer than r = kCoincidenceRadius (units of h, solver.hpp), periodic images
// included. Within a leaf every pair is tested. Two particles of different leaves lie in
// disjoint leaf cubes, and a particle and another's periodic image lie on both sides of the
// cell boundary, so both particles of such a pair are within r of a face of their leaf cube
// or of the cell boundary. Only those boundary particles (normally none) are compared, through
// 8 staggered grids of cell 4 r (a pair closer than r shares a cell in at least one of them),
// so that lattice-aligned inputs with many particles on cube faces stay O(k log k).
// (An M2L pair of nodes that close would need nodes smaller than r holding more particles than
// the P2P threshold (3.16): coincident pairs inside them, found here, as well.)
void SolverCore::find_coincident_pairs() {
  coincident.clear();
  const auto &xs = tree.xs, &ys = tree.ys, &zs = tree.zs;
  const double r = kCoincidenceRadius, r2 = r * r;
  auto add = [&](std::uint32_t a, std::uint32_t b) { coincident.emplace_back(std::min(a, b), std::max(a, b)); };
  struct Point {
    double x, y, z;
    std::uint32_t k;
  };
  std::vector<Point> boundary;
  for (auto li : tree.leaves) {
    const Node &A = tree.nodes[li];
    const Cube &cube = tree.cubes[li];
    for (std::uint32_t a = A.begin; a < A.end; ++a) {
      auto d2 = [&](std::uint32_t b) {
        const double dx = xs[a] - xs[b], dy = ys[a] - ys[b], dz = zs[a] - zs[b];
        return dx * dx + dy * dy + dz * dz;
      };
      double dmin = 2.0 * r2;  // a vectorisable scan first; the pairs only where one is close
#pragma omp simd reduction(min : dmin)
      for (std::uint32_t b = a + 1; b < A.end; ++b) dmin = std::min(dmin, d2(b));
      if (dmin <= r2)
        for (std::uint32_t b = a + 1; b < A.end; ++b)
          if (d2(b) <= r2) add(a, b);
      const double face = std::min({cube.half - std::abs(xs[a] - cube.center.x), cube.half - std::abs(ys[a] - cube.center.y),
                                    cube.half - std::abs(zs[a] - cube.center.z)});
      const bool wall = periodic() && std::min({xs[a] - sx0, sx0 + slx - xs[a], ys[a] - sy0, sy0 + sly - ys[a]}) <= r;
      if (face > r && !wall) continue;
      for (const Vec3 &s : lists.shifts) {  // the particle and, at the cell boundary, its images
        const Point q{xs[a] + s.x, ys[a] + s.y, zs[a], a};
        if (s.x == 0.0 && s.y == 0.0) boundary.push_back(q);
        else if (q.x >= sx0 - r && q.x <= sx0 + slx + r && q.y >= sy0 - r && q.y <= sy0 + sly + r) boundary.push_back(q);
      }
    }
  }
  if (boundary.size() > 1) {
    const double cell = 4.0 * r;
    std::vector<std::pair<std::array<double, 3>, std::uint32_t>> keys(boundary.size());
    for (int g = 0; g < 8; ++g) {
      const double ox = (g & 1) ? 2.0 * r : 0.0, oy = (g & 2) ? 2.0 * r : 0.0, oz = (g & 4) ? 2.0 * r : 0.0;
      for (std::size_t i = 0; i < boundary.size(); ++i) {
        const Point &q = boundary[i];
        keys[i] = {{std::floor((q.x + ox) / cell), std::floor((q.y + oy) / cell), std::floor((q.z + oz) / cell)},
                   static_cast<std::uint32_t>(i)};
      }
      std::sort(keys.begin(), keys.end());
      for (std::size_t i = 0; i < keys.size(); ++i)
        for (std::size_t j = i + 1; j < keys.size() && keys[j].first == keys[i].first; ++j) {
          const Point &u = boundary[keys[i].second], &v = boundary[keys[j].second];
          const double dx = u.x - v.x, dy = u.y - v.y, dz = u.z - v.z;
          if (u.k != v.k && dx * dx + dy * dy + dz * dz <= r2) add(u.k, v.k);
        }
    }
  }
  // each pair once (found in several grids, or as a particle and as an image)
  std::sort(coincident.begin(), coincident.end());
  coincident.erase(std::unique(coincident.begin(), coincident.end()), coincident.end());
}

void SolverCore::setup_far_field() {
  if (!periodic() || opts.farfield != FarField::Exact) return;
  const double facc = far_field_accuracy(opts);
  double lo = zmin, hi = zmax;
  if (!std::isnan(zhint_lo)) {
    lo = std::min(lo, zhint_lo * inv_h);
    hi = std::max(hi, zhint_hi * inv_h);
  }
  if (far.needs_setup(sx0, sy0, slx, sly, lo, hi, opts.images, facc))
    far.setup(sx0, sy0, slx, sly, lo, hi, opts.images, facc);
  stats.estimated_error += far.estimated_error();
}

}  // namespace gcfmm
