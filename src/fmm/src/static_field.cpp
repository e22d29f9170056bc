// GRANULAR-CHARGED FMM core library (gcfmm): the field of a fixed set of sources at moving
// targets (include/gcfmm/static_field.hpp; method: doc/fmm-static-sources.md). The operators,
// the traversal, the P2P kernel and both far fields are the library's own (expansions.hpp,
// interaction_lists.hpp, kernels.hpp, far_field.hpp, average_field.hpp); this file is the
// driver:
//   set_sources(): wrap/scale -> source tree -> upward pass (P2M, M2M) -> far field: set-up
//                  and node potentials (exact) or charge and bed (average) -> source energy
//   evaluate():    wrap/scale -> target tree -> coincidence test -> dual-tree lists (target
//                  tree x source tree, every shift) -> M2L -> P2P -> L2L/L2P -> far field
//                  -> scatter to the caller's order
#include "gcfmm/static_field.hpp"

#include "solver_impl.hpp"

namespace gcfmm {

using namespace detail;

struct StaticSourceField::Impl {
  Options opts;
  Resolved res;
  StaticFieldStats stats;
  int target_leaf = StaticSourceField::kDefaultTargetLeaf;
  bool box_set = false;
  double x0 = 0.0, y0 = 0.0, lx = 0.0, ly = 0.0;      // primary cell (Periodic2D)
  double zhint_lo = NAN, zhint_hi = NAN;              // set_z_range()
  double cover_lo = NAN, cover_hi = NAN;              // z range the far column must cover (units of h)
  bool sources_set = false;
  std::size_t ns = 0;                                  // sources given (with zero charges)
  std::unique_ptr<Operators> ops;
  P2PKernel p2p_kernel;    // on the path of ops, within p2p_term_tolerance of the options
  double h = 1.0, inv_h = 1.0;                         // length unit and its inverse
  double sx0 = 0.0, sy0 = 0.0, slx = 0.0, sly = 0.0;   // the cell in units of h
  std::vector<Vec3> shifts;                            // image shifts of the sources (units of h)

  // sources (charged only), in units of h
  std::vector<std::size_t> src_index;                  // kept source -> index in set_sources()' arrays
  std::vector<double> cx, cy, cz, cq;                  // kept sources, wrapped and scaled (input order)
  Tree stree;                                          // source tree
  std::vector<double> sq;                              // charges in source-tree order
  std::vector<double> multipole;                       // ops->size() doubles per source node
  double qsum = 0.0;                                   // total charge (average far field)
  double bed_lo = 0.0, bed_hi = 0.0;                   // bed of the average far field (units of h)
  PeriodicFarField far;                                // exact far field: operator
  std::vector<double> phi;                             // and the sources' node potentials
  double energy = 0.0;
  bool energy_valid = false;                           // energy of the current sources computed

  // targets (scratch of evaluate())
  std::vector<double> tx, ty, tz;
  Tree ttree;
  InteractionLists lists;
  std::vector<double> local;
  std::vector<char> has_local;
  std::vector<double> tpot, tex, tey, tez;
  std::vector<const double *> batch_m;
  std::vector<Vec3> batch_r;

  bool periodic() const { return opts.boundary == Boundary::Periodic2D; }
  std::size_t esize() const { return ops->size(); }

