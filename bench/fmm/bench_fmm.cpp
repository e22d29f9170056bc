// Benchmark of the gcfmm library (not a test). Prints one table row per configuration:
// build time, evaluation time (best of `reps`), and the relative RMS force error against
// direct_images (FarField::None, same image shells) or direct_free, exact for N <= 20000 and
// on a random sample of targets above.
//
// usage: bench_fmm [--geom deposition|cube] [--n N[,N...]] [--acc a[,a...]] [--order p[,p...]]
//                  [--theta t[,t...]] [--leaf L] [--images k] [--reps r] [--sample s]
#include "bench_util.hpp"
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "gcfmm/kernels.hpp"
#include "gcfmm/solver.hpp"

using namespace gcfmm;

namespace {

struct Particles {
  std::vector<double> x, y, z, q;
};

double width(std::size_t n) { return 28.0 * std::sqrt(double(n) / 2000.0); }

Particles deposition(std::size_t n, unsigned seed) {
  // same recipe as unittest/fmm/fmm_test_util.hpp: lx = ly = 28 sqrt(N / 2000) (28 at N = 2000),
  // 90 % in a bed of phi ~ 0.3 (about 32 high), 10 % spread up to z = 160, equal charges
  const double lx = width(n), ly = lx, zmax = 160;
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const std::size_t nbed = n * 9 / 10;
  const double hbed = nbed * (4.0 / 3.0 * M_PI) / (0.3 * lx * ly);
  Particles p;
  for (std::size_t i = 0; i < n; ++i) {
    const bool bed = i < nbed;
    p.x.push_back(lx * u(g));
    p.y.push_back(ly * u(g));
    p.z.push_back(bed ? 1.0 + hbed * u(g) : 1.0 + hbed + (zmax - 1.0 - hbed) * u(g));
    p.q.push_back(1.0);
  }
  return p;
}

Particles cube(std::size_t n, unsigned seed) {
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Particles p;
  for (std::size_t i = 0; i < n; ++i) {
    p.x.push_back(u(g));
    p.y.push_back(u(g));
    p.z.push_back(u(g));
    p.q.push_back((u(g) < 0.5 ? -1.0 : 1.0) * (0.5 + u(g)));
  }
  return p;
}

using gcfmm_bench::list;

}  // namespace

