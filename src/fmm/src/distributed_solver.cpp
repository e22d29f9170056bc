// GRANULAR-CHARGED FMM core library (gcfmm): the distributed solver (include/gcfmm/
// distributed_solver.hpp; method and collectives: doc/fmm-distributed.md). This rank's own
// particles go through the phases of detail::SolverCore; the remote sources (received LETs)
// are added between them.
#include "distributed_impl.hpp"

#include <limits>

namespace gcfmm {

using namespace detail;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Runs the data-dependent steps of one evaluate(): after the first exception the remaining
// steps are skipped, but the caller still makes every collective call; rethrow() at the end.
class Deferred {
 public:
  template <class F>
  void run(F &&f) {
    if (error_) return;
    try {
      f();
    } catch (...) {
      error_ = std::current_exception();
    }
  }
  void fail(std::exception_ptr e) {
    if (!error_) error_ = e;
  }
  bool failed() const { return static_cast<bool>(error_); }
  void rethrow() const {
    if (error_) std::rethrow_exception(error_);
  }

 private:
  std::exception_ptr error_;
};

}  // namespace

DistributedSolver::DistributedSolver(const Options &opts, Communicator &comm) : impl_(new Impl(comm)) {
  SolverCore &c = impl_->core;
  c.configure(opts);
  DistributedStats &s = impl_->stats;
  s.order = c.stats.order;
  s.theta = c.stats.theta;
  s.leaf = c.stats.leaf;
  s.estimated_error = c.stats.estimated_error;
}

DistributedSolver::~DistributedSolver() = default;

void DistributedSolver::set_box(double xlo, double ylo, double lx, double ly) { impl_->core.set_box(xlo, ylo, lx, ly); }

void DistributedSolver::set_z_range(double zlo, double zhi) { impl_->core.set_z_range(zlo, zhi); }

const DistributedStats &DistributedSolver::stats() const { return impl_->stats; }
const Options &DistributedSolver::options() const { return impl_->core.opts; }

void DistributedSolver::energy_potential(double *u) const {
  const Impl &I = *impl_;
  if (!I.evaluated) throw std::runtime_error("gcfmm: energy_potential() called before evaluate()");
  if (I.core.n > 0 && !u) throw std::invalid_argument("gcfmm: energy_potential() got a null array");
  I.core.energy_potential(u);
}

void DistributedSolver::Impl::record_coincidence(std::int64_t a, std::int64_t b) {
  if (coincident) return;
  coincident = true;
  coincident_first = std::min(a, b);
  coincident_second = std::max(a, b);
}

// charged[i]: the number of nonzero charges in node i of this rank's tree (only nodes with
// charge are sent)
void DistributedSolver::Impl::mark_charged_nodes() {
  const auto &nodes = core.tree.nodes;
  charged.assign(nodes.size(), 0);
  for (std::size_t i = nodes.size(); i-- > 0;) {
    const Node &A = nodes[i];
    if (A.leaf())
      for (std::uint32_t k = A.begin; k < A.end; ++k) charged[i] += core.sorted_q[k] != 0.0 ? 1 : 0;
    if (A.parent >= 0) charged[A.parent] += charged[i];
  }
}

void DistributedSolver::Impl::build_remote_lists() {
  build_lists(core.tree, let.tree, core.lists.shifts, core.res.theta, m2l_cost(core.res.order, core.ops->simd_path()),
              remote, &let.multipole_only);
}