  void scale_sources(std::size_t n, const double *x, const double *y, const double *z, const double *q);
  void prepare_far_field();
  void compute_energy();
  void scale_targets(std::size_t n, const double *x, const double *y, const double *z);
  void check_coincidence() const;
  void m2l();
  void p2p();
  void downward();
  void far_field();
};

namespace {
void check_finite_box(double xlo, double ylo, double lx, double ly) {
  if (!(std::isfinite(xlo) && std::isfinite(ylo) && std::isfinite(lx) && std::isfinite(ly)) || !(lx > 0.0) ||
      !(ly > 0.0))
    throw std::invalid_argument("gcfmm: set_box() needs finite xlo, ylo and lx, ly > 0");
}
}  // namespace

StaticSourceField::StaticSourceField(const Options &opts) : impl_(new Impl) {
  opts.validate();
  Impl &I = *impl_;
  I.opts = opts;
  I.res = resolve(opts);
  I.opts.order = I.res.order;
  I.opts.theta = I.res.theta;
  I.opts.leaf = I.res.leaf;
  I.ops.reset(new Operators(I.res.order));
  I.p2p_kernel = p2p_kernel_within(p2p_term_tolerance(opts), I.ops->simd_path());
  I.stats.order = I.res.order;
  I.stats.theta = I.res.theta;
  I.stats.leaf = I.res.leaf;
  I.stats.target_leaf = I.target_leaf;
  I.stats.estimated_error = I.res.estimated_error;
}

StaticSourceField::~StaticSourceField() = default;

void StaticSourceField::set_box(double xlo, double ylo, double lx, double ly) {
  Impl &I = *impl_;
  if (!I.periodic()) throw std::invalid_argument("gcfmm: set_box() is only for Boundary::Periodic2D");
  check_finite_box(xlo, ylo, lx, ly);
  I.x0 = xlo;
  I.y0 = ylo;
  I.lx = lx;
  I.ly = ly;
  I.box_set = true;
  I.sources_set = false;
  I.cover_lo = I.cover_hi = NAN;
}

void StaticSourceField::set_z_range(double zlo, double zhi) {
  Impl &I = *impl_;
  if (!I.periodic()) throw std::invalid_argument("gcfmm: set_z_range() is only for Boundary::Periodic2D");
  if (!(std::isfinite(zlo) && std::isfinite(zhi)) || !(zhi >= zlo))
    throw std::invalid_argument("gcfmm: set_z_range() needs finite zlo <= zhi");
  I.zhint_lo = zlo;
  I.zhint_hi = zhi;
}

void StaticSourceField::set_target_leaf(int leaf) {
  if (leaf < 0) throw std::invalid_argument("gcfmm: set_target_leaf() needs leaf >= 0 (0 = default)");
  impl_->target_leaf = leaf > 0 ? leaf : kDefaultTargetLeaf;
  impl_->stats.target_leaf = impl_->target_leaf;
}

// ---------------------------------------------------------------------------------------------
// set_sources

// Charged sources only, wrapped into the cell and expressed in the length unit h: the cell's
// (as Solver) for Periodic2D, the charged sources' extent in free space (Solver over the
// sources uses the same one; the targets are scaled by it too, wherever they lie).
void StaticSourceField::Impl::scale_sources(std::size_t n, const double *x, const double *y, const double *z,
                                            const double *q) {
  src_index.clear();
  for (std::size_t i = 0; i < n; ++i)
    if (q[i] != 0.0) src_index.push_back(i);
  const std::size_t m = src_index.size();
  if (periodic()) {
    h = length_unit(std::max(lx, ly));
  } else {
    double extent = 0.0;
    if (m > 0)
      for (const double *c : {x, y, z}) {
        double lo = c[src_index[0]], hi = lo;
        for (std::size_t i : src_index) {
          lo = std::min(lo, c[i]);
          hi = std::max(hi, c[i]);
        }
        extent = std::max(extent, hi - lo);
      }
    h = length_unit(extent);
  }
  inv_h = 1.0 / h;
  sx0 = x0 * inv_h;
  sy0 = y0 * inv_h;
  slx = lx * inv_h;
  sly = ly * inv_h;
  shifts.clear();
  if (periodic()) {
    const int k = opts.images;
    for (int nx = -k; nx <= k; ++nx)
      for (int ny = -k; ny <= k; ++ny) shifts.push_back({nx * slx, ny * sly, 0.0});
  } else {
    shifts.push_back({0.0, 0.0, 0.0});
  }
  cx.resize(m);
  cy.resize(m);
  cz.resize(m);
  cq.resize(m);
  qsum = 0.0;
  for (std::size_t k = 0; k < m; ++k) {
    const std::size_t i = src_index[k];
    cx[k] = (periodic() ? wrap(x[i], x0, lx) : x[i]) * inv_h;
    cy[k] = (periodic() ? wrap(y[i], y0, ly) : y[i]) * inv_h;
    cz[k] = z[i] * inv_h;
    cq[k] = q[i];
    qsum += q[i];
  }
  stree.build(m, cx.data(), cy.data(), cz.data(), res.leaf);
  sq.resize(m);
  for (std::size_t k = 0; k < m; ++k) sq[k] = cq[stree.perm[k]];
}

// Exact: the column covers the sources, set_z_range() and every target range seen so far
// (units of h); the node potentials of the sources at all its boxes (eq. (4.6)). Average: the
// bed (eq. (4.7)), as Solver takes it.
void StaticSourceField::Impl::prepare_far_field() {
  phi.clear();
  stats.t_far_setup = stats.t_far_prepare = 0.0;
  if (!periodic() || stree.nodes.empty()) return;
  if (opts.farfield == FarField::Average) {
    average_bed(opts, inv_h, sq.size(), stree.zs.data(), sq.data(), slx, sly, bed_lo, bed_hi);
    return;
  }
  if (opts.farfield != FarField::Exact) return;
  const auto [zlo, zhi] = std::minmax_element(stree.zs.begin(), stree.zs.end());
  double lo = *zlo, hi = *zhi;
  if (!std::isnan(zhint_lo)) {
    lo = std::min(lo, zhint_lo * inv_h);
    hi = std::max(hi, zhint_hi * inv_h);
  }
  if (!std::isnan(cover_lo)) {
    lo = std::min(lo, cover_lo);
    hi = std::max(hi, cover_hi);
  }
  cover_lo = lo;
  cover_hi = hi;
  const double facc = far_field_accuracy(opts);
  stats.t_far_setup = timed([&] {
    if (far.needs_setup(sx0, sy0, slx, sly, lo, hi, opts.images, facc)) {
      far.setup(sx0, sy0, slx, sly, lo, hi, opts.images, facc);
      ++stats.far_setups;
    }
  });
  stats.t_far_prepare =
      timed([&] { far.node_potentials(sq.size(), stree.xs.data(), stree.ys.data(), stree.zs.data(), sq.data(), phi); });
}

// U_S = (1/2) sum_s q_s u_s (eq. (4.10)) by one Solver over the charged sources. For the exact
// far field the Solver runs without it and the far part is interpolated from the node
// potentials already computed (the same operator and node charges: no second set-up).
void StaticSourceField::Impl::compute_energy() {
  energy = 0.0;
  const std::size_t m = cq.size();
  if (m == 0) return;
  Options o = opts;
  const bool exact = periodic() && opts.farfield == FarField::Exact;
  if (exact) o.farfield = FarField::None;
  Solver s(o);
  // the Solver gets the kept sources in the caller's units (its length unit is the same h)
  std::vector<double> ux(m), uy(m), uz(m), pot(m), ex(m), ey(m), ez(m), u(m);
  for (std::size_t k = 0; k < m; ++k) {
    ux[k] = cx[k] * h;
    uy[k] = cy[k] * h;
    uz[k] = cz[k] * h;
  }
  if (periodic()) s.set_box(x0, y0, lx, ly);
  s.build(m, ux.data(), uy.data(), uz.data());
  try {
    s.evaluate(cq.data(), pot.data(), ex.data(), ey.data(), ez.data());
  } catch (const CoincidentParticles &c) {
    const std::size_t i = src_index[c.first()], j = src_index[c.second()];
    throw CoincidentParticles(i, j, "gcfmm: sources " + std::to_string(i) + " and " + std::to_string(j) +
                                        " are at the same position (closer than " +
                                        std::to_string(kCoincidenceRadius * h) + ")");
  }
  s.energy_potential(u.data());
  double e = 0.0;
  for (std::size_t k = 0; k < m; ++k) e += cq[k] * u[k];
  if (exact) {
    std::vector<double> fp(m, 0.0), fx(m, 0.0), fy(m, 0.0), fz(m, 0.0);
    far.interpolate_at(phi, m, stree.xs.data(), stree.ys.data(), stree.zs.data(), fp.data(), fx.data(), fy.data(),
                       fz.data());
    for (std::size_t k = 0; k < m; ++k) e += sq[k] * fp[k] * inv_h;
  }
  energy = 0.5 * e;
}

void StaticSourceField::set_sources(std::size_t ns, const double *x, const double *y, const double *z,
                                    const double *q) {
  Impl &I = *impl_;
  if (I.periodic() && !I.box_set) throw std::runtime_error("gcfmm: Periodic2D needs set_box() before set_sources()");
  if (ns > 0 && (!x || !y || !z || !q)) throw std::invalid_argument("gcfmm: set_sources() got a null array");
  I.sources_set = false;
  I.ns = ns;
  StaticFieldStats &s = I.stats;
  s.t_set_sources = timed([&] {
    s.t_source_tree = timed([&] { I.scale_sources(ns, x, y, z, q); });
    s.t_upward = timed([&] { upward_pass(I.stree, I.sq.data(), *I.ops, I.multipole); });
    I.prepare_far_field();
  });
  // the sources' energy costs one Solver over them: computed when first asked
  I.energy_valid = false;
  s.t_energy = 0.0;
  s.sources = I.sq.size();
  s.source_nodes = I.stree.nodes.size();
  s.source_leaves = I.stree.leaves.size();
  s.estimated_error = I.res.estimated_error;
  if (I.periodic() && I.opts.farfield == FarField::Exact && I.far.ready()) s.estimated_error += I.far.estimated_error();
  I.sources_set = true;
}

// ---------------------------------------------------------------------------------------------
// evaluate

void StaticSourceField::Impl::scale_targets(std::size_t n, const double *x, const double *y, const double *z) {
  tx.resize(n);
  ty.resize(n);
  tz.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    tx[i] = (periodic() ? wrap(x[i], x0, lx) : x[i]) * inv_h;
    ty[i] = (periodic() ? wrap(y[i], y0, ly) : y[i]) * inv_h;
    tz[i] = z[i] * inv_h;
  }
  ttree.build(n, tx.data(), ty.data(), tz.data(), target_leaf);
}

