// GRANULAR-CHARGED FMM core library (gcfmm): the solver driver.
// One evaluation is a sequence of named phases (doc/architecture.md, "Data flow of one step"):
//   build():    wrap positions -> tree -> interaction lists -> storage -> partition costs
//               -> coincident pairs -> far-field set-up
//   evaluate(): sort charges -> upward (P2M, M2M) -> M2L -> P2P -> downward (L2L, L2P)
//               -> far field -> scatter to the caller's order
// Each phase is one member function of Solver::Impl; the phases of evaluate() are the units
// for threading.
#include "gcfmm/solver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "gcfmm/average_field.hpp"
#include "gcfmm/expansions.hpp"
#include "gcfmm/far_field.hpp"
#include "gcfmm/interaction_lists.hpp"
#include "gcfmm/kernels.hpp"
#include "gcfmm/tree.hpp"

namespace gcfmm {

namespace {
using Clock = std::chrono::steady_clock;

// run f() and return its wall time in seconds
template <class F>
double timed(F &&f) {
  const auto t0 = Clock::now();
  f();
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// Cost model in units of one P2P particle pair (doc/theory.md, eq. (3.16)), used to route
// cheap accepted pairs to P2P and to balance the work partitions; measured values in
// doc/benchmarks.md.
double m2l_cost(int p) { return 0.8 * (p + 1.0) * (p + 1.0) * (p + 1.0); }
double l2p_cost(int p) { return 0.25 * (p + 1.0) * (p + 1.0); }

// x wrapped into [lo, lo + l)
double wrap(double v, double lo, double l) {
  double w = v - l * std::floor((v - lo) / l);
  if (w >= lo + l) w -= l;  // round-off at the upper edge
  if (w < lo) w = lo;
  return w;
}

// The solver's length unit: the power of two >= extent (1 if the extent is zero or not
// finite). Scaling by a power of two is exact, so the arithmetic in scaled coordinates gives
// bit-identical results, and r^n, r^-(n+1) of the expansions stay in range at any box size.
double length_unit(double extent) {
  if (!(extent > 0.0) || !std::isfinite(extent)) return 1.0;
  int e = 0;
  std::frexp(extent, &e);  // extent = m 2^e, m in [0.5, 1)
  return std::ldexp(1.0, e);
}

//! The targets of one work partition: sorted particle indices [begin, end).
struct TargetRange {
  std::size_t begin = 0, end = 0;
  bool hits(const Node &A) const { return A.begin < end && A.end > begin; }
  std::size_t first(const Node &A) const { return std::max<std::size_t>(A.begin, begin); }
  std::size_t last(const Node &A) const { return std::min<std::size_t>(A.end, end); }
};
}  // namespace

struct Solver::Impl {
  Options opts;
  Resolved res;
  Stats stats;
  bool box_set = false;
  double x0 = 0.0, y0 = 0.0, lx = 0.0, ly = 0.0;  // primary cell (Periodic2D)
  bool built = false;
  std::size_t n = 0;

  Tree tree;
  InteractionLists lists;
  std::unique_ptr<Operators> ops;
  double h = 1.0, inv_h = 1.0;                // length unit (power of two) and its inverse
  double sx0 = 0.0, sy0 = 0.0, slx = 0.0, sly = 0.0;  // the cell in units of h
  std::vector<double> scaled_x, scaled_y, scaled_z;   // wrapped positions / h (original order)
  std::vector<double> multipole, local;       // expansions, ops->size() doubles per node
  std::vector<char> has_local;                // node has a nonzero local expansion
  // charges and results in the tree's (sorted) particle order
  std::vector<double> sorted_q, sorted_pot, sorted_ex, sorted_ey, sorted_ez;
  std::vector<const double *> batch_m;        // M2L batch of one target node: source multipoles
  std::vector<Vec3> batch_r;                  // and translation vectors
  std::vector<double> leaf_prefix;            // cumulative estimated cost over leaves
  std::vector<std::pair<std::uint32_t, std::uint32_t>> coincident;  // sorted indices, closer than kCoincidenceRadius h
  double zmin = 0.0, zmax = 0.0;              // z range of all particles (units of h)
  PeriodicFarField far;

