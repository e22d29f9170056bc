// GRANULAR-CHARGED FMM core library (gcfmm): the solver's public interface; its phases are
// in solver_build.cpp and solver_evaluate.cpp (src/solver_impl.hpp).
#include "solver_impl.hpp"

namespace gcfmm {

using namespace detail;

Solver::Solver(const Options &opts) : impl_(new Impl) { impl_->configure(opts); }

Solver::~Solver() = default;

void Solver::energy_potential(double *u) const {
  const Impl &I = *impl_;
  if (!I.built || !I.evaluated) throw std::runtime_error("gcfmm: energy_potential() called before evaluate()");
  if (I.n > 0 && !u) throw std::invalid_argument("gcfmm: energy_potential() got a null array");
  I.energy_potential(u);
}

const Stats &Solver::stats() const { return impl_->stats; }
const Options &Solver::options() const { return impl_->opts; }
std::size_t Solver::size() const { return impl_->n; }
std::size_t Solver::memory_bytes() const { return impl_->memory_bytes(); }

void Solver::partition(int part, int nparts, std::size_t &first, std::size_t &last) const {
  if (!impl_->built) throw std::runtime_error("gcfmm: partition() called before build()");
  if (nparts < 1 || part < 0 || part >= nparts)
    throw std::invalid_argument("gcfmm: need 0 <= part < nparts, got part " + std::to_string(part) + " of " +
                                std::to_string(nparts));
  const TargetRange r = impl_->range_of(part, nparts);
  first = r.begin;
  last = r.end;
}

void Solver::set_box(double xlo, double ylo, double lx, double ly) { impl_->set_box(xlo, ylo, lx, ly); }

void Solver::set_z_range(double zlo, double zhi) { impl_->set_z_range(zlo, zhi); }

void Solver::build(std::size_t n, const double *x, const double *y, const double *z) {
  Impl &I = *impl_;
  if (I.periodic() && !I.box_set) throw std::runtime_error("gcfmm: Periodic2D needs set_box() before build()");
  if (n > 0 && (!x || !y || !z)) throw std::invalid_argument("gcfmm: build() got a null position array");
  I.built = false;
  I.n = n;
  I.stats.t_build = timed([&] {
    I.build_tree(x, y, z);
    I.build_after_tree();
    I.setup_far_field();
  });
  I.built = true;
  I.evaluated = false;
}

void Solver::evaluate(const double *q, double *pot, double *ex, double *ey, double *ez, int part, int nparts,
                      const PartSum &sum) {
  Impl &I = *impl_;
  if (!I.built) throw std::runtime_error("gcfmm: evaluate() called before build()");
  SolverCore::check_part("evaluate()", part, nparts);
  const std::size_t n = I.n;
  if (n > 0 && (!q || !pot || !ex || !ey || !ez)) throw std::invalid_argument("gcfmm: evaluate() got a null array");
  I.evaluated = false;
  I.sort_charges(q);
  std::size_t first, second;
  if (I.charged_coincident_pair(first, second)) throw coincidence_error(first, second, I.h);
  for (std::size_t i = 0; i < n; ++i) pot[i] = ex[i] = ey[i] = ez[i] = 0.0;
  TargetRange t;
  if (!I.start_phases(part, nparts, t)) return;
  Stats &s = I.stats;
  s.t_upward = timed([&] { I.upward(); });
  s.t_m2l = timed([&] { I.m2l(t); });
  s.t_p2p = timed([&] { I.p2p(t); });
  s.t_downward = timed([&] { I.downward(t); });
  s.t_far = timed([&] { I.far_field(t, part, nparts, sum); });

  I.scatter(t, pot, ex, ey, ez);
}

}  // namespace gcfmm