// A target closer than r = kCoincidenceRadius (units of h) to a charged source or to one of
// its copies in the image shells: the P2P kernel would skip the pair (its r2_min) and the
// field would silently miss it, so it throws, as Solver does for two particles. A range query
// in the source tree per target (bounding spheres of the nodes), for the unshifted sources and,
// for a target within r of the cell wall, for the shifted ones (both are wrapped into the cell,
// so a target and a source image can only be that close across the wall).
void StaticSourceField::Impl::check_coincidence() const {
  const double r = kCoincidenceRadius, r2 = r * r;
  const auto &nodes = stree.nodes;
  std::vector<std::int32_t> stack;
  for (std::size_t k = 0; k < ttree.xs.size(); ++k) {
    const double px = ttree.xs[k], py = ttree.ys[k], pz = ttree.zs[k];
    const bool wall = periodic() && std::min({px - sx0, sx0 + slx - px, py - sy0, sy0 + sly - py}) <= r;
    for (const Vec3 &s : shifts) {
      if (!(s.x == 0.0 && s.y == 0.0) && !wall) continue;
      const double ux = px - s.x, uy = py - s.y, uz = pz - s.z;  // |target - (source + s)|
      stack.assign(1, 0);
      while (!stack.empty()) {
        const Node &B = nodes[stack.back()];
        stack.pop_back();
        const double dx = ux - B.center.x, dy = uy - B.center.y, dz = uz - B.center.z;
        const double reach = B.radius + r;
        if (dx * dx + dy * dy + dz * dz > reach * reach) continue;
        if (!B.leaf()) {
          for (int c = 0; c < B.nchild; ++c) stack.push_back(B.child + c);
          continue;
        }
        for (std::uint32_t j = B.begin; j < B.end; ++j) {
          const double ex = ux - stree.xs[j], ey = uy - stree.ys[j], ez = uz - stree.zs[j];
          if (ex * ex + ey * ey + ez * ez <= r2) {
            const std::size_t ti = ttree.perm[k], si = src_index[stree.perm[j]];
            throw CoincidentParticles(ti, si, "gcfmm: target " + std::to_string(ti) + " and source " +
                                                  std::to_string(si) + " are at the same position (closer than " +
                                                  std::to_string(kCoincidenceRadius * h) + ")");
          }
        }
      }
    }
  }
}