// A remote particle within the coincidence radius of one of this rank's particles lies in a
// node the sender did not truncate (eq. (D.1)), and the two leaves are then too close for the
// MAC: their pair is in the remote P2P list (as in SolverCore::find_coincident_pairs, an
// accepted pair that close would need nodes smaller than the radius holding more particles
// than the P2P threshold, and so coincident pairs the sender finds itself).
void DistributedSolver::Impl::find_remote_coincidences() {
  const auto &nodes = core.tree.nodes;
  const auto &xs = core.tree.xs, &ys = core.tree.ys, &zs = core.tree.zs;
  const double r2 = kCoincidenceRadius * kCoincidenceRadius;
  for (std::size_t i = 0; i < nodes.size() && !coincident; ++i)
    for (std::uint32_t e = remote.p2p_offset[i]; e < remote.p2p_offset[i + 1]; ++e) {
      const Interaction &it = remote.p2p[e];
      const Node &A = nodes[i], &B = let.tree.nodes[it.source];
      const Vec3 &s = remote.shifts[it.shift];
      for (std::uint32_t a = A.begin; a < A.end; ++a) {
        auto d2 = [&](std::uint32_t b) {
          const double dx = xs[a] - let.tree.xs[b] - s.x, dy = ys[a] - let.tree.ys[b] - s.y,
                       dz = zs[a] - let.tree.zs[b] - s.z;
          return dx * dx + dy * dy + dz * dz;
        };
        double dmin = 2.0 * r2;  // a vectorisable scan first
#pragma omp simd reduction(min : dmin)
        for (std::uint32_t b = B.begin; b < B.end; ++b) dmin = std::min(dmin, d2(b));
        if (dmin > r2) continue;
        for (std::uint32_t b = B.begin; b < B.end; ++b)
          if (d2(b) <= r2) {
            record_coincidence(sorted_ids[a], let.ids[b]);
            return;
          }
      }
    }
}

// M2L (eq. (3.11)) from the received multipoles, added to the local expansions of the own tree
void DistributedSolver::Impl::remote_m2l() {
  const auto &nodes = core.tree.nodes;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const std::uint32_t e0 = remote.m2l_offset[i], e1 = remote.m2l_offset[i + 1];
    if (e1 == e0) continue;
    m2l_entries(*core.ops, nodes[i], remote, e0, e1, let.tree.nodes, let.multipole.data(), core.batch_m,
                core.batch_r, core.local_of(i));
    core.has_local[i] = 1;
  }
}

// P2P (eq. (3.1)) from the received particles, then M2P from the truncated received nodes at
// the particles of the target leaves
void DistributedSolver::Impl::remote_p2p_m2p() {
  SolverCore &c = core;
  const auto &nodes = c.tree.nodes;
  const double *xs = c.tree.xs.data(), *ys = c.tree.ys.data(), *zs = c.tree.zs.data();
  double *pot = c.sorted_pot.data(), *ex = c.sorted_ex.data(), *ey = c.sorted_ey.data(), *ez = c.sorted_ez.data();
  stats.m2p_count = 0;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const Node &A = nodes[i];
    p2p_entries(c.p2p_kernel, remote, i, A.begin, A.end, xs, ys, zs, let.tree.nodes, let.tree.xs.data(), let.tree.ys.data(),
                let.tree.zs.data(), let.q.data(), pot, ex, ey, ez);
    for (std::uint32_t e = remote.m2p_offset[i]; e < remote.m2p_offset[i + 1]; ++e) {
      const Interaction &it = remote.m2p[e];
      const Node &B = let.tree.nodes[it.source];
      c.ops->m2p_batch(let.multipole.data() + it.source * c.expansion_size(), B.center + remote.shifts[it.shift],
                       A.count(), xs + A.begin, ys + A.begin, zs + A.begin, pot + A.begin, ex + A.begin,
                       ey + A.begin, ez + A.begin);
      stats.m2p_count += A.count();
    }
  }
}

std::size_t DistributedSolver::Impl::memory_bytes() const {
  // the own solver's state (SolverCore::memory_bytes), plus the remote lists, the received LETs,
  // the far field's node potentials, the ranks' boxes and the exchange buffers
  std::size_t b = core.memory_bytes() + lists_bytes(remote) + let.memory_bytes() + vector_bytes(phi) +
                  vector_bytes(boxes) + vector_bytes(sorted_ids) + vector_bytes(charged);
  for (const auto *buffers : {&send, &recv})
    for (const auto &v : *buffers) b += vector_bytes(v);
  return b;
}

