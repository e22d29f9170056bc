// GRANULAR-CHARGED FMM core library (gcfmm): adaptive octree (src/fmm/README.md, "Tree and
// traversal").
#include "gcfmm/tree.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace gcfmm {

namespace {
constexpr int kMaxDepth = 48;  // coincident points cannot be separated: stop splitting there
}

void Tree::build(std::size_t n, const double *x, const double *y, const double *z, int leaf) {
  if (n > 0xFFFFFFF0u) throw std::invalid_argument("gcfmm: too many particles for one tree");
  if (leaf < 1) throw std::invalid_argument("gcfmm: leaf size must be >= 1");
  nodes.clear();
  cubes.clear();
  leaves.clear();
  perm.resize(n);
  for (std::size_t i = 0; i < n; ++i) perm[i] = static_cast<std::uint32_t>(i);
  xs.assign(x, x + n);  // temporarily unsorted; rewritten below
  ys.assign(y, y + n);
  zs.assign(z, z + n);
  levels = 0;
  if (n == 0) return;

  double lo[3] = {xs[0], ys[0], zs[0]}, hi[3] = {xs[0], ys[0], zs[0]};
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(xs[i]) || !std::isfinite(ys[i]) || !std::isfinite(zs[i]))
      throw std::runtime_error("gcfmm: non-finite particle position");
    lo[0] = std::min(lo[0], xs[i]); hi[0] = std::max(hi[0], xs[i]);
    lo[1] = std::min(lo[1], ys[i]); hi[1] = std::max(hi[1], ys[i]);
    lo[2] = std::min(lo[2], zs[i]); hi[2] = std::max(hi[2], zs[i]);
  }
  Node root;
  Cube cube;
  cube.center = {0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])};
  cube.half = 0.5 * std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  cube.half = cube.half * (1.0 + 1e-12) + 1e-300;
  root.begin = 0;
  root.end = static_cast<std::uint32_t>(n);
  nodes.push_back(root);
  cubes.push_back(cube);
  std::vector<std::uint32_t> scratch(n);
  split(0, leaf, scratch);

  // sorted positions
  std::vector<double> tx(n), ty(n), tz(n);
  for (std::size_t k = 0; k < n; ++k) {
    tx[k] = x[perm[k]];
    ty[k] = y[perm[k]];
    tz[k] = z[perm[k]];
  }
  xs.swap(tx);
  ys.swap(ty);
  zs.swap(tz);

  // expansion centres (bounding-box centre of the particles) and radii; leaves in order
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    Node &nd = nodes[i];
    double a[3] = {xs[nd.begin], ys[nd.begin], zs[nd.begin]}, b[3] = {a[0], a[1], a[2]};
    for (std::uint32_t k = nd.begin; k < nd.end; ++k) {
      a[0] = std::min(a[0], xs[k]); b[0] = std::max(b[0], xs[k]);
      a[1] = std::min(a[1], ys[k]); b[1] = std::max(b[1], ys[k]);
      a[2] = std::min(a[2], zs[k]); b[2] = std::max(b[2], zs[k]);
    }
    nd.center = {0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), 0.5 * (a[2] + b[2])};
    double r2 = 0.0;
    for (std::uint32_t k = nd.begin; k < nd.end; ++k) {
      double dx = xs[k] - nd.center.x, dy = ys[k] - nd.center.y, dz = zs[k] - nd.center.z;
      r2 = std::max(r2, dx * dx + dy * dy + dz * dz);
    }
    nd.radius = std::sqrt(r2);
    levels = std::max(levels, nd.level + 1);
  }
  // leaves in particle order: depth-first walk
  std::vector<std::int32_t> stack{0};
  while (!stack.empty()) {
    std::int32_t i = stack.back();
    stack.pop_back();
    const Node &nd = nodes[i];
    if (nd.leaf()) {
      leaves.push_back(i);
    } else {
      for (int c = nd.nchild - 1; c >= 0; --c) stack.push_back(nd.child + c);
    }
  }
}

void Tree::split(std::int32_t ni, int leaf, std::vector<std::uint32_t> &scratch) {
  const Node nd = nodes[ni];
  const Cube cube = cubes[ni];
  if (nd.count() <= static_cast<std::uint32_t>(leaf) || nd.level >= kMaxDepth) return;
  // octant of every particle; xs/ys/zs are still in original order here
  std::uint32_t cnt[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  auto octant = [&](std::uint32_t p) {
    return (xs[p] >= cube.center.x ? 1 : 0) | (ys[p] >= cube.center.y ? 2 : 0) | (zs[p] >= cube.center.z ? 4 : 0);
  };
  for (std::uint32_t k = nd.begin; k < nd.end; ++k) ++cnt[octant(perm[k])];
  std::uint32_t off[8];
  std::uint32_t s = nd.begin;
  int nonempty = 0;
  for (int o = 0; o < 8; ++o) {
    off[o] = s;
    s += cnt[o];
    if (cnt[o]) ++nonempty;
  }
  for (std::uint32_t k = nd.begin; k < nd.end; ++k) scratch[off[octant(perm[k])]++] = perm[k];
  std::copy(scratch.begin() + nd.begin, scratch.begin() + nd.end, perm.begin() + nd.begin);

  const std::int32_t first = static_cast<std::int32_t>(nodes.size());
  std::uint32_t b = nd.begin;
  const double h = 0.5 * cube.half;
  for (int o = 0; o < 8; ++o) {
    if (!cnt[o]) continue;
    Node c;
    Cube cc;
    cc.half = h;
    cc.center = {cube.center.x + ((o & 1) ? h : -h), cube.center.y + ((o & 2) ? h : -h),
                 cube.center.z + ((o & 4) ? h : -h)};
    cubes.push_back(cc);
    c.begin = b;
    c.end = b + cnt[o];
    b = c.end;
    c.parent = ni;
    c.level = nd.level + 1;
    nodes.push_back(c);
  }
  nodes[ni].child = first;
  nodes[ni].nchild = nonempty;
  for (int c = 0; c < nonempty; ++c) split(first + c, leaf, scratch);
}

}  // namespace gcfmm