// M2L (eq. (3.11)) from the source multipoles into the target nodes' local expansions.
void StaticSourceField::Impl::m2l() {
  const auto &tn = ttree.nodes, &sn = stree.nodes;
  const std::size_t S = esize();
  for (std::size_t i = 0; i < tn.size(); ++i) {
    const std::uint32_t e0 = lists.m2l_offset[i], e1 = lists.m2l_offset[i + 1];
    if (e1 == e0) continue;
    m2l_entries(*ops, tn[i], lists, e0, e1, sn, multipole.data(), batch_m, batch_r, local.data() + i * S);
    has_local[i] = 1;
  }
}

// P2P (eq. (3.1)): the targets of each listed target node against the source node's sources.
void StaticSourceField::Impl::p2p() {
  const auto &tn = ttree.nodes, &sn = stree.nodes;
  const auto &xs = ttree.xs, &ys = ttree.ys, &zs = ttree.zs;
  for (std::size_t i = 0; i < tn.size(); ++i)
    p2p_entries(p2p_kernel, lists, i, tn[i].begin, tn[i].end, xs.data(), ys.data(), zs.data(), sn, stree.xs.data(),
                stree.ys.data(), stree.zs.data(), sq.data(), tpot.data(), tex.data(), tey.data(), tez.data());
}

