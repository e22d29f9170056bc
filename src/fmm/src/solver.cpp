// GRANULAR-CHARGED FMM core library (gcfmm): the solver driver.
#include "gcfmm/solver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "gcfmm/expansions.hpp"
#include "gcfmm/interaction_lists.hpp"
#include "gcfmm/kernels.hpp"
#include "gcfmm/tree.hpp"

#if __has_include("gcfmm/lattice_sum.hpp")
#include "gcfmm/lattice_sum.hpp"
#define GCFMM_HAVE_LATTICE_SUM 1
#else
#define GCFMM_HAVE_LATTICE_SUM 0
#endif
#if __has_include("gcfmm/average_field.hpp")
#include "gcfmm/average_field.hpp"
#define GCFMM_HAVE_AVERAGE_FIELD 1
#else
#define GCFMM_HAVE_AVERAGE_FIELD 0
#endif

namespace gcfmm {

namespace {
using Clock = std::chrono::steady_clock;
double seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

// Cost model (in units of one P2P particle pair) used to route cheap accepted pairs to P2P
// and to balance the work partitions. Measured here: one M2L of order p costs about as much
// as 0.8 (p+1)^3 P2P pairs (AVX-512 P2P, batched M2L), one L2P about (p+1)^2 / 4.
double m2l_cost(int p) { return 0.8 * (p + 1.0) * (p + 1.0) * (p + 1.0); }
double l2p_cost(int p) { return 0.25 * (p + 1.0) * (p + 1.0); }
}  // namespace

struct Solver::Impl {
  Options opts;
  Resolved res;
  Stats stats;
  bool box_set = false;
  double x0 = 0.0, y0 = 0.0, lx = 0.0, ly = 0.0;
  bool built = false;
  std::size_t n = 0;

  Tree tree;
  InteractionLists lists;
  std::unique_ptr<Operators> ops;
  std::vector<double> wx, wy;                 // wrapped input positions (original order)
  std::vector<double> M, L;                   // expansions, ops->size() doubles per node
  std::vector<char> has_local;                // node has a nonzero local expansion
  std::vector<double> qs, ps, exs, eys, ezs;  // sorted charges and results
  std::vector<const double *> batch_m;       // M2L batch of one target node: source multipoles
  std::vector<Vec3> batch_r;                  // and translation vectors
  std::vector<double> leaf_prefix;            // cumulative estimated cost over leaves
  std::vector<std::pair<std::uint32_t, std::uint32_t>> coincident;  // sorted indices
  double zmin = 0.0, zmax = 0.0;
#if GCFMM_HAVE_LATTICE_SUM
  PeriodicFarField far;
#endif

  bool periodic() const { return opts.boundary == Boundary::Periodic2D; }