int main(int argc, char **argv) {
  std::string geom = "deposition";
  std::vector<std::size_t> ns{2000, 20000, 200000};
  std::vector<double> accs{1e-3, 1e-4, 1e-6};
  std::vector<int> orders{0};
  std::vector<double> thetas{0.0};
  int leaf = 0, images = 1, reps = 3;
  bool exact_far = false;    // --farfield exact: add the lattice beyond the images (err_F not measured)
  std::size_t sample = 2000;
  for (int i = 1; i + 1 < argc; i += 2) {
    std::string k = argv[i];
    if (k == "--geom") geom = argv[i + 1];
    else if (k == "--n") ns = list<std::size_t>(argv[i + 1]);
    else if (k == "--acc") accs = list<double>(argv[i + 1]);
    else if (k == "--order") orders = list<int>(argv[i + 1]);
    else if (k == "--theta") thetas = list<double>(argv[i + 1]);
    else if (k == "--leaf") leaf = std::atoi(argv[i + 1]);
    else if (k == "--images") images = std::atoi(argv[i + 1]);
    else if (k == "--reps") reps = std::atoi(argv[i + 1]);
    else if (k == "--sample") sample = std::atoi(argv[i + 1]);
    else if (k == "--farfield") exact_far = std::string(argv[i + 1]) == "exact";
    else {
      std::fprintf(stderr, "unknown option %s\n", k.c_str());
      return 1;
    }
  }
  const bool periodic = geom == "deposition";
  std::printf("# geometry %s, %s\n", geom.c_str(),
              periodic ? ("Periodic2D, FarField::" + std::string(exact_far ? "Exact" : "None") + ", images " + std::to_string(images)).c_str() : "free space");
  std::printf("# deposition box: lx = ly = 28 sqrt(N/2000), z up to 160\n");
  std::printf("%8s %8s %5s %6s %5s %6s %10s %10s %10s %10s %10s %10s %10s %11s %9s\n", "N", "acc", "p", "theta",
              "leaf", "levels", "m2l", "p2p_pairs", "t_build", "t_eval", "t_up", "t_m2l", "t_p2p", "t_down", "err_F");
  if (exact_far) std::printf("# t_far (far field beyond the images) follows err_F; err_F is not measured (nan)\n");
  using Clock = std::chrono::steady_clock;
  for (std::size_t n : ns) {
    Particles P = periodic ? deposition(n, 42) : cube(n, 42);
    // reference on a sample of targets (all targets when n <= 20000)
    std::vector<std::size_t> idx;
    if (n <= 20000) {
      for (std::size_t i = 0; i < n; ++i) idx.push_back(i);
    } else {
      std::mt19937_64 g(5);
      for (std::size_t i = 0; i < sample; ++i) idx.push_back(g() % n);
    }
    std::vector<double> rp(idx.size(), 0), rx(idx.size(), 0), ry(idx.size(), 0), rz(idx.size(), 0);
    const auto t_ref0 = Clock::now();
    {
      std::vector<double> tx, ty, tz;
      for (auto i : idx) {
        tx.push_back(P.x[i]);
        ty.push_back(P.y[i]);
        tz.push_back(P.z[i]);
      }
      const int k = periodic ? images : 0;
      for (int ix = -k; ix <= k; ++ix)
        for (int iy = -k; iy <= k; ++iy)
          p2p(idx.size(), tx.data(), ty.data(), tz.data(), n, P.x.data(), P.y.data(), P.z.data(), P.q.data(),
              ix * width(n), iy * width(n), 0.0, rp.data(), rx.data(), ry.data(), rz.data());
    }
    // the alternative the solver must beat at small N: the same P2P kernel over all pairs of
    // the image block (the reference above, when it covers every target)
    if (idx.size() == n)
      std::printf("# N = %zu: direct sum over the %s (same P2P kernel): %.2fms; compare t_build + t_eval\n", n,
                  periodic ? "image block" : "particles",
                  1e3 * std::chrono::duration<double>(Clock::now() - t_ref0).count());
    for (double acc : accs)
      for (int order : orders)
        for (double theta : thetas) {
          Options o;
          o.accuracy = acc;
          o.order = order;
          o.theta = theta;
          o.leaf = leaf;
          o.images = images;
          o.boundary = periodic ? Boundary::Periodic2D : Boundary::Free;
          o.farfield = periodic && exact_far ? FarField::Exact : FarField::None;
          Solver s(o);
          if (periodic) s.set_box(0.0, 0.0, width(n), width(n));
          // t_build: a second build(), as in a run (the far-field operator is set up once, by
          // the first)
          s.build(n, P.x.data(), P.y.data(), P.z.data());
          auto t0 = Clock::now();
          s.build(n, P.x.data(), P.y.data(), P.z.data());
          const double tb = std::chrono::duration<double>(Clock::now() - t0).count();
          std::vector<double> pot(n), ex(n), ey(n), ez(n);
          double best = 1e300;
          Stats st{};
          for (int r = 0; r < reps; ++r) {
            t0 = Clock::now();
            s.evaluate(P.q.data(), pot.data(), ex.data(), ey.data(), ez.data());
            const double te = std::chrono::duration<double>(Clock::now() - t0).count();
            if (te < best) {
              best = te;
              st = s.stats();
            }
          }
          double num = 0, den = 0;
          for (std::size_t k = 0; k < idx.size(); ++k) {
            const std::size_t i = idx[k];
            const double q2 = P.q[i] * P.q[i];
            num += q2 * ((ex[i] - rx[k]) * (ex[i] - rx[k]) + (ey[i] - ry[k]) * (ey[i] - ry[k]) +
                         (ez[i] - rz[k]) * (ez[i] - rz[k]));
            den += q2 * (rx[k] * rx[k] + ry[k] * ry[k] + rz[k] * rz[k]);
          }
          std::printf("%8zu %8.0e %5d %6.3f %5d %6d %10zu %10zu %9.2fms %9.2fms %9.2fms %9.2fms %9.2fms %10.2fms %9.2e%s",
                      n, acc, st.order, st.theta, st.leaf, st.levels, st.m2l_count, st.p2p_pairs, tb * 1e3,
                      best * 1e3, st.t_upward * 1e3, st.t_m2l * 1e3, st.t_p2p * 1e3, st.t_downward * 1e3,
                      exact_far ? std::nan("") : std::sqrt(num / den), exact_far ? "" : "\n");
          if (exact_far) std::printf("%10.2fms\n", st.t_far * 1e3);
          std::fflush(stdout);
        }
  }
  return 0;
}