// L2L (eq. (3.12)) down the target tree, L2P (eq. (3.13)) at its leaves.
void StaticSourceField::Impl::downward() {
  const auto &tn = ttree.nodes;
  const auto &xs = ttree.xs, &ys = ttree.ys, &zs = ttree.zs;
  const std::size_t S = esize();
  for (std::size_t i = 0; i < tn.size(); ++i) {
    const Node &A = tn[i];
    double *Li = local.data() + i * S;
    if (A.parent >= 0 && has_local[A.parent]) {
      ops->l2l(local.data() + static_cast<std::size_t>(A.parent) * S, A.center - tn[A.parent].center, Li);
      has_local[i] = 1;
    }
    if (!has_local[i]) continue;
    ops->symmetrize(Li);
    if (A.leaf())
      ops->l2p_batch(Li, A.center, A.count(), xs.data() + A.begin, ys.data() + A.begin, zs.data() + A.begin,
                     tpot.data() + A.begin, tex.data() + A.begin, tey.data() + A.begin, tez.data() + A.begin);
  }
}

// Beyond the image shells (eq. (4.1)): the node potentials interpolated at the targets (exact,
// eq. (4.6)), or the average field of the sources' charge and bed (eq. (4.7)).
void StaticSourceField::Impl::far_field() {
  if (!periodic()) return;
  const std::size_t n = ttree.xs.size();
  const auto &xs = ttree.xs, &ys = ttree.ys, &zs = ttree.zs;
  if (opts.farfield == FarField::Exact) {
    // targets outside the stored column: extend it (a new set-up and node potentials)
    const auto [lo, hi] = std::minmax_element(zs.begin(), zs.end());
    if (*lo < far.stored_zlo() || *hi > far.stored_zhi()) {
      cover_lo = std::min(cover_lo, *lo);
      cover_hi = std::max(cover_hi, *hi);
      prepare_far_field();
      stats.estimated_error = res.estimated_error + far.estimated_error();
    }
    far.interpolate_at(phi, n, xs.data(), ys.data(), zs.data(), tpot.data(), tex.data(), tey.data(), tez.data());
  } else if (opts.farfield == FarField::Average) {
    average_far_field_of_charge(qsum, xs.data(), ys.data(), zs.data(), sx0, sy0, slx, sly, opts.images, bed_lo,
                                bed_hi, 0, n, tpot.data(), tex.data(), tey.data(), tez.data());
  }
}