  void range_of(int part, int nparts, std::size_t &first, std::size_t &last) const {
    const std::size_t nl = tree.leaves.size();
    auto bound = [&](int k) -> std::size_t {
      if (k <= 0) return 0;
      if (k >= nparts) return nl;
      const double target = leaf_prefix.back() * double(k) / double(nparts);
      auto it = std::lower_bound(leaf_prefix.begin(), leaf_prefix.end(), target);
      return std::min<std::size_t>(static_cast<std::size_t>(it - leaf_prefix.begin()), nl);
    };
    auto start = [&](std::size_t b) -> std::size_t {
      return b >= nl ? n : tree.nodes[tree.leaves[b]].begin;
    };
    first = start(bound(part));
    last = start(bound(part + 1));
    if (last < first) last = first;
  }
};

Solver::Solver(const Options &opts) : impl_(new Impl) {
  opts.validate();
  impl_->opts = opts;
  impl_->res = resolve(opts);
  impl_->opts.order = impl_->res.order;
  impl_->opts.theta = impl_->res.theta;
  impl_->opts.leaf = impl_->res.leaf;
  impl_->ops.reset(new Operators(impl_->res.order));
  Stats &s = impl_->stats;
  s.order = impl_->res.order;
  s.theta = impl_->res.theta;
  s.leaf = impl_->res.leaf;
  s.estimated_error = impl_->res.estimated_error;
}

Solver::~Solver() = default;

const Stats &Solver::stats() const { return impl_->stats; }
const Options &Solver::options() const { return impl_->opts; }
std::size_t Solver::size() const { return impl_->n; }

void Solver::partition(int part, int nparts, std::size_t &first, std::size_t &last) const {
  if (!impl_->built) throw std::runtime_error("gcfmm: partition() called before build()");
  if (nparts < 1 || part < 0 || part >= nparts)
    throw std::invalid_argument("gcfmm: need 0 <= part < nparts, got part " + std::to_string(part) +
                                " of " + std::to_string(nparts));
  impl_->range_of(part, nparts, first, last);
}

void Solver::set_box(double xlo, double ylo, double lx, double ly) {
  if (impl_->opts.boundary != Boundary::Periodic2D)
    throw std::invalid_argument("gcfmm: set_box() is only for Boundary::Periodic2D");
  if (!(std::isfinite(xlo) && std::isfinite(ylo) && std::isfinite(lx) && std::isfinite(ly)) || !(lx > 0.0) ||
      !(ly > 0.0))
    throw std::invalid_argument("gcfmm: set_box() needs finite xlo, ylo and lx, ly > 0");
  impl_->x0 = xlo;
  impl_->y0 = ylo;
  impl_->lx = lx;
  impl_->ly = ly;
  impl_->box_set = true;
  impl_->built = false;
}

void Solver::build(std::size_t n, const double *x, const double *y, const double *z) {
  Impl &I = *impl_;
  const auto t0 = Clock::now();
  if (I.periodic() && !I.box_set) throw std::runtime_error("gcfmm: Periodic2D needs set_box() before build()");
  if (n > 0 && (!x || !y || !z)) throw std::invalid_argument("gcfmm: build() got a null position array");
  I.built = false;
  I.n = n;
  const double *px = x, *py = y;
  if (I.periodic()) {
    I.wx.resize(n);
    I.wy.resize(n);
    auto wrap = [](double v, double lo, double l) {
      double w = v - l * std::floor((v - lo) / l);
      if (w >= lo + l) w -= l;  // round-off at the upper edge
      if (w < lo) w = lo;
      return w;
    };
    for (std::size_t i = 0; i < n; ++i) {
      I.wx[i] = wrap(x[i], I.x0, I.lx);
      I.wy[i] = wrap(y[i], I.y0, I.ly);
    }
    px = I.wx.data();
    py = I.wy.data();
  }
  I.tree.build(n, px, py, z, I.res.leaf);

  std::vector<Vec3> shifts;
  if (I.periodic()) {
    const int k = I.opts.images;
    for (int nx = -k; nx <= k; ++nx)
      for (int ny = -k; ny <= k; ++ny) shifts.push_back({nx * I.lx, ny * I.ly, 0.0});
  } else {
    shifts.push_back({0.0, 0.0, 0.0});
  }
  const int p = I.res.order;
  build_lists(I.tree, shifts, I.res.theta, m2l_cost(p), I.lists);

  const std::size_t nn = I.tree.nodes.size();
  const std::size_t es = I.ops->size();
  I.M.assign(nn * es, 0.0);
  I.L.assign(nn * es, 0.0);
  I.has_local.assign(nn, 0);
  std::size_t maxm2l = 0;
  for (std::size_t i = 0; i < nn; ++i)
    maxm2l = std::max<std::size_t>(maxm2l, I.lists.m2l_offset[i + 1] - I.lists.m2l_offset[i]);
  I.batch_m.assign(maxm2l, nullptr);
  I.batch_r.assign(maxm2l, Vec3{});
  I.qs.assign(n, 0.0);
  I.ps.assign(n, 0.0);
  I.exs.assign(n, 0.0);
  I.eys.assign(n, 0.0);
  I.ezs.assign(n, 0.0);

  // estimated cost per particle, summed over leaves, for the work partitions
  std::vector<double> cost(n, l2p_cost(p));
  const auto &nodes = I.tree.nodes;
  for (const auto &e : I.lists.p2p) {
    const Node &A = nodes[e.target];
    const double c = nodes[e.source].count();
    for (std::uint32_t k = A.begin; k < A.end; ++k) cost[k] += c;
  }
  for (const auto &e : I.lists.m2l) {
    const Node &A = nodes[e.target];
    const double c = m2l_cost(p) / A.count();
    for (std::uint32_t k = A.begin; k < A.end; ++k) cost[k] += c;
  }
  I.leaf_prefix.assign(I.tree.leaves.size() + 1, 0.0);
  for (std::size_t l = 0; l < I.tree.leaves.size(); ++l) {
    const Node &A = nodes[I.tree.leaves[l]];
    double c = 0.0;
    for (std::uint32_t k = A.begin; k < A.end; ++k) c += cost[k];
    I.leaf_prefix[l + 1] = I.leaf_prefix[l] + c;
  }

  // coincident particles (always in the same leaf)
  I.coincident.clear();
  const auto &xs = I.tree.xs, &ys = I.tree.ys, &zs = I.tree.zs;
  for (auto li : I.tree.leaves) {
    const Node &A = nodes[li];
    for (std::uint32_t a = A.begin; a < A.end; ++a)
      for (std::uint32_t b = a + 1; b < A.end; ++b)
        if (xs[a] == xs[b] && ys[a] == ys[b] && zs[a] == zs[b]) I.coincident.emplace_back(a, b);
  }

  I.zmin = I.zmax = 0.0;
  if (n > 0) {
    I.zmin = I.zmax = zs[0];
    for (std::size_t k = 0; k < n; ++k) {
      I.zmin = std::min(I.zmin, zs[k]);
      I.zmax = std::max(I.zmax, zs[k]);
    }
  }

  Stats &s = I.stats;
  s.levels = I.tree.levels;
  s.nodes = nn;
  s.leaves = I.tree.leaves.size();
  s.m2l_count = I.lists.m2l.size();
  s.p2p_pairs = I.lists.p2p_pairs;
  s.estimated_error = I.res.estimated_error;

  if (I.periodic() && I.opts.farfield == FarField::Exact) {
#if GCFMM_HAVE_LATTICE_SUM
    // the lattice sum accepts accuracies down to 1e-8 (its far field is smooth and tiny anyway)
    const double facc = std::max(I.opts.accuracy, 1e-8);
    if (I.far.needs_setup(I.x0, I.y0, I.lx, I.ly, I.zmin, I.zmax, I.opts.images, facc))
      I.far.setup(I.x0, I.y0, I.lx, I.ly, I.zmin, I.zmax, I.opts.images, facc);
    s.estimated_error += I.far.estimated_error();
#else
    throw std::runtime_error("gcfmm: FarField::Exact is not available in this build (no lattice_sum.hpp)");
#endif
  }
#if !GCFMM_HAVE_AVERAGE_FIELD
  if (I.periodic() && I.opts.farfield == FarField::Average)
    throw std::runtime_error("gcfmm: FarField::Average is not available in this build (no average_field.hpp)");
#endif
  I.built = true;
  s.t_build = seconds(t0, Clock::now());
}

void Solver::evaluate(const double *q, double *pot, double *ex, double *ey, double *ez, int part, int nparts) {
  Impl &I = *impl_;
  if (!I.built) throw std::runtime_error("gcfmm: evaluate() called before build()");
  if (nparts < 1 || part < 0 || part >= nparts)
    throw std::invalid_argument("gcfmm: evaluate() needs 0 <= part < nparts, got part " + std::to_string(part) +
                                " of " + std::to_string(nparts));
  const std::size_t n = I.n;
  if (n > 0 && (!q || !pot || !ex || !ey || !ez)) throw std::invalid_argument("gcfmm: evaluate() got a null array");
  const auto &perm = I.tree.perm;
  for (std::size_t k = 0; k < n; ++k) I.qs[k] = q[perm[k]];
  for (const auto &c : I.coincident)
    if (I.qs[c.first] != 0.0 || I.qs[c.second] != 0.0)
      throw std::runtime_error("gcfmm: particles " + std::to_string(perm[c.first]) + " and " +
                               std::to_string(perm[c.second]) + " are at the same position");
  for (std::size_t i = 0; i < n; ++i) pot[i] = ex[i] = ey[i] = ez[i] = 0.0;
  Stats &s = I.stats;
  s.t_upward = s.t_m2l = s.t_p2p = s.t_downward = s.t_far = 0.0;
  if (n == 0) return;

  std::size_t tb, te;
  I.range_of(part, nparts, tb, te);
  for (std::size_t k = tb; k < te; ++k) I.ps[k] = I.exs[k] = I.eys[k] = I.ezs[k] = 0.0;

  const auto &nodes = I.tree.nodes;
  const auto &xs = I.tree.xs, &ys = I.tree.ys, &zs = I.tree.zs;
  const Operators &ops = *I.ops;
  const std::size_t es = ops.size();
  const std::size_t nn = nodes.size();
  const auto &shifts = I.lists.shifts;
  auto hits = [&](const Node &A) { return A.begin < te && A.end > tb; };

  // upward pass: P2M at leaves, M2M to parents (children have larger indices)
  auto t = Clock::now();
  std::fill(I.M.begin(), I.M.end(), 0.0);
  for (std::size_t i = nn; i-- > 0;) {
    const Node &A = nodes[i];
    double *Mi = I.M.data() + i * es;
    if (A.leaf())
      ops.p2m_batch(A.count(), xs.data() + A.begin, ys.data() + A.begin, zs.data() + A.begin,
                    I.qs.data() + A.begin, A.center, Mi);
    ops.symmetrize(Mi);
    if (A.parent >= 0) {
      const Node &P = nodes[A.parent];
      ops.m2m(Mi, A.center - P.center, I.M.data() + A.parent * es);
    }
  }
  auto t1 = Clock::now();
  s.t_upward = seconds(t, t1);

  // M2L into the local expansions of the nodes that hold targets of this part
  t = t1;
  for (std::size_t i = 0; i < nn; ++i) {
    const Node &A = nodes[i];
    I.has_local[i] = 0;
    if (!hits(A)) continue;
    const std::uint32_t e0 = I.lists.m2l_offset[i], e1 = I.lists.m2l_offset[i + 1];
    double *Li = I.L.data() + i * es;
    std::fill(Li, Li + es, 0.0);
    if (e1 == e0) continue;
    for (std::uint32_t e = e0; e < e1; ++e) {
      const Interaction &it = I.lists.m2l[e];
      const Node &B = nodes[it.source];
      I.batch_m[e - e0] = I.M.data() + it.source * es;
      I.batch_r[e - e0] = A.center - (B.center + shifts[it.shift]);
    }
    ops.m2l_batch(e1 - e0, I.batch_m.data(), I.batch_r.data(), Li);
    if (e1 > e0) I.has_local[i] = 1;
  }
  t1 = Clock::now();
  s.t_m2l = seconds(t, t1);

  // P2P (per target, contributions in list order: independent of the partition)
  t = t1;
  for (std::size_t i = 0; i < nn; ++i) {
    const Node &A = nodes[i];
    if (!hits(A)) continue;
    const std::uint32_t e0 = I.lists.p2p_offset[i], e1 = I.lists.p2p_offset[i + 1];
    if (e0 == e1) continue;
    const std::size_t a = std::max<std::size_t>(A.begin, tb), b = std::min<std::size_t>(A.end, te);
    for (std::uint32_t e = e0; e < e1; ++e) {
      const Interaction &it = I.lists.p2p[e];
      const Node &B = nodes[it.source];
      const Vec3 &sh = shifts[it.shift];
      p2p(b - a, xs.data() + a, ys.data() + a, zs.data() + a, B.count(), xs.data() + B.begin, ys.data() + B.begin,
          zs.data() + B.begin, I.qs.data() + B.begin, sh.x, sh.y, sh.z, I.ps.data() + a, I.exs.data() + a,
          I.eys.data() + a, I.ezs.data() + a);
    }
  }
  t1 = Clock::now();
  s.t_p2p = seconds(t, t1);

  // downward pass: L2L from the parent, L2P at leaves
  t = t1;
  for (std::size_t i = 0; i < nn; ++i) {
    const Node &A = nodes[i];
    if (!hits(A)) continue;
    double *Li = I.L.data() + i * es;
    if (A.parent >= 0 && I.has_local[A.parent]) {
      const Node &P = nodes[A.parent];
      ops.l2l(I.L.data() + A.parent * es, A.center - P.center, Li);
      I.has_local[i] = 1;
    }
    if (!I.has_local[i]) continue;
    ops.symmetrize(Li);
    if (A.leaf()) {
      const std::size_t a = std::max<std::size_t>(A.begin, tb), b = std::min<std::size_t>(A.end, te);
      ops.l2p_batch(Li, A.center, b - a, xs.data() + a, ys.data() + a, zs.data() + a, I.ps.data() + a,
                    I.exs.data() + a, I.eys.data() + a, I.ezs.data() + a);
    }
  }
  t1 = Clock::now();
  s.t_downward = seconds(t, t1);

  // far field beyond the image shells
  t = t1;
  if (I.periodic() && I.opts.farfield == FarField::Exact) {
#if GCFMM_HAVE_LATTICE_SUM
    I.far.evaluate(n, xs.data(), ys.data(), zs.data(), I.qs.data(), tb, te, I.ps.data(), I.exs.data(), I.eys.data(),
                   I.ezs.data());
#endif
  } else if (I.periodic() && I.opts.farfield == FarField::Average) {
#if GCFMM_HAVE_AVERAGE_FIELD
    double blo = I.opts.bed_zlo, bhi = I.opts.bed_zhi;
    if (std::isnan(blo)) {
      bool any = false;
      for (std::size_t k = 0; k < n; ++k)
        if (I.qs[k] != 0.0) {
          blo = any ? std::min(blo, zs[k]) : zs[k];
          bhi = any ? std::max(bhi, zs[k]) : zs[k];
          any = true;
        }
      if (!any) blo = bhi = NAN;
    }
    if (!std::isnan(blo) && !(bhi - blo > 1e-6 * std::min(I.lx, I.ly))) {
      // a flat layer of charges (e.g. one charged particle): the slab becomes a sheet; give it
      // a small thickness (relative change of the far field ~ 1e-6)
      const double mid = 0.5 * (blo + bhi), h = 0.5e-6 * std::min(I.lx, I.ly);
      blo = mid - h;
      bhi = mid + h;
    }
    if (!std::isnan(blo))
      average_far_field(n, xs.data(), ys.data(), zs.data(), I.qs.data(), I.x0, I.y0, I.lx, I.ly, I.opts.images, blo,
                        bhi, tb, te, I.ps.data(), I.exs.data(), I.eys.data(), I.ezs.data());
#endif
  }
  s.t_far = seconds(t, Clock::now());

  for (std::size_t k = tb; k < te; ++k) {
    const std::size_t i = perm[k];
    pot[i] = I.ps[k];
    ex[i] = I.exs[k];
    ey[i] = I.eys[k];
    ez[i] = I.ezs[k];
  }
}

}  // namespace gcfmm
