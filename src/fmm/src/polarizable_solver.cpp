// GRANULAR-CHARGED FMM core library (gcfmm): charged, polarizable particles by the FMM
// (polarizable_solver.hpp; doc/polarization.md, section 5).
#include "gcfmm/polarizable_solver.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "gcfmm/dipole_kernels.hpp"

namespace gcfmm {

namespace {
Options expansion_options(Options opts, bool dipoles) {
  if (dipoles && opts.order <= 0) opts.accuracy /= dipole_accuracy_margin(opts.accuracy);
  return opts;
}
}  // namespace

PolarizableSolver::PolarizableSolver(const Options &opts, bool dipoles) : solver_(expansion_options(opts, dipoles)) {
  PolarizationSettings s;
  s.tolerance = gcfmm::induction_tolerance(opts);
  set_induction(s);
}

void PolarizableSolver::set_box(double xlo, double ylo, double lx, double ly) { solver_.set_box(xlo, ylo, lx, ly); }

void PolarizableSolver::set_z_range(double zlo, double zhi) {
  if (env_.electrode) zlo = std::min(zlo, 2.0 * env_.electrode_z - zhi);
  solver_.set_z_range(zlo, zhi);
}

void PolarizableSolver::set_environment(const PolarizableEnvironment &env) {
  const Vec3 &e = env.applied_field;
  if (!std::isfinite(e.x) || !std::isfinite(e.y) || !std::isfinite(e.z) || !std::isfinite(env.electrode_z))
    throw std::invalid_argument("gcfmm: the applied field and the electrode position must be finite");
  env_ = env;
}

void PolarizableSolver::set_induction(const PolarizationSettings &settings) {
  if (!(settings.tolerance > 0.0) || settings.max_iterations < 1)
    throw std::invalid_argument("gcfmm: the induction needs a tolerance > 0 and max_iterations >= 1");
  // iterate to a quarter of the tolerance, accept a start within it: a start extrapolated from
  // the last two solutions (errors up to ~3/4 of the tolerance, plus the motion's) is accepted
  induction_ = settings;
  induction_.accept_start = settings.tolerance;
  induction_.tolerance = 0.25 * settings.tolerance;
}

void PolarizableSolver::set_partition(int part, int nparts, PartSum sum) {
  if (nparts < 1 || part < 0 || part >= nparts || (nparts > 1 && !sum))
    throw std::invalid_argument("gcfmm: PolarizableSolver::set_partition needs 0 <= part < nparts and a sum "
                                "for nparts > 1");
  part_ = part;
  nparts_ = nparts;
  sum_ = std::move(sum);
}

void PolarizableSolver::evaluate(const double *p, bool charges, bool gradient) {
  ++evaluations_;
  const std::size_t ns = sx_.size();
  if (p) {
    for (std::size_t i = 0; i < n_; ++i) {
      spx_[i] = p[3 * i];
      spy_[i] = p[3 * i + 1];
      spz_[i] = p[3 * i + 2];
      if (ns > n_) {
        const Vec3 img = image_dipole({spx_[i], spy_[i], spz_[i]});
        spx_[n_ + i] = img.x;
        spy_[n_ + i] = img.y;
        spz_[n_ + i] = img.z;
      }
    }
  }
  DipoleSources src;
  if (charges) src.q = sq_.data();
  if (p) {
    src.px = spx_.data();
    src.py = spy_.data();
    src.pz = spz_.data();
  }
  g_.resize(gradient ? 6 * ns : 0);
  // the images are sources only
  solver_.evaluate_dipoles(src, {pot_.data(), ex_.data(), ey_.data(), ez_.data(), gradient ? g_.data() : nullptr, n_},
                           part_, nparts_);
  if (nparts_ == 1) return;
  // the parts' results of the n particles, in one sum
  const std::size_t per = gradient ? 10 : 4;
  buffer_.resize(per * n_);
  for (std::size_t i = 0; i < n_; ++i) {
    double *b = buffer_.data() + per * i;
    b[0] = pot_[i];
    b[1] = ex_[i];
    b[2] = ey_[i];
    b[3] = ez_[i];
    for (std::size_t c = 4; c < per; ++c) b[c] = g_[6 * i + c - 4];
  }
  sum_(buffer_.data(), buffer_.size());
  for (std::size_t i = 0; i < n_; ++i) {
    const double *b = buffer_.data() + per * i;
    pot_[i] = b[0];
    ex_[i] = b[1];
    ey_[i] = b[2];
    ez_[i] = b[3];
    for (std::size_t c = 4; c < per; ++c) g_[6 * i + c - 4] = b[c];
  }
}

void PolarizableSolver::compute(std::size_t n, const double *x, const double *y, const double *z, const double *q,
                                const double *alpha, double *p, PolarizableOutputs &out) {
  if (env_.electrode)
    for (std::size_t i = 0; i < n; ++i)
      if (!(z[i] > env_.electrode_z))
        throw std::invalid_argument("gcfmm: particle " + std::to_string(i) + " is not above the electrode (z = " +
                                    std::to_string(z[i]) + " <= " + std::to_string(env_.electrode_z) + ")");
  n_ = n;
  const std::size_t ns = env_.electrode ? 2 * n : n;
  for (auto *v : {&sx_, &sy_, &sz_, &sq_, &spx_, &spy_, &spz_, &pot_, &ex_, &ey_, &ez_}) v->assign(ns, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    sx_[i] = x[i];
    sy_[i] = y[i];
    sz_[i] = z[i];
    sq_[i] = q[i];
    if (ns > n) {
      const Vec3 m = mirror_point({x[i], y[i], z[i]}, env_.electrode_z);
      sx_[n + i] = m.x;
      sy_[n + i] = m.y;
      sz_[n + i] = m.z;
      sq_[n + i] = image_charge(q[i]);
    }
  }
  solver_.build(ns, sx_.data(), sy_.data(), sz_.data());

  const Vec3 &ea = env_.applied_field;
  report_ = PolarizationReport{};
  if (!alpha)
    for (std::size_t k = 0; k < 3 * n; ++k) p[k] = 0.0;
  // one evaluation of the charges and the starting dipoles: the local field E0 + T p of the
  // induction's start (no evaluation of E0 apart)
  // the start's evaluation carries the gradient when the last step's start was already the
  // solution (a predicted warm start often is): then it is also the forces' evaluation
  const bool start_is_final = alpha && start_converged_;
  evaluations_ = 0;
  if (alpha) {
    evaluate(p, true, start_is_final);
    std::vector<double> local(3 * n);
    for (std::size_t i = 0; i < n; ++i) {
      local[3 * i] = ex_[i] + ea.x;
      local[3 * i + 1] = ey_[i] + ea.y;
      local[3 * i + 2] = ez_[i] + ea.z;
    }
    const DipoleFieldOperator field = [&](const double *pv, double *f) {
      evaluate(pv, false, false);
      for (std::size_t i = 0; i < n; ++i) {
        f[3 * i] = ex_[i];
        f[3 * i + 1] = ey_[i];
        f[3 * i + 2] = ez_[i];
      }
    };
    report_ = solve_induced_dipoles_from(n, alpha, local.data(), field, p, induction_);
    start_converged_ = report_.iterations == 0;
    report_.iterations += 1;  // the first evaluation
  } else {
    report_.converged = true;
    start_converged_ = false;
  }
  // the field and its gradient with the converged dipoles
  if (!(start_is_final && start_converged_)) evaluate(alpha ? p : nullptr, true, true);

  out.field.assign(3 * n, 0.0);
  out.force.assign(3 * n, 0.0);
  out.energy.assign(n, 0.0);
  energy_ = 0.0;
  const Vec3 origin{0.0, 0.0, env_.electrode ? env_.electrode_z : 0.0};
  for (std::size_t i = 0; i < n; ++i) {
    PointField f;
    f.e = Vec3{ex_[i], ey_[i], ez_[i]} + ea;
    const double *g = g_.data() + 6 * i;
    f.g = SymTensor{g[0], g[1], g[2], g[3], g[4], g[5]};
    const Vec3 pi{p[3 * i], p[3 * i + 1], p[3 * i + 2]};
    const Vec3 force = point_force(q[i], pi, f);
    double *fi = out.field.data() + 3 * i, *Fi = out.force.data() + 3 * i;
    fi[0] = f.e.x;
    fi[1] = f.e.y;
    fi[2] = f.e.z;
    Fi[0] = force.x;
    Fi[1] = force.y;
    Fi[2] = force.z;
    out.energy[i] = polarizable_energy_term(q[i], pot_[i], ea, Vec3{x[i], y[i], z[i]} - origin, pi);
    energy_ += out.energy[i];
  }
}

}  // namespace gcfmm
