// GRANULAR-CHARGED FMM core library (gcfmm): the solvers behind one interface
// (include/gcfmm/coulomb_backend.hpp).
#include "gcfmm/coulomb_backend.hpp"

#include <algorithm>

namespace gcfmm {

namespace {
// the parameters that Stats and DistributedStats name alike
template <class S>
BackendStats parameters(const S &st) {
  BackendStats b;
  b.estimated_error = st.estimated_error;
  b.order = st.order;
  b.theta = st.theta;
  b.leaf = st.leaf;
  b.m2l = static_cast<double>(st.m2l_count);
  b.p2p = static_cast<double>(st.p2p_pairs);
  return b;
}
}  // namespace

void CoulombBackend::share(std::size_t n, std::size_t &first, std::size_t &last) const {
  first = 0;
  last = n;
}

// ---- replicated ----

ReplicatedBackend::ReplicatedBackend(const Options &opts, int part, int nparts, PartSum sum)
    : solver_(opts), part_(part), nparts_(nparts), sum_(std::move(sum)) {}

void ReplicatedBackend::set_box(double xlo, double ylo, double lx, double ly) { solver_.set_box(xlo, ylo, lx, ly); }

void ReplicatedBackend::set_z_range(double zlo, double zhi) { solver_.set_z_range(zlo, zhi); }

void ReplicatedBackend::evaluate(const BackendInput &in, const BackendOutput &out) {
  solver_.build(in.n, in.x, in.y, in.z);
  solver_.evaluate(in.q, out.pot, out.ex, out.ey, out.ez, part_, nparts_, sum_);
}

void ReplicatedBackend::energy_potential(double *u) const { solver_.energy_potential(u); }

BackendStats ReplicatedBackend::stats() const {
  BackendStats b = parameters(solver_.stats());
  b.counts_whole = true;
  b.memory_bytes = static_cast<double>(solver_.memory_bytes());
  return b;
}

void ReplicatedBackend::share(std::size_t n, std::size_t &first, std::size_t &last) const {
  first = n * part_ / nparts_;
  last = n * (part_ + 1) / nparts_;
}

// ---- distributed ----

DistributedBackend::DistributedBackend(const Options &opts, Communicator &comm) : solver_(opts, comm) {}

void DistributedBackend::set_box(double xlo, double ylo, double lx, double ly) { solver_.set_box(xlo, ylo, lx, ly); }

void DistributedBackend::set_z_range(double zlo, double zhi) { solver_.set_z_range(zlo, zhi); }

void DistributedBackend::evaluate(const BackendInput &in, const BackendOutput &out) {
  solver_.evaluate(in.n, in.x, in.y, in.z, in.q, in.ids, out.pot, out.ex, out.ey, out.ez);
}

void DistributedBackend::energy_potential(double *u) const { solver_.energy_potential(u); }

BackendStats DistributedBackend::stats() const {
  BackendStats b = parameters(solver_.stats());
  b.counts_whole = false;
  b.memory_bytes = static_cast<double>(solver_.stats().memory_bytes);
  return b;
}

// ---- polarizable ----

PolarizableBackend::PolarizableBackend(const Options &opts, bool dipoles) : solver_(opts, dipoles) {}

void PolarizableBackend::set_box(double xlo, double ylo, double lx, double ly) { solver_.set_box(xlo, ylo, lx, ly); }

void PolarizableBackend::set_z_range(double zlo, double zhi) { solver_.set_z_range(zlo, zhi); }

void PolarizableBackend::evaluate(const BackendInput &in, const BackendOutput &out) {
  solver_.compute(in.n, in.x, in.y, in.z, in.q, in.alpha, in.p, last_);
  charges_.assign(in.q, in.q + in.n);
  for (std::size_t k = 0; k < in.n; ++k) {
    if (out.ex) out.ex[k] = last_.field[3 * k];
    if (out.ey) out.ey[k] = last_.field[3 * k + 1];
    if (out.ez) out.ez[k] = last_.field[3 * k + 2];
  }
  if (out.force) std::copy(last_.force.begin(), last_.force.end(), out.force);
  if (out.energy) std::copy(last_.energy.begin(), last_.energy.end(), out.energy);
  if (out.pot) energy_potential(out.pot);
}

void PolarizableBackend::energy_potential(double *u) const {
  for (std::size_t k = 0; k < charges_.size(); ++k)
    u[k] = charges_[k] != 0.0 ? 2.0 * last_.energy[k] / charges_[k] : 0.0;
}

BackendStats PolarizableBackend::stats() const {
  BackendStats b = parameters(solver_.stats());
  b.counts_whole = true;
  const PolarizationReport &rep = solver_.report();
  b.iterations = rep.iterations;
  b.residual = rep.residual;
  b.converged = rep.converged;
  return b;
}

}  // namespace gcfmm
