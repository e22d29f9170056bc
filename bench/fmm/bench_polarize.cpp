// Benchmark of gcfmm::PolarizableSolver (not a test): one evaluation with induced dipoles
// (`polarize`: applied field, CG induction, grounded electrode by images) against the
// charges-only Solver evaluation the fix does today, at the same requested accuracy.
//
// Geometry (deposition): lx = ly = 28 sqrt(N / 2000), radius-1 particles, 90% on a jittered
// simple cubic lattice of spacing 2.2 from z = 1.2 (the bed; volume fraction ~0.39, no
// overlaps), 10% at random above it up to z = 160 (at least 2.2 from every other); charges 1,
// beta = 0.48 (eps_p = 3.8, silica, in vacuum), applied field 0.05 along z (bare units), the
// electrode at z = 0. Periodic2D, images 1, far field exact, column [0, 160] by set_z_range.
// Columns, without and with the electrode: the charges-only evaluation (Solver::evaluate, or
// PolarizableSolver without alpha with the electrode's images), polarize from p = 0 (cold),
// polarize warm-started after every particle moved by up to --step per coordinate (a
// deposition step), polarize two steps later started from the dipoles extrapolated from the
// last two (2 p_n - p_{n-1}), with the FMM evaluations of each and the ratios.
//
// usage: bench_polarize [--n N[,N...]] [--acc a] [--reps r] [--step s]
// --step: the displacement (uniform in [-s, s] per coordinate) between the cold and the warm
// evaluation, in particle radii (default 0.01)
#include "bench_util.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "gcfmm/dipole_kernels.hpp"
#include "gcfmm/polarizable_solver.hpp"
#include "gcfmm/solver.hpp"

using namespace gcfmm;