void StaticSourceField::evaluate(std::size_t nt, const double *x, const double *y, const double *z, double *pot,
                                 double *ex, double *ey, double *ez) {
  Impl &I = *impl_;
  if (!I.sources_set) throw std::runtime_error("gcfmm: StaticSourceField::evaluate() called before set_sources()");
  if (nt > 0 && (!x || !y || !z || !pot || !ex || !ey || !ez))
    throw std::invalid_argument("gcfmm: StaticSourceField::evaluate() got a null array");
  StaticFieldStats &s = I.stats;
  s.targets = nt;
  s.target_nodes = s.m2l_count = s.p2p_pairs = 0;
  s.t_target_tree = s.t_lists = s.t_m2l = s.t_p2p = s.t_downward = s.t_far = 0.0;
  const auto t0 = Clock::now();
  for (std::size_t i = 0; i < nt; ++i) pot[i] = ex[i] = ey[i] = ez[i] = 0.0;
  if (nt > 0 && !I.stree.nodes.empty()) {
    s.t_target_tree = timed([&] {
      I.scale_targets(nt, x, y, z);
      I.check_coincidence();
    });
    s.t_lists = timed([&] {
      build_lists(I.ttree, I.stree, I.shifts, I.res.theta, m2l_cost(I.res.order, I.ops->simd_path()), I.lists);
    });
    const std::size_t nn = I.ttree.nodes.size();
    I.local.assign(nn * I.esize(), 0.0);
    I.has_local.assign(nn, 0);
    std::size_t maxm2l = 0;
    for (std::size_t i = 0; i < nn; ++i)
      maxm2l = std::max<std::size_t>(maxm2l, I.lists.m2l_offset[i + 1] - I.lists.m2l_offset[i]);
    I.batch_m.resize(maxm2l);
    I.batch_r.resize(maxm2l);
    for (auto *v : {&I.tpot, &I.tex, &I.tey, &I.tez}) v->assign(nt, 0.0);
    s.t_m2l = timed([&] { I.m2l(); });
    s.t_p2p = timed([&] { I.p2p(); });
    s.t_downward = timed([&] { I.downward(); });
    s.t_far = timed([&] { I.far_field(); });
    s.target_nodes = nn;
    s.m2l_count = I.lists.m2l.size();
    s.p2p_pairs = I.lists.p2p_pairs;
    // scatter to the caller's order, back from the length unit h
    const auto &perm = I.ttree.perm;
    const double fp = I.inv_h, fe = I.inv_h * I.inv_h;
    for (std::size_t k = 0; k < nt; ++k) {
      const std::size_t i = perm[k];
      pot[i] = fp * I.tpot[k];
      ex[i] = fe * I.tex[k];
      ey[i] = fe * I.tey[k];
      ez[i] = fe * I.tez[k];
    }
  }
  s.t_evaluate = std::chrono::duration<double>(Clock::now() - t0).count();
}

double StaticSourceField::source_energy() const {
  Impl &I = *impl_;
  if (!I.sources_set) throw std::runtime_error("gcfmm: source_energy() called before set_sources()");
  if (!I.energy_valid) {
    I.stats.t_energy = detail::timed([&] { I.compute_energy(); });
    I.energy_valid = true;
  }
  return I.energy;
}

const StaticFieldStats &StaticSourceField::stats() const { return impl_->stats; }
const Options &StaticSourceField::options() const { return impl_->opts; }
std::size_t StaticSourceField::size() const { return impl_->ns; }

std::size_t StaticSourceField::memory_bytes() const {
  const Impl &I = *impl_;
  std::size_t b = 0;
  auto vec = [&b](const auto &v) { b += v.capacity() * sizeof(v[0]); };
  b += tree_bytes(I.stree) + tree_bytes(I.ttree);
  vec(I.src_index);
  for (const auto *v : {&I.cx, &I.cy, &I.cz, &I.cq, &I.sq, &I.multipole, &I.phi, &I.tx, &I.ty, &I.tz, &I.local,
                        &I.tpot, &I.tex, &I.tey, &I.tez})
    vec(*v);
  b += lists_bytes(I.lists);
  vec(I.has_local);
  vec(I.batch_m);
  vec(I.batch_r);
  return b + I.far.memory_bytes();
}

}  // namespace gcfmm