  bool periodic() const { return opts.boundary == Boundary::Periodic2D; }
  std::size_t expansion_size() const { return ops->size(); }
  double *multipole_of(std::size_t node) { return multipole.data() + node * expansion_size(); }
  double *local_of(std::size_t node) { return local.data() + node * expansion_size(); }

  TargetRange range_of(int part, int nparts) const {
    const std::size_t nl = tree.leaves.size();
    auto bound = [&](int k) -> std::size_t {
      if (k <= 0) return 0;
      if (k >= nparts) return nl;
      const double target = leaf_prefix.back() * double(k) / double(nparts);
      auto it = std::lower_bound(leaf_prefix.begin(), leaf_prefix.end(), target);
      return std::min<std::size_t>(static_cast<std::size_t>(it - leaf_prefix.begin()), nl);
    };
    auto start = [&](std::size_t b) -> std::size_t { return b >= nl ? n : tree.nodes[tree.leaves[b]].begin; };
    TargetRange r;
    r.begin = start(bound(part));
    r.end = std::max(r.begin, start(bound(part + 1)));
    return r;
  }

  // ---- build phases ----
  void build_tree(const double *x, const double *y, const double *z);
  void build_interaction_lists();
  void allocate_storage();
  void estimate_partition_costs();
  void find_coincident_pairs();
  void setup_far_field();
  // ---- evaluate phases ----
  // f(i, node) for every node i that holds targets of the range, in node order
  template <class F>
  void for_target_nodes(const TargetRange &t, F &&f) {
    for (std::size_t i = 0; i < tree.nodes.size(); ++i)
      if (t.hits(tree.nodes[i])) f(i, tree.nodes[i]);
  }
  void sort_charges(const double *q);
  void upward();
  void m2l(const TargetRange &t);
  void p2p(const TargetRange &t);
  void downward(const TargetRange &t);
  void far_field(const TargetRange &t);
};

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
  build_lists(tree, shifts, res.theta, m2l_cost(res.order), lists);
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
  for (auto *v : {&sorted_q, &sorted_pot, &sorted_ex, &sorted_ey, &sorted_ez}) v->assign(n, 0.0);
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
    const double c = m2l_cost(p) / A.count();
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

// Upward pass: P2M at leaves (eq. (3.9)), M2M to parents (eq. (3.10)); children have larger
// indices than their parents, so one reverse sweep suffices. Done for all nodes by every part.
void Solver::Impl::upward() {
  const auto &nodes = tree.nodes;
  const auto &xs = tree.xs, &ys = tree.ys, &zs = tree.zs;
  std::fill(multipole.begin(), multipole.end(), 0.0);
  for (std::size_t i = nodes.size(); i-- > 0;) {
    const Node &A = nodes[i];
    double *Mi = multipole_of(i);
    if (A.leaf())
      ops->p2m_batch(A.count(), xs.data() + A.begin, ys.data() + A.begin, zs.data() + A.begin,
                     sorted_q.data() + A.begin, A.center, Mi);
    ops->symmetrize(Mi);
    if (A.parent >= 0) ops->m2m(Mi, A.center - nodes[A.parent].center, multipole_of(A.parent));
  }
}

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
void Solver::Impl::far_field(const TargetRange &t) {
  if (!periodic()) return;
  const auto &xs = tree.xs, &ys = tree.ys, &zs = tree.zs;
  if (opts.farfield == FarField::Exact) {
    far.evaluate(n, xs.data(), ys.data(), zs.data(), sorted_q.data(), t.begin, t.end, sorted_pot.data(),
                 sorted_ex.data(), sorted_ey.data(), sorted_ez.data());
  } else if (opts.farfield == FarField::Average) {
    double blo = opts.bed_zlo * inv_h, bhi = opts.bed_zhi * inv_h;
    if (std::isnan(blo)) {
      bool any = false;
      for (std::size_t k = 0; k < n; ++k)
        if (sorted_q[k] != 0.0) {
          blo = any ? std::min(blo, zs[k]) : zs[k];
          bhi = any ? std::max(bhi, zs[k]) : zs[k];
          any = true;
        }
      if (!any) return;
    }
    if (!(bhi - blo > 1e-6 * std::min(slx, sly))) {
      // a flat layer of charges (e.g. one charged particle): the slab becomes a sheet; give it
      // a small thickness (relative change of the far field ~ 1e-6)
      const double mid = 0.5 * (blo + bhi), half = 0.5e-6 * std::min(slx, sly);
      blo = mid - half;
      bhi = mid + half;
    }
    average_far_field(n, xs.data(), ys.data(), zs.data(), sorted_q.data(), sx0, sy0, slx, sly, opts.images, blo, bhi,
                      t.begin, t.end, sorted_pot.data(), sorted_ex.data(), sorted_ey.data(), sorted_ez.data());
  }
}

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
    throw std::invalid_argument("gcfmm: need 0 <= part < nparts, got part " + std::to_string(part) + " of " +
                                std::to_string(nparts));
  const TargetRange r = impl_->range_of(part, nparts);
  first = r.begin;
  last = r.end;
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
  if (I.periodic() && !I.box_set) throw std::runtime_error("gcfmm: Periodic2D needs set_box() before build()");
  if (n > 0 && (!x || !y || !z)) throw std::invalid_argument("gcfmm: build() got a null position array");
  I.built = false;
  I.n = n;
  Stats &s = I.stats;
  s.t_build = timed([&] {
    I.build_tree(x, y, z);
    I.build_interaction_lists();
    I.allocate_storage();
    I.estimate_partition_costs();
    I.find_coincident_pairs();
    s.levels = I.tree.levels;
    s.nodes = I.tree.nodes.size();
    s.leaves = I.tree.leaves.size();
    s.m2l_count = I.lists.m2l.size();
    s.p2p_pairs = I.lists.p2p_pairs;
    s.estimated_error = I.res.estimated_error;
    I.setup_far_field();
  });
  I.built = true;
}

void Solver::evaluate(const double *q, double *pot, double *ex, double *ey, double *ez, int part, int nparts) {
  Impl &I = *impl_;
  if (!I.built) throw std::runtime_error("gcfmm: evaluate() called before build()");
  if (nparts < 1 || part < 0 || part >= nparts)
    throw std::invalid_argument("gcfmm: evaluate() needs 0 <= part < nparts, got part " + std::to_string(part) +
                                " of " + std::to_string(nparts));
  const std::size_t n = I.n;
  if (n > 0 && (!q || !pot || !ex || !ey || !ez)) throw std::invalid_argument("gcfmm: evaluate() got a null array");
  I.sort_charges(q);
  for (std::size_t i = 0; i < n; ++i) pot[i] = ex[i] = ey[i] = ez[i] = 0.0;
  Stats &s = I.stats;
  s.t_upward = s.t_m2l = s.t_p2p = s.t_downward = s.t_far = 0.0;
  if (n == 0) return;

  const TargetRange t = I.range_of(part, nparts);
  for (std::size_t k = t.begin; k < t.end; ++k) I.sorted_pot[k] = I.sorted_ex[k] = I.sorted_ey[k] = I.sorted_ez[k] = 0.0;
  s.t_upward = timed([&] { I.upward(); });
  s.t_m2l = timed([&] { I.m2l(t); });
  s.t_p2p = timed([&] { I.p2p(t); });
  s.t_downward = timed([&] { I.downward(t); });
  s.t_far = timed([&] { I.far_field(t); });

  // scatter to the caller's order, back from the length unit h: pot ~ 1/length, E ~ 1/length^2
  const auto &perm = I.tree.perm;
  const double fp = I.inv_h, fe = I.inv_h * I.inv_h;
  for (std::size_t k = t.begin; k < t.end; ++k) {
    const std::size_t i = perm[k];
    pot[i] = fp * I.sorted_pot[k];
    ex[i] = fe * I.sorted_ex[k];
    ey[i] = fe * I.sorted_ey[k];
    ez[i] = fe * I.sorted_ez[k];
  }
}

}  // namespace gcfmm