namespace {

// the best time so far and the evaluations it took
void keep_best(double &best, int &evaluations, double t, int ev) {
  if (t < best) {
    best = t;
    evaluations = ev;
  }
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

Options options(double acc) {
  Options o;
  o.accuracy = acc;
  o.boundary = Boundary::Periodic2D;
  o.farfield = FarField::Exact;
  o.images = 1;
  return o;
}

}  // namespace

int main(int argc, char **argv) {
  std::vector<std::size_t> ns{2000, 20000};
  double acc = 1e-4;
  int reps = 3;
  double step = 0.01;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string k = argv[i];
    if (k == "--n") ns = gcfmm_bench::list<std::size_t>(argv[i + 1]);
    else if (k == "--acc") acc = std::atof(argv[i + 1]);
    else if (k == "--reps") reps = std::atoi(argv[i + 1]);
    else if (k == "--step") step = std::atof(argv[i + 1]);
  }
  std::printf("# accuracy %g, best of %d, seconds per evaluation (build included), warm start after a step of\n"
              "# %g radii; pred: the second step started from the dipoles extrapolated from the last two;\n"
              "# ev: FMM evaluations of the step; ratios against the charges-only evaluation of the same geometry\n", acc, reps, step);
  std::printf("%8s %9s %9s %3s %9s %3s %6s %9s %3s %6s | %9s %9s %3s %9s %3s %6s %9s %3s %6s\n", "N", "charges",
              "cold", "ev", "warm", "ev", "w/q", "pred", "ev", "p/q", "q+images", "cold", "ev", "warm", "ev", "w/q",
              "pred", "ev", "p/q");
  for (const std::size_t n : ns) {
    const gcfmm_bench::Bed b = gcfmm_bench::deposition(n, 7);
    std::vector<double> alpha(n, polarizability(clausius_mossotti(3.8, 1.0), 1.0));
    std::printf("%8zu", n);
    for (const bool electrode : {false, true}) {
      double t_q = 1e30, t_cold = 1e30, t_warm = 1e30, t_pred = 1e30;
      int it_cold = 0, it_warm = 0, it_pred = 0;
      PolarizableEnvironment env;
      env.applied_field = {0.0, 0.0, 0.05};
      env.electrode = electrode;
      for (int r = 0; r < reps; ++r) {
        PolarizableSolver ps(options(acc));
        PolarizableSolver ps_q(options(acc), false);   // charges + images: no dipoles
        ps.set_box(0, 0, b.L, b.L);
        ps.set_environment(env);
        ps.set_z_range(0.0, 160.0);
        std::vector<double> p(3 * n, 0.0);
        PolarizableOutputs out;
        ps.compute(n, b.x.data(), b.y.data(), b.z.data(), b.q.data(), nullptr, p.data(), out);  // set-up
        // charges only: without an electrode the plain Solver evaluation the fix does today
        auto t0 = std::chrono::steady_clock::now();
        if (electrode) {
          ps_q.set_box(0, 0, b.L, b.L);
          ps_q.set_environment(env);
          ps_q.set_z_range(0.0, 160.0);
          ps_q.compute(n, b.x.data(), b.y.data(), b.z.data(), b.q.data(), nullptr, p.data(), out);  // set-up
          t0 = std::chrono::steady_clock::now();
          ps_q.compute(n, b.x.data(), b.y.data(), b.z.data(), b.q.data(), nullptr, p.data(), out);
        } else {
          Solver s(options(acc));
          s.set_box(0, 0, b.L, b.L);
          s.set_z_range(0.0, 160.0);
          std::vector<double> pot(n), ex(n), ey(n), ez(n);
          s.build(n, b.x.data(), b.y.data(), b.z.data());  // far-field set-up outside the timing
          t0 = std::chrono::steady_clock::now();
          s.build(n, b.x.data(), b.y.data(), b.z.data());
          s.evaluate(b.q.data(), pot.data(), ex.data(), ey.data(), ez.data());
        }
        t_q = std::min(t_q, seconds_since(t0));
        t0 = std::chrono::steady_clock::now();
        ps.compute(n, b.x.data(), b.y.data(), b.z.data(), b.q.data(), alpha.data(), p.data(), out);
        // the evaluations of the fastest repetition
        keep_best(t_cold, it_cold, seconds_since(t0), ps.evaluations());
        // every particle moves by a constant step of up to `step` per coordinate
        std::mt19937_64 g(r + 11);
        std::uniform_real_distribution<double> u(-step, step);
        std::vector<double> vx(n), vy(n), vz(n);
        for (std::size_t i = 0; i < n; ++i) {
          vx[i] = u(g);
          vy[i] = u(g);
          vz[i] = u(g);
        }
        std::vector<double> x = b.x, y = b.y, z = b.z, p_prev = p;
        auto advance = [&] {
          for (std::size_t i = 0; i < n; ++i) {
            x[i] += vx[i];
            y[i] += vy[i];
            z[i] += vz[i];
          }
        };
        advance();
        t0 = std::chrono::steady_clock::now();
        ps.compute(n, x.data(), y.data(), z.data(), b.q.data(), alpha.data(), p.data(), out);
        keep_best(t_warm, it_warm, seconds_since(t0), ps.evaluations());
        // then two steps started from the dipoles extrapolated from the last two, 2 p_n - p_{n-1}
        for (int k = 0; k < 2; ++k) {
          advance();
          std::vector<double> guess(3 * n);
          for (std::size_t j = 0; j < 3 * n; ++j) guess[j] = 2.0 * p[j] - p_prev[j];
          p_prev = p;
          p = guess;
          t0 = std::chrono::steady_clock::now();
          ps.compute(n, x.data(), y.data(), z.data(), b.q.data(), alpha.data(), p.data(), out);
          if (k == 1) keep_best(t_pred, it_pred, seconds_since(t0), ps.evaluations());
        }
        if (std::getenv("BENCH_STATS")) {
          const Stats &st = ps.stats();
          std::printf("\n# last evaluation: build %.4f upward %.4f m2l %.4f p2p %.4f down %.4f far %.4f order %d"
                      " pairs %zu\n", st.t_build, st.t_upward, st.t_m2l, st.t_p2p, st.t_downward, st.t_far,
                      st.order, st.p2p_pairs);
        }
      }
      std::printf(" %9.4f %9.4f %3d %9.4f %3d %6.2f %9.4f %3d %6.2f%s", t_q, t_cold, it_cold, t_warm, it_warm,
                  t_warm / t_q, t_pred, it_pred, t_pred / t_q, electrode ? "\n" : " |");
    }
  }
  return 0;
}
