// GRANULAR-CHARGED FMM core library (gcfmm): the phases of Solver::evaluate_dipoles, charges
// and point dipoles as sources, field gradients at the targets (doc/polarization.md, section 5;
// src/solver_impl.hpp). Tree, lists, M2L and L2L are those of evaluate().
#include "solver_impl.hpp"

namespace gcfmm {

using namespace detail;

bool SolverCore::sort_dipoles(const DipoleSources &src) {
  const auto &perm = tree.perm;
  for (auto *v : {&sorted_px, &sorted_py, &sorted_pz}) v->assign(n, 0.0);
  bool any = false;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = perm[k];
    sorted_q[k] = src.q ? src.q[i] : 0.0;
    if (!src.px) continue;
    // dipoles ~ charge x length: in units of h like the positions
    sorted_px[k] = src.px[i] * inv_h;
    sorted_py[k] = src.py[i] * inv_h;
    sorted_pz[k] = src.pz[i] * inv_h;
    any = any || sorted_px[k] != 0.0 || sorted_py[k] != 0.0 || sorted_pz[k] != 0.0;
  }
  return any;
}

void SolverCore::mark_targets(std::size_t targets) {
  node_has_target.clear();
  if (std::min(targets, n) != weighed_targets) weigh_leaves(targets);
  if (targets >= n) return;
  const auto &nodes = tree.nodes;
  node_has_target.assign(nodes.size(), 0);
  // children have larger indices than their parents: leaves first, then up
  for (std::size_t i = nodes.size(); i-- > 0;) {
    const Node &A = nodes[i];
    if (A.leaf())
      for (std::uint32_t k = A.begin; k < A.end && !node_has_target[i]; ++k) node_has_target[i] = tree.perm[k] < targets;
    if (node_has_target[i] && A.parent >= 0) node_has_target[A.parent] = 1;
  }
}

bool SolverCore::source_coincident_pair(std::size_t &i, std::size_t &j) const {
  const auto &perm = tree.perm;
  auto source = [&](std::size_t k) {
    return sorted_q[k] != 0.0 || sorted_px[k] != 0.0 || sorted_py[k] != 0.0 || sorted_pz[k] != 0.0;
  };
  for (const auto &c : coincident)
    if (source(c.first) || source(c.second)) {
      i = std::min(perm[c.first], perm[c.second]);
      j = std::max(perm[c.first], perm[c.second]);
      return true;
    }
  return false;
}

// P2P with dipole sources (and gradients): per target, contributions in list order.
void SolverCore::p2p_dipoles(const TargetRange &t, bool gradient) {
  const auto &xs = tree.xs, &ys = tree.ys, &zs = tree.zs;
  const double r2_min = kCoincidenceRadius * kCoincidenceRadius;
  for_target_nodes(t, [&](std::size_t i, const Node &) {
    const std::size_t a = t.first(tree.nodes[i]), b = t.last(tree.nodes[i]);
    for (std::uint32_t e = lists.p2p_offset[i]; e < lists.p2p_offset[i + 1]; ++e) {
      const Interaction &it = lists.p2p[e];
      const Node &B = tree.nodes[it.source];
      const Vec3 &sh = lists.shifts[it.shift];
      const std::size_t s = B.begin;
      gcfmm::p2p_dipoles(b - a, xs.data() + a, ys.data() + a, zs.data() + a, B.count(), xs.data() + s,
                         ys.data() + s, zs.data() + s, sorted_q.data() + s, sorted_px.data() + s,
                         sorted_py.data() + s, sorted_pz.data() + s, sh.x, sh.y, sh.z, sorted_pot.data() + a,
                         sorted_ex.data() + a, sorted_ey.data() + a, sorted_ez.data() + a,
                         gradient ? sorted_g.data() + 6 * a : nullptr, r2_min);
    }
  });
}

