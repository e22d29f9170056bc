// Benchmark of gcfmm::StaticSourceField (not a test): the field of a fixed ("sleeping") source
// set at a few hundred moving ("awake") targets, against one full Solver build + evaluate over
// all N_sources + N_targets particles (what the fix would do without the split).
//
// Geometry (deposition): lx = ly = 28 sqrt(N_s / 2000), N_s sources in a dense bed (volume
// fraction 0.3, radius-1 particles, about 32 high), positive charges in [0.5, 1.5]; the targets
// 80% in a thin layer [top - 2, top + 3] at the bed's top and 20% up to z = 160. Periodic2D,
// images 1, far field per --farfield (default exact), the column [0, 160] given by set_z_range.
//
// usage: bench_static_field [--ns N[,N...]] [--nt n] [--acc a] [--farfield exact|none|average]
//                           [--tleaf L[,L...]] [--reps r] [--check 0|1]
// --check 1 also measures the error of Solver(targets) + StaticSourceField(sources) against the
// whole Solver at the targets (relative RMS of the field).
#include "bench_util.hpp"
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "gcfmm/solver.hpp"
#include "gcfmm/static_field.hpp"

using namespace gcfmm;

namespace {

struct Particles {
  std::vector<double> x, y, z, q;
  std::size_t size() const { return x.size(); }
  void add(double a, double b, double c, double d) {
    x.push_back(a);
    y.push_back(b);
    z.push_back(c);
    q.push_back(d);
  }
};

using gcfmm_bench::list;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

int main(int argc, char **argv) {
  std::vector<std::size_t> nss{2000, 20000, 200000};
  std::size_t nt = 500;
  double acc = 1e-4;
  std::string ffs = "exact";
  std::vector<int> tleaves{0};
  int reps = 5;
  bool check = false;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string k = argv[i];
    if (k == "--ns") nss = list<std::size_t>(argv[i + 1]);
    else if (k == "--nt") nt = std::atoi(argv[i + 1]);
    else if (k == "--acc") acc = std::atof(argv[i + 1]);
    else if (k == "--farfield") ffs = argv[i + 1];
    else if (k == "--tleaf") tleaves = list<int>(argv[i + 1]);
    else if (k == "--reps") reps = std::atoi(argv[i + 1]);
    else if (k == "--check") check = std::atoi(argv[i + 1]) != 0;
    else {
      std::fprintf(stderr, "unknown option %s\n", k.c_str());
      return 1;
    }
  }
  const FarField ff = ffs == "none" ? FarField::None : (ffs == "average" ? FarField::Average : FarField::Exact);
  std::printf("# StaticSourceField: deposition, Periodic2D images 1, farfield %s, accuracy %.0e, N_t = %zu, "
              "column [0, 160]\n", ffs.c_str(), acc, nt);
  std::printf("# t_src: set_sources (incl. far set-up t_fsetup; the source energy t_energy is computed on first use); t_eval: one evaluate "
              "(best of %d); t_solver: Solver build + evaluate over N_s + N_t (best of %d; far-field set-up done "
              "once before)\n", reps, reps);
  std::printf("# t_src2: set_sources again (the column is kept: no far set-up)\n");
  std::printf("%8s %5s %9s %9s %9s %9s %9s %9s %9s %9s %9s %8s %8s %8s %9s %9s\n", "N_s", "tleaf", "t_src", "t_src2", "t_fsetup",
              "t_energy", "t_eval", "t_solver", "solv/eval", "src2/solv", "t_e_p2p", "t_e_m2l", "t_e_down",
              "t_e_far", "m2l", "p2p_pairs");
  for (std::size_t ns : nss) {
    const double l = 28.0 * std::sqrt(double(ns) / 2000.0);
    std::mt19937_64 g(42);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double hbed = ns * (4.0 / 3.0 * M_PI) / (0.3 * l * l), top = 1.0 + hbed;
    Particles S, T, P;
    for (std::size_t i = 0; i < ns; ++i) S.add(l * u(g), l * u(g), 1.0 + hbed * u(g), 0.5 + u(g));
    for (std::size_t i = 0; i < nt; ++i)
      T.add(l * u(g), l * u(g), i < nt * 4 / 5 ? top - 2.0 + 5.0 * u(g) : top + 3.0 + (160.0 - top - 3.0) * u(g),
            0.5 + u(g));
    for (const Particles *p : {&S, &T})
      for (std::size_t i = 0; i < p->size(); ++i) P.add(p->x[i], p->y[i], p->z[i], p->q[i]);
    Options o;
    o.accuracy = acc;
    o.boundary = Boundary::Periodic2D;
    o.farfield = ff;
    o.images = 1;
    // the whole Solver (the far-field operator is set up by the first build, as in a run)
    Solver whole(o);
    whole.set_box(0, 0, l, l);
    whole.set_z_range(0, 160);
    std::vector<double> wp(P.size()), wx(P.size()), wy(P.size()), wz(P.size());
    double t_solver = 1e300;
    for (int r = 0; r < std::max(1, reps); ++r) {
      const auto t0 = std::chrono::steady_clock::now();
      whole.build(P.size(), P.x.data(), P.y.data(), P.z.data());
      whole.evaluate(P.q.data(), wp.data(), wx.data(), wy.data(), wz.data());
      if (r > 0 || reps == 1) t_solver = std::min(t_solver, seconds_since(t0));
    }
    for (int tl : tleaves) {
      StaticSourceField f(o);
      f.set_target_leaf(tl);
      f.set_box(0, 0, l, l);
      f.set_z_range(0, 160);
      auto t0 = std::chrono::steady_clock::now();
      f.set_sources(ns, S.x.data(), S.y.data(), S.z.data(), S.q.data());
      const double t_src = seconds_since(t0);
      const StaticFieldStats src_stats = f.stats();
      // again, as after a change of the sleeping set in a run: the far-field column is kept
      t0 = std::chrono::steady_clock::now();
      f.set_sources(ns, S.x.data(), S.y.data(), S.z.data(), S.q.data());
      const double t_src2 = seconds_since(t0);
      // the sources' energy, computed on the first call after set_sources()
      t0 = std::chrono::steady_clock::now();
      (void) f.source_energy();
      const double t_energy = seconds_since(t0);
      std::vector<double> pot(nt), ex(nt), ey(nt), ez(nt);
      double t_eval = 1e300;
      StaticFieldStats st{};
      for (int r = 0; r < std::max(1, reps); ++r) {
        t0 = std::chrono::steady_clock::now();
        f.evaluate(nt, T.x.data(), T.y.data(), T.z.data(), pot.data(), ex.data(), ey.data(), ez.data());
        const double t = seconds_since(t0);
        if (t < t_eval) {
          t_eval = t;
          st = f.stats();
        }
      }
      std::printf("%8zu %5d %8.2fms %8.2fms %8.2fms %8.2fms %8.3fms %8.2fms %9.1f %9.2f %8.3fms %7.3fms %7.3fms %7.3fms "
                  "%9zu %9zu\n",
                  ns, st.target_leaf, 1e3 * t_src, 1e3 * t_src2, 1e3 * src_stats.t_far_setup, 1e3 * t_energy,
                  1e3 * t_eval, 1e3 * t_solver, t_solver / t_eval, t_src2 / t_solver, 1e3 * st.t_p2p,
                  1e3 * st.t_m2l, 1e3 * st.t_downward, 1e3 * st.t_far, st.m2l_count, st.p2p_pairs);
      if (check) {
        Solver a(o);
        a.set_box(0, 0, l, l);
        a.set_z_range(0, 160);
        a.build(nt, T.x.data(), T.y.data(), T.z.data());
        std::vector<double> ap(nt), ax(nt), ay(nt), az(nt);
        a.evaluate(T.q.data(), ap.data(), ax.data(), ay.data(), az.data());
        double num = 0, den = 0;
        for (std::size_t i = 0; i < nt; ++i) {
          const std::size_t k = ns + i;
          const double dx = ax[i] + ex[i] - wx[k], dy = ay[i] + ey[i] - wy[k], dz = az[i] + ez[i] - wz[k];
          num += dx * dx + dy * dy + dz * dz;
          den += wx[k] * wx[k] + wy[k] * wy[k] + wz[k] * wz[k];
        }
        std::printf("#   split vs whole: relative RMS field difference at the targets %.2e; memory held %.1f MB\n",
                    std::sqrt(num / den), f.memory_bytes() / 1e6);
      }
      std::fflush(stdout);
    }
  }
  return 0;
}
