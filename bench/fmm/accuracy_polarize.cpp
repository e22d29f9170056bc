// Delivered accuracy of gcfmm::PolarizableSolver in the deposition geometry (a measurement, not a
// test): forces and dipoles of charged, polarisable particles (applied field, grounded electrode,
// p p f) at each requested accuracy, as relative RMS errors against
//  (a) the same solver at accuracy 1e-11 with the exact far field (self-convergence), and
//  (b) for N up to --direct, the O(N^2) direct reference solve_polarizable_direct over the 3 x 3
//      block of cells with its images (the solver with far field none sums exactly that block):
//      an independent check, induction solved to 1e-12.
// Geometry: gcfmm_bench::deposition (bench_util.hpp), beta = 0.48 (eps_p = 3.8), applied field
// 0.05 along z (bare units), electrode at z = 0.
//
// usage: accuracy_polarize [--n N[,N...]] [--acc a[,a...]] [--direct Nmax]
#include "bench_util.hpp"

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "gcfmm/dipole_kernels.hpp"
#include "gcfmm/direct_polarizable.hpp"
#include "gcfmm/polarizable_solver.hpp"

using namespace gcfmm;

namespace {

Options options(double acc, FarField far) {
  Options o;
  o.accuracy = acc;
  o.boundary = Boundary::Periodic2D;
  o.farfield = far;
  o.images = 1;
  return o;
}

struct Solution {
  std::vector<double> force, dipole;  // 3 n each
};

Solution fmm(const gcfmm_bench::Bed &b, const std::vector<double> *alpha, const PolarizableEnvironment &env,
             double acc, FarField far, double induction) {
  PolarizableSolver ps(options(acc, far), alpha != nullptr);
  ps.set_box(0, 0, b.L, b.L);
  ps.set_environment(env);
  ps.set_z_range(0.0, 160.0);
  PolarizationSettings s;
  s.tolerance = induction;
  ps.set_induction(s);
  const std::size_t n = b.size();
  Solution out;
  out.dipole.assign(3 * n, 0.0);
  PolarizableOutputs o;
  ps.compute(n, b.x.data(), b.y.data(), b.z.data(), b.q.data(), alpha ? alpha->data() : nullptr,
             out.dipole.data(), o);
  out.force = o.force;
  return out;
}

Solution direct(const gcfmm_bench::Bed &b, const std::vector<double> &alpha, const PolarizableEnvironment &env) {
  PolarizableSystem sys = particles_of(b.size(), b.x.data(), b.y.data(), b.z.data(), b.q.data(), alpha.data());
  sys.applied_field = env.applied_field;
  sys.electrode = env.electrode;
  sys.electrode_z = env.electrode_z;
  sys.lx = sys.ly = b.L;
  sys.images = 1;
  PolarizationSettings s;
  s.tolerance = 1e-12;
  const PolarizableResult r = solve_polarizable_direct(sys, s);
  Solution out;
  for (std::size_t i = 0; i < sys.n; ++i) {
    const double f[3] = {r.force[i].x, r.force[i].y, r.force[i].z};
    const double p[3] = {r.dipole[i].x, r.dipole[i].y, r.dipole[i].z};
    out.force.insert(out.force.end(), f, f + 3);
    out.dipole.insert(out.dipole.end(), p, p + 3);
  }
  return out;
}

double rel_rms(const std::vector<double> &a, const std::vector<double> &ref) {
  double num = 0.0, den = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    num += (a[k] - ref[k]) * (a[k] - ref[k]);
    den += ref[k] * ref[k];
  }
  return den > 0.0 ? std::sqrt(num / den) : 0.0;
}

}  // namespace

int main(int argc, char **argv) {
  std::vector<std::size_t> ns{2000, 20000};
  std::vector<double> accs{1e-3, 1e-4, 1e-6};
  std::size_t direct_max = 2000;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string k = argv[i];
    if (k == "--n") ns = gcfmm_bench::list<std::size_t>(argv[i + 1]);
    else if (k == "--acc") accs = gcfmm_bench::list<double>(argv[i + 1]);
    else if (k == "--direct") direct_max = std::strtoul(argv[i + 1], nullptr, 10);
  }
  std::printf("# relative RMS errors of the forces (F) and dipoles (p): 'exact' against the solver at 1e-11\n"
              "# ('F q': charges, images and field without polarisation)\n"
              "# with the exact far field; 'block' (far field none) against the direct sum over the 3 x 3 cells\n");
  std::printf("%8s %9s %11s %11s %11s %11s %11s\n", "N", "accuracy", "F q exact", "F exact", "p exact", "F block",
              "p block");
  PolarizableEnvironment env;
  env.applied_field = {0.0, 0.0, 0.05};
  env.electrode = true;
  for (const std::size_t n : ns) {
    const gcfmm_bench::Bed b = gcfmm_bench::deposition(n, 7);
    const std::vector<double> alpha(n, polarizability(clausius_mossotti(3.8, 1.0), 1.0));
    const Solution ref = fmm(b, &alpha, env, 1e-11, FarField::Exact, 1e-12);
    const Solution ref_q = fmm(b, nullptr, env, 1e-11, FarField::Exact, 1e-12);
    const bool with_direct = n <= direct_max;
    Solution ref_block;
    if (with_direct) ref_block = direct(b, alpha, env);
    for (const double acc : accs) {
      const Solution s = fmm(b, &alpha, env, acc, FarField::Exact, 0.1 * acc);
      const Solution sq = fmm(b, nullptr, env, acc, FarField::Exact, 0.1 * acc);
      std::printf("%8zu %9.0e %11.3e %11.3e %11.3e", n, acc, rel_rms(sq.force, ref_q.force), rel_rms(s.force, ref.force),
                  rel_rms(s.dipole, ref.dipole));
      if (with_direct) {
        const Solution sb = fmm(b, &alpha, env, acc, FarField::None, 0.1 * acc);
        std::printf(" %11.3e %11.3e", rel_rms(sb.force, ref_block.force), rel_rms(sb.dipole, ref_block.dipole));
      }
      std::printf("\n");
      std::fflush(stdout);
    }
  }
  return 0;
}