void SolverCore::far_field_dipoles(const TargetRange &t, bool gradient) {
  if (!periodic() || opts.farfield != FarField::Exact) return;
  far.evaluate_dipoles(n, tree.xs.data(), tree.ys.data(), tree.zs.data(), sorted_q.data(), sorted_px.data(),
                       sorted_py.data(), sorted_pz.data(), t.begin, t.end, sorted_pot.data(), sorted_ex.data(),
                       sorted_ey.data(), sorted_ez.data(), gradient ? sorted_g.data() : nullptr);
}

// back from the length unit h: pot ~ 1/length, E ~ 1/length^2, G ~ 1/length^3
void SolverCore::scatter_dipoles(const TargetRange &t, const FieldOutputs &out) const {
  scatter(t, out.pot, out.ex, out.ey, out.ez);
  // the results of particles that are not targets are partial: zero them
  if (out.targets < n)
    for (std::size_t k = t.begin; k < t.end; ++k)
      if (tree.perm[k] >= out.targets) {
        const std::size_t i = tree.perm[k];
        out.pot[i] = out.ex[i] = out.ey[i] = out.ez[i] = 0.0;
      }
  if (!out.gradient) return;
  const double fg = inv_h * inv_h * inv_h;
  for (std::size_t k = t.begin; k < t.end; ++k) {
    double *g = out.gradient + 6 * tree.perm[k];
    const double f = tree.perm[k] < out.targets ? fg : 0.0;
    for (int c = 0; c < 6; ++c) g[c] = f * sorted_g[6 * k + c];
  }
}

}  // namespace gcfmm

void gcfmm::Solver::evaluate_dipoles(const DipoleSources &src, const FieldOutputs &out, int part, int nparts) {
  using namespace detail;
  Impl &I = *impl_;
  if (!I.built) throw std::runtime_error("gcfmm: evaluate_dipoles() called before build()");
  SolverCore::check_part("evaluate_dipoles()", part, nparts);
  if (I.periodic() && I.opts.farfield == FarField::Average)
    throw std::invalid_argument("gcfmm: evaluate_dipoles() has no average far field (its smeared images are "
                                "of charges only): use FarField::Exact or None");
  const std::size_t n = I.n;
  if (n > 0 && (!out.pot || !out.ex || !out.ey || !out.ez))
    throw std::invalid_argument("gcfmm: evaluate_dipoles() got a null output array");
  if (n > 0 && (!src.px) != (!src.py || !src.pz))
    throw std::invalid_argument("gcfmm: evaluate_dipoles() needs all three dipole arrays or none");
  if (out.gradient && I.res.order < 2)
    throw std::invalid_argument("gcfmm: evaluate_dipoles() needs order >= 2 for the field gradient, got " +
                                std::to_string(I.res.order));
  I.evaluated = false;
  I.sort_dipoles(src);
  I.mark_targets(out.targets);
  std::size_t first, second;
  if (I.source_coincident_pair(first, second)) throw coincidence_error(first, second, I.h);
  const bool gradient = out.gradient != nullptr;
  for (std::size_t i = 0; i < n; ++i) {
    out.pot[i] = out.ex[i] = out.ey[i] = out.ez[i] = 0.0;
    if (gradient)
      for (int c = 0; c < 6; ++c) out.gradient[6 * i + c] = 0.0;
  }
  TargetRange t;
  if (!I.start_phases(part, nparts, t)) return;
  Stats &s = I.stats;
  if (gradient) I.sorted_g.assign(6 * n, 0.0);
  s.t_upward = timed([&] {
    upward_pass(I.tree, I.sorted_q.data(), *I.ops, I.multipole, nullptr, I.sorted_px.data(), I.sorted_py.data(),
                I.sorted_pz.data());
  });
  s.t_m2l = timed([&] { I.m2l(t); });
  s.t_p2p = timed([&] { I.p2p_dipoles(t, gradient); });
  s.t_downward = timed([&] { I.downward(t, gradient); });
  s.t_far = timed([&] { I.far_field_dipoles(t, gradient); });
  I.scatter_dipoles(t, out);
}