void DistributedSolver::evaluate(std::size_t n, const double *x, const double *y, const double *z, const double *q,
                                 const std::int64_t *ids, double *pot, double *ex, double *ey, double *ez) {
  Impl &I = *impl_;
  SolverCore &c = I.core;
  Communicator &comm = I.comm;
  // known identically on every rank: may throw before the collectives
  if (c.periodic() && !c.box_set) throw std::runtime_error("gcfmm: Periodic2D needs set_box() before evaluate()");
  Deferred deferred;
  if (n > 0 && (!x || !y || !z || !q || !ids || !pot || !ex || !ey || !ez)) {
    deferred.fail(std::make_exception_ptr(std::invalid_argument("gcfmm: evaluate() got a null array")));
    n = 0;  // take part in the collectives with no particles
  }
  I.evaluated = false;
  I.coincident = false;
  I.let.clear();
  I.remote = InteractionLists{};
  DistributedStats &s = I.stats;
  s.t_tree = s.t_upward = s.t_let = s.t_m2l = s.t_p2p = s.t_downward = s.t_far = 0.0;

  // 1. global geometry (collective 1): maxima of (-min, max) of the positions and of the
  // charged particles' z (the automatic bed of FarField::Average)
  double geo[8] = {-kInf, -kInf, -kInf, -kInf, -kInf, -kInf, -kInf, -kInf};
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(x[i]) || !std::isfinite(y[i]) || !std::isfinite(z[i])) {
      deferred.fail(std::make_exception_ptr(std::runtime_error("gcfmm: non-finite particle position")));
      std::fill(geo, geo + 8, -kInf);
      n = 0;
      break;
    }
    const double p[3] = {x[i], y[i], z[i]};
    for (int k = 0; k < 3; ++k) {
      geo[k] = std::max(geo[k], -p[k]);
      geo[3 + k] = std::max(geo[3 + k], p[k]);
    }
    if (q[i] != 0.0) {
      geo[6] = std::max(geo[6], -z[i]);
      geo[7] = std::max(geo[7], z[i]);
    }
  }
  s.t_tree = timed([&] { comm.allreduce_max(geo, 8); });
  const bool any_particle = geo[5] > -kInf;

  // 2. this rank's tree in the global unit, local lists, far-field set-up, upward pass
  c.n = n;
  s.t_tree += timed([&] {
    double extent = 0.0;  // as SolverCore::choose_length_unit, over all ranks' particles
    if (!c.periodic() && any_particle) extent = std::max({geo[3] + geo[0], geo[4] + geo[1], geo[5] + geo[2]});
    c.set_length_unit(c.periodic() ? length_unit(std::max(c.lx, c.ly)) : length_unit(extent));
    deferred.run([&] {
      c.build_scaled_tree(x, y, z);
      c.build_after_tree();
    });
    // the far-field operator depends on the global geometry only: the same on every rank
    c.zmin = any_particle ? -geo[2] * c.inv_h : 0.0;
    c.zmax = any_particle ? geo[5] * c.inv_h : 0.0;
    c.stats.estimated_error = c.res.estimated_error;
    try {
      c.setup_far_field();
    } catch (...) {
      deferred.fail(std::current_exception());
    }
    s.estimated_error = c.stats.estimated_error;
  });
  if (deferred.failed()) c.n = 0;
  deferred.run([&] {
    c.sort_charges(q);
    I.sorted_ids.resize(c.n);
    for (std::size_t k = 0; k < c.n; ++k) I.sorted_ids[k] = ids[c.tree.perm[k]];
    std::size_t i, j;
    if (c.charged_coincident_pair(i, j)) I.record_coincidence(ids[i], ids[j]);
    s.t_upward = timed([&] { c.upward(); });
    I.mark_charged_nodes();
  });

  // 3. every rank's target box (collective 2), in units of h
  const auto P = static_cast<std::size_t>(comm.size());
  const int self = comm.rank();
  double mine[6] = {kInf, kInf, kInf, -kInf, -kInf, -kInf};
  if (!deferred.failed() && c.n > 0) {
    const auto &t = c.tree;
    for (int k = 0; k < 3; ++k) {
      const auto &v = k == 0 ? t.xs : (k == 1 ? t.ys : t.zs);
      const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
      mine[k] = *lo;
      mine[3 + k] = *hi;
    }
  }
  I.boxes.resize(6 * P);
  s.t_let = timed([&] { comm.allgather(mine, 6, I.boxes.data()); });

  // 4. the LET for every other rank, exchanged (collective 3)
  s.t_let += timed([&] {
    I.send.resize(P);
    for (auto &b : I.send) b.clear();
    deferred.run([&] {
      for (std::size_t r = 0; r < P; ++r) {
        if (static_cast<int>(r) == self) continue;
        Box box;
        for (int k = 0; k < 3; ++k) {
          box.lo[k] = I.boxes[6 * r + k];
          box.hi[k] = I.boxes[6 * r + 3 + k];
        }
        pack_let(c.tree, I.charged, c.multipole.data(), c.sorted_q.data(), I.sorted_ids.data(), *c.ops, box,
                 c.lists.shifts, c.res.theta, I.send[r]);
      }
    });
    comm.alltoallv(I.send, I.recv);
    s.bytes_sent = s.bytes_received = 0;
    for (std::size_t r = 0; r < P; ++r) {
      s.bytes_sent += I.send[r].size();
      if (static_cast<int>(r) != self && r < I.recv.size()) s.bytes_received += I.recv[r].size();
    }
    deferred.run([&] {
      unpack_lets(I.recv, self, *c.ops, I.let);
      I.build_remote_lists();
      I.find_remote_coincidences();
    });
  });
  s.let_nodes_received = I.let.nodes_received;
  s.let_particles_received = I.let.particles_received;

  // 5. near field of local and remote sources (no collective)
  const TargetRange all{0, c.n};
  deferred.run([&] {
    c.clear_results(all);
    s.t_m2l = timed([&] {
      c.m2l(all);
      I.remote_m2l();
    });
    s.t_p2p = timed([&] {
      c.p2p(all);
      I.remote_p2p_m2p();
    });
    s.t_downward = timed([&] { c.downward(all); });
  });

  // 6. far field (collective 4, periodic only): node potentials or total charge summed
  s.t_far = timed([&] {
    if (!c.periodic()) return;
    const auto &xs = c.tree.xs, &ys = c.tree.ys, &zs = c.tree.zs;
    if (c.opts.farfield == FarField::Exact) {
      // every rank's set-up is the same: the same number of node potentials
      const std::size_t count = c.far.ready() ? static_cast<std::size_t>(c.far.order_xy()) * c.far.order_xy() *
                                                    c.far.order_z() * c.far.boxes()
                                              : 0;
      I.phi.assign(count, 0.0);
      deferred.run([&] { c.far.node_potentials(c.n, xs.data(), ys.data(), zs.data(), c.sorted_q.data(), I.phi); });
      if (I.phi.size() != count) I.phi.assign(count, 0.0);
      comm.allreduce_sum(I.phi.data(), count);
      deferred.run([&] {
        c.far.interpolate_at(I.phi, c.n, xs.data(), ys.data(), zs.data(), c.sorted_pot.data(), c.sorted_ex.data(),
                             c.sorted_ey.data(), c.sorted_ez.data());
      });
    } else if (c.opts.farfield == FarField::Average) {
      double qsum = 0.0;  // in tree order, as SolverCore::far_field
      if (!deferred.failed())
        for (std::size_t k = 0; k < c.n; ++k) qsum += c.sorted_q[k];
      comm.allreduce_sum(&qsum, 1);
      // the bed: given, or the z range of all ranks' charged particles (average_bed)
      double blo = c.opts.bed_zlo * c.inv_h, bhi = c.opts.bed_zhi * c.inv_h;
      if (std::isnan(blo)) {
        if (!(geo[7] > -kInf)) return;  // no charge anywhere: no far field
        blo = -geo[6] * c.inv_h;
        bhi = geo[7] * c.inv_h;
      }
      thicken_bed(c.slx, c.sly, blo, bhi);
      deferred.run([&] { c.add_average_far_field(qsum, blo, bhi, all); });
    }
  });

  // after the last collective: results, then this rank's errors
  s.m2l_count = c.lists.m2l.size() + I.remote.m2l.size();
  s.p2p_pairs = c.lists.p2p_pairs + I.remote.p2p_pairs;
  s.nodes = c.tree.nodes.size();
  s.memory_bytes = I.memory_bytes();
  deferred.rethrow();
  if (I.coincident)
    throw coincidence_error(static_cast<std::size_t>(I.coincident_first), static_cast<std::size_t>(I.coincident_second),
                            c.h);
  c.last_range = all;
  c.scatter(all, pot, ex, ey, ez);
  I.evaluated = true;
}

}  // namespace gcfmm
