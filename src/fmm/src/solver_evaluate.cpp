// GRANULAR-CHARGED FMM core library (gcfmm): the evaluate() phases of the solver
// (src/solver_impl.hpp).
#include "solver_impl.hpp"

namespace gcfmm {

using namespace detail;

void SolverCore::sort_charges(const double *q) {
  node_has_target.clear();  // evaluate(): every particle is a target
  if (weighed_targets != n) weigh_leaves(n);
  const auto &perm = tree.perm;
  for (std::size_t k = 0; k < n; ++k) sorted_q[k] = q[perm[k]];
}

bool SolverCore::charged_coincident_pair(std::size_t &i, std::size_t &j) const {
  const auto &perm = tree.perm;
  for (const auto &c : coincident)
    if (sorted_q[c.first] != 0.0 || sorted_q[c.second] != 0.0) {
      i = std::min(perm[c.first], perm[c.second]);
      j = std::max(perm[c.first], perm[c.second]);
      return true;
    }
  return false;
}

void SolverCore::clear_results(const TargetRange &t) {
  for (std::size_t k = t.begin; k < t.end; ++k) sorted_pot[k] = sorted_ex[k] = sorted_ey[k] = sorted_ez[k] = 0.0;
}

// Upward pass: P2M at leaves (eq. (3.9)), M2M to parents (eq. (3.10)) (detail::upward_pass).
// Done for all nodes by every part: splitting the P2M would need the leaf multipoles summed
// over the parts, and at N = 200,000 that sum (~all nodes x expansion size doubles) cost more
// than the P2M it saved (doc/benchmarks.md, "2 MPI ranks").
void SolverCore::upward() { upward_pass(tree, sorted_q.data(), *ops, multipole); }

// M2L (eq. (3.11)) into the local expansions of the nodes that hold targets of this part.
void SolverCore::m2l(const TargetRange &t) {
  std::fill(has_local.begin(), has_local.end(), 0);
  for_target_nodes(t, [&](std::size_t i, const Node &A) {
    const std::uint32_t e0 = lists.m2l_offset[i], e1 = lists.m2l_offset[i + 1];
    double *Li = local_of(i);
    std::fill(Li, Li + expansion_size(), 0.0);
    if (e1 == e0) return;
    m2l_entries(*ops, A, lists, e0, e1, tree.nodes, multipole.data(), batch_m, batch_r, Li);
    has_local[i] = 1;
  });
}

// P2P (eq. (3.1)): per target, contributions in list order, so independent of the partition.
void SolverCore::p2p(const TargetRange &t) {
  const auto &xs = tree.xs, &ys = tree.ys, &zs = tree.zs;
  for_target_nodes(t, [&](std::size_t i, const Node &A) {
    p2p_entries(p2p_kernel, lists, i, t.first(A), t.last(A), xs.data(), ys.data(), zs.data(), tree.nodes, xs.data(), ys.data(),
                zs.data(), sorted_q.data(), sorted_pot.data(), sorted_ex.data(), sorted_ey.data(), sorted_ez.data());
  });
}

// Downward pass: L2L from the parent (eq. (3.12)), L2P at leaves (eq. (3.13)); with the
// gradient (evaluate_dipoles) L2P to degree 2 (doc/polarization.md, eq. (5.2)) into sorted_g.
void SolverCore::downward(const TargetRange &t, bool gradient) {
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
    if (!A.leaf()) return;
    const std::size_t a = t.first(A), b = t.last(A);
    if (gradient) {
      for (std::size_t k = a; k < b; ++k)
        ops->l2p_gradient(Li, Vec3{xs[k], ys[k], zs[k]} - A.center, sorted_pot[k], sorted_ex[k], sorted_ey[k],
                          sorted_ez[k], sorted_g.data() + 6 * k);
    } else {
      ops->l2p_batch(Li, A.center, b - a, xs.data() + a, ys.data() + a, zs.data() + a, sorted_pot.data() + a,
                     sorted_ex.data() + a, sorted_ey.data() + a, sorted_ez.data() + a);
    }
  });
}

// The image cells beyond the near block (doc/theory.md, eq. (4.1)): exact (eq. (4.6)) or the
// average field (eq. (4.7)).
void SolverCore::far_field(const TargetRange &t, int part, int nparts, const PartSum &sum) {
  if (!periodic()) return;
  const auto &xs = tree.xs, &ys = tree.ys, &zs = tree.zs;
  if (opts.farfield == FarField::Exact) {
    far.evaluate(n, xs.data(), ys.data(), zs.data(), sorted_q.data(), t.begin, t.end, sorted_pot.data(),
                 sorted_ex.data(), sorted_ey.data(), sorted_ez.data(), part, nparts, sum);
  } else if (opts.farfield == FarField::Average) {
    double blo, bhi;
    if (!average_bed(opts, inv_h, n, zs.data(), sorted_q.data(), slx, sly, blo, bhi)) return;
    double qsum = 0.0;  // as average_far_field() sums them
    for (std::size_t k = 0; k < n; ++k) qsum += sorted_q[k];
    add_average_far_field(qsum, blo, bhi, t);
  }
}

void SolverCore::add_average_far_field(double qsum, double blo, double bhi, const TargetRange &t) {
  // the potential part apart, for energy_potential() (eq. (4.10))
  std::fill(sorted_average_pot.begin() + t.begin, sorted_average_pot.begin() + t.end, 0.0);
  average_far_field_of_charge(qsum, tree.xs.data(), tree.ys.data(), tree.zs.data(), sx0, sy0, slx, sly, opts.images,
                              blo, bhi, t.begin, t.end, sorted_average_pot.data(), sorted_ex.data(),
                              sorted_ey.data(), sorted_ez.data());
  for (std::size_t k = t.begin; k < t.end; ++k) sorted_pot[k] += sorted_average_pot[k];
}

// to the caller's order, back from the length unit h: pot ~ 1/length, E ~ 1/length^2
void SolverCore::scatter(const TargetRange &t, double *pot, double *ex, double *ey, double *ez) const {
  const double fp = inv_h, fe = inv_h * inv_h;
  for (std::size_t k = t.begin; k < t.end; ++k) {
    const std::size_t i = tree.perm[k];
    pot[i] = fp * sorted_pot[k];
    ex[i] = fe * sorted_ex[k];
    ey[i] = fe * sorted_ey[k];
    ez[i] = fe * sorted_ez[k];
  }
}

void SolverCore::check_part(const char *what, int part, int nparts) {
  if (nparts < 1 || part < 0 || part >= nparts)
    throw std::invalid_argument(std::string("gcfmm: ") + what + " needs 0 <= part < nparts, got part " +
                                std::to_string(part) + " of " + std::to_string(nparts));
}

bool SolverCore::start_phases(int part, int nparts, TargetRange &t) {
  stats.t_upward = stats.t_m2l = stats.t_p2p = stats.t_downward = stats.t_far = 0.0;
  evaluated = true;
  last_range = TargetRange{};
  if (n == 0) return false;
  t = range_of(part, nparts);
  last_range = t;
  clear_results(t);
  return true;
}

void SolverCore::energy_potential(double *u) const {
  const bool average = periodic() && opts.farfield == FarField::Average;
  const auto &perm = tree.perm;
  for (std::size_t i = 0; i < n; ++i) u[i] = 0.0;
  for (std::size_t k = last_range.begin; k < last_range.end; ++k)
    u[perm[k]] = inv_h * (average ? sorted_pot[k] + sorted_average_pot[k] : sorted_pot[k]);
}

}  // namespace gcfmm
