// GRANULAR-CHARGED FMM core library (gcfmm): the solver's internal state (private header of
// src/solver*.cpp, not installed). One evaluation is a sequence of named phases
// (doc/architecture.md, "Data flow of one step"):
//   build():    wrap positions -> tree -> interaction lists -> storage -> partition costs
//               -> coincident pairs -> far-field set-up                  (solver_build.cpp)
//   evaluate(): sort charges -> upward (P2M, M2M) -> M2L -> P2P -> downward (L2L, L2P)
//               -> far field -> scatter to the caller's order             (solver_evaluate.cpp)
// Each phase is one member function of detail::SolverCore (Solver::Impl is exactly that); the
// phases of evaluate() are the units for threading. DistributedSolver runs the same phases on
// its rank's particles and adds the remote part between them (src/distributed_impl.hpp).
#ifndef GCFMM_SOLVER_IMPL_HPP
#define GCFMM_SOLVER_IMPL_HPP

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

namespace detail {
using Clock = std::chrono::steady_clock;

// run f() and return its wall time in seconds
template <class F>
inline double timed(F &&f) {
  const auto t0 = Clock::now();
  f();
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// Cost model in units of one P2P particle pair (doc/theory.md, eq. (3.16)), used to route
// cheap accepted pairs to P2P and to balance the work partitions; measured values in
// doc/benchmarks.md.
// The M2L coefficient depends on the instruction-set path: the AVX-512 P2P is the fastest
// relative to M2L (doc/benchmarks.md, "Cost model per path").
inline double m2l_cost(int p, gcsimd::SimdPath path) {
  const double c = path == gcsimd::SimdPath::AVX512 ? 0.8 : (path == gcsimd::SimdPath::AVX2 ? 0.4 : 0.2);
  return c * (p + 1.0) * (p + 1.0) * (p + 1.0);
}
inline double l2p_cost(int p) { return 0.25 * (p + 1.0) * (p + 1.0); }

// x wrapped into [lo, lo + l)
inline double wrap(double v, double lo, double l) {
  double w = v - l * std::floor((v - lo) / l);
  if (w >= lo + l) w -= l;  // round-off at the upper edge
  if (w < lo) w = lo;
  return w;
}

// The solver's length unit: the power of two >= extent (1 if the extent is zero or not
// finite). Scaling by a power of two is exact, so the arithmetic in scaled coordinates gives
// bit-identical results, and r^n, r^-(n+1) of the expansions stay in range at any box size.
inline double length_unit(double extent) {
  if (!(extent > 0.0) || !std::isfinite(extent)) return 1.0;
  int e = 0;
  std::frexp(extent, &e);  // extent = m 2^e, m in [0.5, 1)
  return std::ldexp(1.0, e);
}

// Upward pass (doc/theory.md, eqs. (3.9), (3.10)): P2M at the leaves, M2M to the parents, for
// all nodes of `tree` with the charges q in tree order; `multipole` holds ops.size() doubles
// per node (overwritten). Children have larger indices than their parents, so one reverse
// sweep suffices. Shared by Solver, StaticSourceField and the received LETs of
// DistributedSolver; for the last, `given` flags the leaves whose multipole is already in
// `multipole` (received, not computed: no P2M, not zeroed; the caller zeroes all other nodes).
// With dipoles (px, py, pz in tree order, not null) their P2M (doc/polarization.md, eq. (5.1))
// is added at the leaves.
inline void upward_pass(const Tree &tree, const double *q, Operators &ops, std::vector<double> &multipole,
                        const std::vector<char> *given = nullptr, const double *px = nullptr,
                        const double *py = nullptr, const double *pz = nullptr) {
  const auto &nodes = tree.nodes;
  const auto &xs = tree.xs, &ys = tree.ys, &zs = tree.zs;
  const std::size_t size = ops.size();
  if (!given) multipole.assign(nodes.size() * size, 0.0);
  for (std::size_t i = nodes.size(); i-- > 0;) {
    const Node &A = nodes[i];
    double *Mi = multipole.data() + i * size;
    if (A.leaf() && !(given && (*given)[i])) {
      ops.p2m_batch(A.count(), xs.data() + A.begin, ys.data() + A.begin, zs.data() + A.begin, q + A.begin, A.center,
                    Mi);
      if (px)
        ops.p2m_dipoles(A.count(), xs.data() + A.begin, ys.data() + A.begin, zs.data() + A.begin, px + A.begin,
                        py + A.begin, pz + A.begin, A.center, Mi);
    }
    ops.symmetrize(Mi);
    if (A.parent >= 0) ops.m2m(Mi, A.center - nodes[A.parent].center, multipole.data() + A.parent * size);
  }
}

// The bed z range [blo, bhi] of the average far field made a slab: a flat layer (e.g. one
// charged particle) becomes a slab of thickness 1e-6 min(slx, sly) (relative change of the far
// field ~1e-6).
inline void thicken_bed(double slx, double sly, double &blo, double &bhi) {
  if (!(bhi - blo > 1e-6 * std::min(slx, sly))) {
    const double mid = 0.5 * (blo + bhi), half = 0.5e-6 * std::min(slx, sly);
    blo = mid - half;
    bhi = mid + half;
  }
}

// The bed of the average far field (doc/theory.md, eq. (4.7)) in units of h: Options::bed_zlo
// and bed_zhi if given, else the z range of the charged particles (zs, q: n particles in units
// of h); a flat layer (e.g. one charged particle) becomes a slab of thickness 1e-6 min(slx, sly)
// (relative change of the far field ~1e-6). Returns false when no particle is charged (no
// automatic bed: the far field is zero). Shared by Solver and StaticSourceField.
inline bool average_bed(const Options &o, double inv_h, std::size_t n, const double *zs, const double *q, double slx,
                        double sly, double &blo, double &bhi) {
  blo = o.bed_zlo * inv_h;
  bhi = o.bed_zhi * inv_h;
  if (std::isnan(blo)) {
    bool any = false;
    for (std::size_t k = 0; k < n; ++k)
      if (q[k] != 0.0) {
        blo = any ? std::min(blo, zs[k]) : zs[k];
        bhi = any ? std::max(bhi, zs[k]) : zs[k];
        any = true;
      }
    if (!any) return false;
  }
  thicken_bed(slx, sly, blo, bhi);
  return true;
}

// bytes held by a tree and by interaction lists (memory statistics)
template <class T>
inline std::size_t vector_bytes(const std::vector<T> &v) {
  return v.capacity() * sizeof(T);
}
inline std::size_t tree_bytes(const Tree &t) {
  return vector_bytes(t.nodes) + vector_bytes(t.cubes) + vector_bytes(t.perm) + vector_bytes(t.xs) +
         vector_bytes(t.ys) + vector_bytes(t.zs) + vector_bytes(t.leaves);
}
inline std::size_t lists_bytes(const InteractionLists &l) {
  return vector_bytes(l.shifts) + vector_bytes(l.m2l) + vector_bytes(l.p2p) + vector_bytes(l.m2p) +
         vector_bytes(l.m2l_offset) + vector_bytes(l.p2p_offset) + vector_bytes(l.m2p_offset);
}

//! The targets of one work partition: sorted particle indices [begin, end).
struct TargetRange {
  std::size_t begin = 0, end = 0;
  bool hits(const Node &A) const { return A.begin < end && A.end > begin; }
  std::size_t first(const Node &A) const { return std::max<std::size_t>(A.begin, begin); }
  std::size_t last(const Node &A) const { return std::min<std::size_t>(A.end, end); }
};

// the error of two coincident particles (ids or indices i < j) at the length unit h
inline CoincidentParticles coincidence_error(std::size_t i, std::size_t j, double h) {
  return CoincidentParticles(i, j, "gcfmm: particles " + std::to_string(i) + " and " + std::to_string(j) +
                                       " are at the same position (closer than " +
                                       std::to_string(kCoincidenceRadius * h) + ")");
}

// The shifts of the source tree for the near block (doc/theory.md, eq. (4.1)): (2 images + 1)^2
// lattice vectors of the cell (slx, sly) for Periodic2D, the single shift 0 in free space.
inline std::vector<Vec3> image_shifts(bool periodic, int images, double slx, double sly) {
  std::vector<Vec3> shifts;
  if (periodic) {
    for (int nx = -images; nx <= images; ++nx)
      for (int ny = -images; ny <= images; ++ny) shifts.push_back({nx * slx, ny * sly, 0.0});
  } else {
    shifts.push_back({0.0, 0.0, 0.0});
  }
  return shifts;
}

// M2L (eq. (3.11)) of the list entries [e0, e1) of one target node A into its local expansion
// Li (added), the sources being `snodes` with multipoles `smultipole` (ops.size() doubles per
// node); batch_m, batch_r are scratch of at least e1 - e0 entries.
inline void m2l_entries(Operators &ops, const Node &A, const InteractionLists &lists, std::uint32_t e0,
                        std::uint32_t e1, const std::vector<Node> &snodes, const double *smultipole,
                        std::vector<const double *> &batch_m, std::vector<Vec3> &batch_r, double *Li) {
  if (e1 == e0) return;
  if (batch_m.size() < e1 - e0) {
    batch_m.resize(e1 - e0);
    batch_r.resize(e1 - e0);
  }
  for (std::uint32_t e = e0; e < e1; ++e) {
    const Interaction &it = lists.m2l[e];
    const Node &B = snodes[it.source];
    batch_m[e - e0] = smultipole + it.source * ops.size();
    batch_r[e - e0] = A.center - (B.center + lists.shifts[it.shift]);
  }
  ops.m2l_batch(e1 - e0, batch_m.data(), batch_r.data(), Li);
}

// P2P (eq. (3.1)) of the list entries of target node i at its targets [a, b) (tree order of the
// target arrays tx, ty, tz; results added to pot, ex, ey, ez at the same indices), the sources
// being the node ranges of `snodes` in the arrays sx, sy, sz, sq; with the solver's kernel
// (p2p_kernel_within its options' p2p_term_tolerance).
inline void p2p_entries(const P2PKernel &kernel, const InteractionLists &lists, std::size_t i, std::size_t a,
                        std::size_t b, const double *tx, const double *ty, const double *tz,
                        const std::vector<Node> &snodes, const double *sx, const double *sy, const double *sz,
                        const double *sq, double *pot, double *ex, double *ey, double *ez) {
  for (std::uint32_t e = lists.p2p_offset[i]; e < lists.p2p_offset[i + 1]; ++e) {
    const Interaction &it = lists.p2p[e];
    const Node &B = snodes[it.source];
    const Vec3 &sh = lists.shifts[it.shift];
    kernel.run(b - a, tx + a, ty + a, tz + a, B.count(), sx + B.begin, sy + B.begin, sz + B.begin, sq + B.begin, sh.x,
               sh.y, sh.z, pot + a, ex + a, ey + a, ez + a, kCoincidenceRadius * kCoincidenceRadius);
  }
}

//! The state and phases of one solver over one set of particles (Solver::Impl; one rank's
//! particles in DistributedSolver).
struct SolverCore {
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
  P2PKernel p2p_kernel;                       // on the path of ops, within p2p_term_tolerance(opts)
  double h = 1.0, inv_h = 1.0;                // length unit (power of two) and its inverse
  double sx0 = 0.0, sy0 = 0.0, slx = 0.0, sly = 0.0;  // the cell in units of h
  std::vector<double> scaled_x, scaled_y, scaled_z;   // wrapped positions / h (original order)
  std::vector<double> multipole, local;       // expansions, ops->size() doubles per node
  std::vector<char> has_local;                // node has a nonzero local expansion
  // charges and results in the tree's (sorted) particle order
  std::vector<double> sorted_q, sorted_pot, sorted_ex, sorted_ey, sorted_ez;
  std::vector<double> sorted_average_pot;     // the average far field's part of sorted_pot
  // evaluate_dipoles(): dipoles (units of h) and field gradients (6 per particle), tree order
  std::vector<double> sorted_px, sorted_py, sorted_pz, sorted_g;
  // evaluate_dipoles() with FieldOutputs::targets: nodes holding a target (empty: all nodes)
  std::vector<char> node_has_target;
  bool evaluated = false;                     // evaluate() ran since the last build()
  detail::TargetRange last_range;                     // targets of the last evaluate()
  std::vector<const double *> batch_m;        // M2L batch of one target node: source multipoles
  std::vector<Vec3> batch_r;                  // and translation vectors
  std::vector<double> leaf_prefix;            // cumulative estimated cost over leaves
  std::vector<double> leaf_target_cost;       // estimated cost per target of each leaf
  std::size_t weighed_targets = 0;            // leaf_prefix counts the particles below this index
  std::vector<std::pair<std::uint32_t, std::uint32_t>> coincident;  // sorted indices, closer than kCoincidenceRadius h
  double zmin = 0.0, zmax = 0.0;              // z range of all particles (units of h)
  double zhint_lo = NAN, zhint_hi = NAN;      // set_z_range(): range the far field covers
  PeriodicFarField far;

  bool periodic() const { return opts.boundary == Boundary::Periodic2D; }
  std::size_t expansion_size() const { return ops->size(); }
  //! bytes held: tree, lists, expansions, per-particle arrays, scratch, far-field operator
  std::size_t memory_bytes() const {
    std::size_t b = tree_bytes(tree) + lists_bytes(lists) + far.memory_bytes();
    for (const auto *v : {&scaled_x, &scaled_y, &scaled_z, &multipole, &local, &sorted_q, &sorted_pot, &sorted_ex,
                          &sorted_ey, &sorted_ez, &sorted_average_pot, &leaf_prefix, &leaf_target_cost, &sorted_px, &sorted_py,
                          &sorted_pz, &sorted_g})
      b += vector_bytes(*v);
    b += vector_bytes(has_local) + vector_bytes(batch_m) + vector_bytes(batch_r) + vector_bytes(coincident);
    return b + (ops ? ops->size() * sizeof(double) * 3 * Operators::kBatch : 0);
  }
  double *multipole_of(std::size_t node) { return multipole.data() + node * expansion_size(); }
  double *local_of(std::size_t node) { return local.data() + node * expansion_size(); }

  detail::TargetRange range_of(int part, int nparts) const {
    const std::size_t nl = tree.leaves.size();
    auto bound = [&](int k) -> std::size_t {
      if (k <= 0) return 0;
      if (k >= nparts) return nl;
      const double target = leaf_prefix.back() * double(k) / double(nparts);
      auto it = std::lower_bound(leaf_prefix.begin(), leaf_prefix.end(), target);
      return std::min<std::size_t>(static_cast<std::size_t>(it - leaf_prefix.begin()), nl);
    };
    auto start = [&](std::size_t b) -> std::size_t { return b >= nl ? n : tree.nodes[tree.leaves[b]].begin; };
    detail::TargetRange r;
    r.begin = start(bound(part));
    r.end = std::max(r.begin, start(bound(part + 1)));
    return r;
  }

  // validated options, resolved order/theta/leaf, operators and the stats they fix
  void configure(const Options &o);
  // Solver::set_box() and set_z_range() (checks and state)
  void set_box(double xlo, double ylo, double cell_x, double cell_y);
  void set_z_range(double zlo, double zhi);
  // ---- build phases ----
  void build_tree(const double *x, const double *y, const double *z);
  // the two halves of build_tree(): h from the particles' extent (free) or the cell, then the
  // tree over the wrapped positions in units of h
  void choose_length_unit(const double *x, const double *y, const double *z);
  void set_length_unit(double unit);
  void build_scaled_tree(const double *x, const double *y, const double *z);
  // the phases of build() after build_tree() but setup_far_field()
  void build_after_tree();
  void build_interaction_lists();
  void allocate_storage();
  void estimate_partition_costs();
  // leaf_prefix from the targets among each leaf's particles (input index < targets)
  void weigh_leaves(std::size_t targets);
  void find_coincident_pairs();
  void setup_far_field();
  // ---- evaluate phases ----
  // f(i, node) for every node i that holds targets of the range, in node order
  template <class F>
  void for_target_nodes(const detail::TargetRange &t, F &&f) {
    const bool all = node_has_target.empty();
    for (std::size_t i = 0; i < tree.nodes.size(); ++i)
      if (t.hits(tree.nodes[i]) && (all || node_has_target[i])) f(i, tree.nodes[i]);
  }
  void sort_charges(const double *q);
  // the first coincident pair with a charge, as input indices i < j; false if none
  bool charged_coincident_pair(std::size_t &i, std::size_t &j) const;
  // zero the sorted results of the targets t
  void clear_results(const detail::TargetRange &t);
  void upward();
  void m2l(const detail::TargetRange &t);
  void p2p(const detail::TargetRange &t);
  void downward(const detail::TargetRange &t, bool gradient = false);
  // evaluate()'s and evaluate_dipoles()'s checks and start: std::invalid_argument unless
  // 0 <= part < nparts; the timings reset, the targets t of the part with their results
  // zeroed (false if there are no particles)
  static void check_part(const char *what, int part, int nparts);
  bool start_phases(int part, int nparts, detail::TargetRange &t);
  void far_field(const detail::TargetRange &t, int part, int nparts, const PartSum &sum);
  // the average far field of a total charge qsum per cell in the bed [blo, bhi] (units of h) at
  // the targets t, its potential also kept apart for energy_potential()
  void add_average_far_field(double qsum, double blo, double bhi, const detail::TargetRange &t);
  // the results of the targets t in the caller's order, back from the length unit h
  void scatter(const detail::TargetRange &t, double *pot, double *ex, double *ey, double *ez) const;
  // ---- evaluate_dipoles() phases (solver_dipoles.cpp) ----
  // charges and dipoles to tree order (zero where not given); true if any dipole is nonzero
  bool sort_dipoles(const DipoleSources &src);
  // node_has_target for the particles with input index < targets (cleared if that is all)
  void mark_targets(std::size_t targets);
  // the first coincident pair with a charge or a dipole, as input indices i < j; false if none
  bool source_coincident_pair(std::size_t &i, std::size_t &j) const;
  void p2p_dipoles(const detail::TargetRange &t, bool gradient);
  void far_field_dipoles(const detail::TargetRange &t, bool gradient);
  void scatter_dipoles(const detail::TargetRange &t, const FieldOutputs &out) const;
  // energy_potential() of the last evaluate() (solver.hpp)
  void energy_potential(double *u) const;
};

}  // namespace detail

struct Solver::Impl : detail::SolverCore {};

}  // namespace gcfmm

#endif
