// Benchmark of gcfmm::DistributedSolver (not a test): counts, not speed. The ranks are threads
// of one process (unittest/fmm/thread_communicator.hpp), so wall times at P > 1 say nothing
// about a cluster; what is printed per P is what one rank receives and holds.
//
// Geometries: "deposition" (Periodic2D, images 1, FarField::Exact with the column [0, 160] given
// by set_z_range; lx = ly = 28 sqrt(N / 2000), 90% of equal charges in a dense bed of volume
// fraction 0.3 about 32 high, 10% up to z = 160: gcfmm_test::deposition) and "cube" (free space,
// N random charges of both signs in a cube of side N^(1/3), i.e. unit density).
// Partitions: an x-y grid of P ranks (1x1, 2x1, 2x2, 4x2, as LAMMPS `processors * * 1`), and at
// P = 8 also a 2x2x2 grid (a z split). Strong scaling: N fixed; weak: N P / 8 particles, so
// that N / P = N / 8 at every P (and the P = 8 row is the strong one's).
//
// Columns: the largest LET bytes any rank receives in one evaluation, that over N x 32 bytes
// (the allgather of x, y, z, q the LAMMPS fix does today), the largest memory_bytes of any
// rank and its ratio to P = 1 (same geometry and scaling), the largest numbers of LET nodes and
// particles received, and at P = 1 the wall time of one evaluation (the second of two: the
// first sets up the far-field operator).
//
// usage: bench_distributed [--n N[,N...]] [--ranks P[,P...]] [--acc a] [--geometry deposition|cube|both]
//                          [--scaling strong|weak|both]
#include "bench_util.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "gcfmm/distributed_solver.hpp"
#include "fmm_test_util.hpp"
#include "thread_communicator.hpp"

using namespace gcfmm;

namespace {

using gcfmm_test::Particles;

struct Row {
  std::size_t bytes = 0, memory = 0, let_nodes = 0, let_particles = 0;
  double seconds = 0.0;
};

Row run(const Options &o, const Particles &p, const std::vector<int> &rank, int P, double l) {
  Row row;
  std::vector<DistributedStats> stats(P);
  std::vector<double> seconds(P, 0.0);
  gcfmm_test::run_ranks(P, [&](gcfmm_test::ThreadCommunicator &comm) {
    const int r = comm.rank();
    Particles mine;
    std::vector<std::int64_t> ids;
    gcfmm_test::rank_share(p, rank, r, mine, ids);
    DistributedSolver s(o, comm);
    if (o.boundary == Boundary::Periodic2D) {
      s.set_box(0.0, 0.0, l, l);
      s.set_z_range(0.0, 160.0);
    }
    const std::size_t n = mine.size();
    std::vector<double> pot(n), ex(n), ey(n), ez(n);
    for (int e = 0; e < 2; ++e) {
      const auto t0 = std::chrono::steady_clock::now();
      s.evaluate(n, mine.x.data(), mine.y.data(), mine.z.data(), mine.q.data(), ids.data(), pot.data(), ex.data(),
                 ey.data(), ez.data());
      seconds[r] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    stats[r] = s.stats();
  });
  for (int r = 0; r < P; ++r) {
    row.bytes = std::max(row.bytes, stats[r].bytes_received);
    row.memory = std::max(row.memory, stats[r].memory_bytes);
    row.let_nodes = std::max(row.let_nodes, stats[r].let_nodes_received);
    row.let_particles = std::max(row.let_particles, stats[r].let_particles_received);
    row.seconds = std::max(row.seconds, seconds[r]);
  }
  return row;
}

}  // namespace

int main(int argc, char **argv) {
  std::vector<double> ns = {100000};
  std::vector<int> ranks = {1, 2, 4, 8};
  double acc = 1e-4;
  std::string geometry = "both", scaling = "both";
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--n")) ns = gcfmm_bench::list<double>(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--ranks")) ranks = gcfmm_bench::list<int>(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--acc")) acc = std::atof(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--geometry")) geometry = argv[i + 1];
    else if (!std::strcmp(argv[i], "--scaling")) scaling = argv[i + 1];
    else {
      std::fprintf(stderr, "unknown option %s\n", argv[i]);
      return 1;
    }
  }
  std::printf("| geometry | scaling | N total | P | grid | max LET bytes recv | / (N x 32) | max memory MB | "
              "memory / P=1 | LET nodes | LET particles | t eval P=1 (s) |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const char *geo : {"deposition", "cube"}) {
    if (geometry != "both" && geometry != geo) continue;
    const bool periodic = !std::strcmp(geo, "deposition");
    Options o;
    o.accuracy = acc;
    o.boundary = periodic ? Boundary::Periodic2D : Boundary::Free;
    o.farfield = FarField::Exact;
    for (double nd : ns)
      for (const char *mode : {"strong", "weak"}) {
        if (scaling != "both" && scaling != mode) continue;
        const bool weak = !std::strcmp(mode, "weak");
        double memory_one = 0.0;
        struct Layout {
          int P, px, py, pz;
        };
        std::vector<Layout> layouts;
        for (int P : ranks) {
          const int px = P >= 4 ? P / 2 : P, py = P >= 4 ? 2 : 1;
          layouts.push_back({P, px, py, 1});
          if (P == 8) layouts.push_back({8, 2, 2, 2});
        }
        for (const Layout &lay : layouts) {
          const auto n = static_cast<std::size_t>(weak ? nd * lay.P / 8.0 : nd);
          const double l = gcfmm_test::deposition_width(n);
          const Particles p =
              periodic ? gcfmm_test::deposition(n, 1) : gcfmm_test::random_cube(n, 1, std::cbrt(double(n)));
          const Row row = run(o, p, gcfmm_test::grid_partition(p, lay.px, lay.py, lay.pz), lay.P, l);
          if (lay.P == 1) memory_one = double(row.memory);
          char t[32] = "";
          if (lay.P == 1) std::snprintf(t, sizeof t, "%.2f", row.seconds);
          char ratio[32] = "";
          if (memory_one > 0) std::snprintf(ratio, sizeof ratio, "%.3f", row.memory / memory_one);
          std::printf("| %s | %s | %zu | %d | %dx%dx%d | %zu | %.3f | %.1f | %s | %zu | %zu | %s |\n", geo, mode, n,
                      lay.P, lay.px, lay.py, lay.pz, row.bytes, row.bytes / (32.0 * n), row.memory / 1048576.0,
                      ratio, row.let_nodes, row.let_particles, t);
          std::fflush(stdout);
        }
      }
  }
  return 0;
}
