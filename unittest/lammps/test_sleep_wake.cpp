/* GRANULAR-CHARGED: which sleepers fix sleep/gran wakes, on any processor grid, and its counts
   straight after read_restart.

   The documented rule (doc/fix_sleep_gran.rst, "Waking"): a sleeper whose awake partners push
   it with more than `wake` wakes on that step, and so do the sleepers touching it; nothing else
   wakes. The sum over the partners may change its order with the grid, nothing else may.

   - TheDocumentedRuleStepByStep (1 rank): a bed of 256 sleepers (an 8 x 8 x 4 lattice whose
     neighbours touch) is rained on by 80 spheres at ~1 m/s. Step by step, the sleepers woken
     are compared with those the rule names: the pushed sleepers (the fix's own push, above
     `wake`) and their lattice neighbours that were asleep. Both parts of the rule must occur.
   - SameSleepersWakeOnEveryGrid (1, 2, 3 ranks): the same deck on every `processors` grid of
     the ranks (and with newton on) wakes the same sleepers, by lattice cell, as on one rank.
     The atoms' IDs depend on the grid (create_atoms numbers the lattice per rank): a sleeper is
     named by its lattice cell, kept in a custom per-atom integer.
   - ChainAcrossRanks (1, 2, 3 ranks): four touching sleepers in a row across a sub-domain face;
     a sphere hits the second. On the step of the impact the second (pushed) and its two
     neighbours wake, the fourth (touching only sleepers, not pushed) stays asleep.
   - SurfacePushesAsFromTheWholeList (1, 2 ranks): with a rest time the fix counts contacts on
     every step, over every list entry with an awake atom; without one (time none) it counts
     them on commit steps only and sums the pushes over the entries of awake-sleeper pairs.
     The same bed put to sleep by either rule is rained on: on every step each sleeper's push
     is the same bit for bit, the same sleepers wake and every atom ends where it ends with the
     other rule.
   - CountsRightAfterReadRestart: f_sleep and f_sleep[2] read after read_restart, before any
     run, give the awake and sleeping atoms of the restart (27 asleep, 5 awake).

   Checked against broken code: with the reverse communication of the wake requests reading
   its buffer through MAX() (which evaluates buf[m++] twice), the rule check fails on 1 rank
   (atoms of the bed's corner column woken, 44 sleepers woken instead of 30, the extra ones
   neither pushed nor touching a pushed one) and the grid comparison fails on 2 and 3 ranks
   (94, 69, 87 woken on 2x1x1, 1x2x1, 3x1x1); without counting the sleepers where the counts
   are read, CountsRightAfterReadRestart reads 32 awake and 0 asleep. */
#include "gc_testing.h"

#include "atom.h"
#include "fix.h"
#include "modify.h"

#include "gtest/gtest.h"
#include "library.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <string>
#include <vector>

using gctest::Lmp;
using gctest::nprocs;
using gctest::rank;

namespace {
const char *MODEL = "jkr/marshall 2e8 0.7 0.33 0.01 damping marshall tangential marshall 0.3 "
                    "rolling marshall 0.01 twisting marshall/jkr";

// the bed: NX x NX x NZ lattice cells of spacing A (< the diameter 2 um: neighbours touch)
constexpr int NX = 8, NZ = 4, NBED = NX * NX * NZ;
constexpr double A = 1.995e-6;
// the wake threshold: above the static contact forces of the bed (below them the first woken
// sleepers push their neighbours awake in a cascade through the whole bed), below the push of
// an impact at 1 m/s (~m U / t_c = 1.7e-7 N)
constexpr double WAKE = 1e-7;
constexpr int NSTEPS = 3000;    // the rain lands within ~2500 steps

// the bed falls asleep on the commit step 1000000 (every 1000000: no other commit follows,
// so a woken sleeper stays awake and the woken set is the sleepers awake at the end), then 80
// spheres rain on it from 3-14 um above at 1 m/s with a little thermal spread
// rule: the fix's falling-asleep rule (both put every bed atom to sleep on the commit step)
std::vector<std::string> rain_deck(const std::string &grid, const std::string &newton,
                                   const std::string &rule = "time 0")
{
  return {"units si", "atom_style sphere", "atom_modify map array", "boundary p p f",
          "newton " + newton, "comm_modify vel yes", "processors " + grid,
          fmt::format("lattice sc {}", A), "region box block 0 8 0 8 -1 40", "create_box 1 box",
          "region cells block 0 8 0 8 0 3", "create_atoms 1 region cells", "group bed region cells",
          "fix cells all property/atom i_cell",
          fmt::format("variable cellidx atom 1+round(x/{0})+{1}*round(y/{0})+{2}*round(z/{0})", A,
                      NX, NX * NX),
          "set group bed i_cell v_cellidx", "set group all diameter 2.0e-6",
          "set group all density 2500", "pair_style granular/opt",
          std::string("pair_coeff * * ") + MODEL,
          std::string("fix floor all wall/gran granular ") + MODEL + " zplane -0.999e-6 NULL",
          "neighbor 2e-7 bin", "neigh_modify every 1 delay 0 check yes",
          "fix integrate all nve/sphere", "fix grav all gravity 9.81 vector 0 0 -1",
          "timestep 5e-9", "thermo 0", "reset_timestep 999999",
          fmt::format("fix sleep all sleep/gran speed 1e3 force 1.0 wake {} {} every 1000000",
                      WAKE, rule),
          "run 1",
          "region above block EDGE EDGE EDGE EDGE 9.0e-6 20e-6 units box",
          "create_atoms 1 random 80 4711 above overlap 2.2e-6 maxtry 1000 units box",
          "group rain subtract all bed", "set group rain diameter 2.0e-6",
          "set group rain density 2500", "velocity rain create 1e8 77 loop geom",
          "velocity rain set NULL NULL -1.0 sum yes"};
}

// lattice cell (1 + ix + NX iy + NX^2 iz) of every bed atom that is awake now, sorted
std::vector<int> awake_cells(Lmp &l)
{
  const int n = static_cast<int>(l.lmp->atom->natoms);
  std::vector<int> cell(n);
  std::vector<double> sleeping(n);
  lammps_gather(l.lmp, "i_cell", 0, 1, cell.data());
  lammps_gather(l.lmp, "f_sleep", 1, 1, sleeping.data());
  std::vector<int> awake;
  for (int k = 0; k < n; k++)
    if (cell[k] > 0 && sleeping[k] == 0.0) awake.push_back(cell[k]);
  std::sort(awake.begin(), awake.end());
  return awake;
}

// the lattice cells touching cell c (periodic in x and y)
std::vector<int> lattice_neighbours(int c)
{
  const int k = c - 1, ix = k % NX, iy = (k / NX) % NX, iz = k / (NX * NX);
  auto cell = [](int x, int y, int z) { return 1 + (x + NX) % NX + NX * ((y + NX) % NX) + NX * NX * z; };
  std::vector<int> nb = {cell(ix - 1, iy, iz), cell(ix + 1, iy, iz), cell(ix, iy - 1, iz),
                         cell(ix, iy + 1, iz)};
  if (iz > 0) nb.push_back(cell(ix, iy, iz - 1));
  if (iz < NZ - 1) nb.push_back(cell(ix, iy, iz + 1));
  return nb;
}

}    // namespace

TEST(SleepWake, TheDocumentedRuleStepByStep)
{
  if (nprocs() > 1) GTEST_SKIP() << "reads the fix's per-atom push on one rank";
  Lmp l;
  l.cmds(rain_deck("1 1 1", "off"));
  auto *fix = l.lmp->modify->get_fix_by_id("sleep");
  ASSERT_NE(fix, nullptr);
  int flag = -1, cols = -1;
  const int icell = l.lmp->atom->find_custom("cell", flag, cols);
  ASSERT_GE(icell, 0);

  // the sleeping flag of each lattice cell before the step
  auto cell_flags = [&]() {
    int dim = 0;
    const double *asleep = static_cast<double *>(fix->extract("sleeping", dim));
    const int *cell = l.lmp->atom->ivector[icell];
    std::vector<char> s(NBED + 1, 0);
    for (int i = 0; i < l.lmp->atom->nlocal; i++)
      if (cell[i] > 0) s[cell[i]] = asleep[i] != 0.0;
    return s;
  };
  std::vector<char> before = cell_flags();
  ASSERT_EQ(std::count(before.begin(), before.end(), 1), NBED) << "the whole bed sleeps";

  int woken_total = 0, pushed_total = 0;
  l.cmd("run 1");
  for (int step = 1; step <= NSTEPS; step++) {
    if (step > 1) l.cmd("run 1 pre no post no");
    const std::vector<char> now = cell_flags();
    // the push of this step on each sleeper (the fix's sum, after its reverse communication)
    int dim = 0;
    double **push = static_cast<double **>(fix->extract("push", dim));
    const int *cell = l.lmp->atom->ivector[icell];
    std::set<int> expected, woken;
    for (int i = 0; i < l.lmp->atom->nlocal; i++) {
      const int c = cell[i];
      if (c <= 0 || !before[c]) continue;
      const double p = std::sqrt(push[i][0] * push[i][0] + push[i][1] * push[i][1] +
                                 push[i][2] * push[i][2]);
      if (p <= WAKE) continue;
      expected.insert(c);
      pushed_total++;
      for (int nb : lattice_neighbours(c))
        if (before[nb]) expected.insert(nb);
    }
    for (int c = 1; c <= NBED; c++)
      if (before[c] && !now[c]) woken.insert(c);
    for (int c : woken)
      EXPECT_TRUE(expected.count(c)) << "step " << step << ": cell " << c
                                     << " woke, neither pushed nor touching a pushed sleeper";
    for (int c : expected)
      EXPECT_TRUE(woken.count(c)) << "step " << step << ": cell " << c
                                  << " pushed or touching a pushed sleeper, still asleep";
    if (woken != expected) return;    // one step's report is enough
    woken_total += static_cast<int>(woken.size());
    before = now;
  }
  const int touching_total = woken_total - pushed_total;
  std::printf("[ rule ] %d sleepers woken in %d steps: %d pushed, %d touching a pushed one\n",
              woken_total, NSTEPS, pushed_total, touching_total);
  EXPECT_GT(pushed_total, 3) << "the rain pushes sleepers";
  EXPECT_GT(touching_total, 3) << "and wakes their neighbours";
  EXPECT_LT(woken_total, NBED / 4) << "no cascade: the threshold is above the static forces";
}

TEST(SleepWake, SurfacePushesAsFromTheWholeList)
{
  const std::string grid = nprocs() == 2 ? "2 1 1" : "1 1 1";
  if (nprocs() > 2) GTEST_SKIP() << "1 and 2 ranks";
  Lmp every_step, surface;
  every_step.cmds(rain_deck(grid, "off", "time 0"));
  surface.cmds(rain_deck(grid, "off", "time none depth 1e-30"));
  ASSERT_EQ(every_step.var("f_sleep[2]"), NBED) << "the rest rule puts the whole bed to sleep";
  ASSERT_EQ(surface.var("f_sleep[2]"), NBED) << "the depth rule puts the whole bed to sleep";
  // the push on every sleeper, step by step: the same sums in the same order
  auto push_of = [](Lmp &l) {
    int dim = 0;
    auto *fix = l.lmp->modify->get_fix_by_id("sleep");
    double **push = static_cast<double **>(fix->extract("push", dim));
    std::vector<double> p;
    for (int i = 0; i < l.lmp->atom->nlocal; i++) p.insert(p.end(), push[i], push[i] + 3);
    return p;
  };
  int differ = 0, pushed = 0;
  for (int step = 1; step <= NSTEPS; step++) {
    const std::string run = step == 1 ? "run 1" : "run 1 pre no post no";
    every_step.cmd(run);
    surface.cmd(run);
    const auto pe = push_of(every_step), ps = push_of(surface);
    if (pe != ps) differ++;
    for (double v : pe) pushed += v != 0.0;
  }
  int differ_all = 0, pushed_all = 0;
  MPI_Allreduce(&differ, &differ_all, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(&pushed, &pushed_all, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_GT(pushed_all, 1000) << "the rain pushes sleepers";
  EXPECT_EQ(differ_all, 0) << "steps on which a rank's pushes differ";
  const auto woken = awake_cells(every_step);
  EXPECT_GT(woken.size(), 10u) << "the rain wakes sleepers";
  EXPECT_EQ(awake_cells(surface), woken);
  EXPECT_EQ(gctest::gather(surface, "x", 3), gctest::gather(every_step, "x", 3))
      << "positions as with the contacts counted on every step";
}

TEST(SleepWake, SameSleepersWakeOnEveryGrid)
{
  // the reference: one rank alone
  std::vector<int> ref;
  int nref = 0;
  if (rank() == 0) {
    Lmp one(MPI_COMM_SELF);
    one.cmds(rain_deck("1 1 1", "off"));
    one.cmd("run " + std::to_string(NSTEPS));
    ref = awake_cells(one);
    nref = static_cast<int>(ref.size());
    std::printf("[ grid 1 rank ] %d sleepers woken\n", nref);
  }
  MPI_Bcast(&nref, 1, MPI_INT, 0, MPI_COMM_WORLD);
  ref.resize(nref);
  MPI_Bcast(ref.data(), nref, MPI_INT, 0, MPI_COMM_WORLD);
  EXPECT_GT(nref, 10) << "the rain wakes sleepers";
  EXPECT_LT(nref, NBED / 4) << "no cascade";

  const int np = nprocs();
  std::vector<std::string> grids;
  if (np == 1) grids = {"1 1 1"};
  if (np == 2) grids = {"2 1 1", "1 2 1", "1 1 2"};
  if (np == 3) grids = {"3 1 1", "1 3 1", "1 1 3"};
  if (grids.empty()) GTEST_SKIP() << "grids for 1, 2 and 3 ranks";
  struct Variant {
    std::string grid, newton;
  };
  std::vector<Variant> variants;
  for (const auto &g : grids) variants.push_back({g, "off"});
  variants.push_back({grids.front(), "on"});
  for (const auto &v : variants) {
    Lmp l;
    l.cmds(rain_deck(v.grid, v.newton));
    l.cmd("run " + std::to_string(NSTEPS));
    const auto woken = awake_cells(l);
    if (rank() == 0)
      std::printf("[ grid %s newton %s ] %d sleepers woken\n", v.grid.c_str(), v.newton.c_str(),
                  static_cast<int>(woken.size()));
    EXPECT_EQ(woken, ref) << "grid " << v.grid << ", newton " << v.newton;
  }
}

// sleepers 1-4 in a row along x (touching: 1.995 um apart), across the sub-domain faces of 2
// ranks (x = 12 um, between 3 and 4) and of 3 ranks (x = 8 um, between 1 and 2); sphere 5
// falls onto sphere 2 at 0.3 m/s (push ~3e-8 N, above wake 1e-8 N)
TEST(SleepWake, ChainAcrossRanks)
{
  const int np = nprocs();
  Lmp l;
  l.cmds({"units si", "atom_style sphere", "atom_modify map array", "boundary p p f",
          "newton off", "comm_modify vel yes", fmt::format("processors {} 1 1", np),
          "region box block 0 24e-6 0 8e-6 0 8e-6", "create_box 1 box",
          "create_atoms 1 single 7.0e-6 4e-6 3e-6", "create_atoms 1 single 8.995e-6 4e-6 3e-6",
          "create_atoms 1 single 10.99e-6 4e-6 3e-6", "create_atoms 1 single 12.985e-6 4e-6 3e-6",
          "create_atoms 1 single 8.995e-6 4e-6 5.05e-6", "set group all diameter 2.0e-6",
          "set group all density 2500", "group chain id 1:4", "pair_style granular/opt",
          std::string("pair_coeff * * ") + MODEL, "neighbor 2e-7 bin",
          "neigh_modify every 1 delay 0 check yes", "fix integrate all nve/sphere",
          "timestep 5e-9", "thermo 0",
          // the chain falls asleep on the first step; sphere 5, not touching, stays awake
          "fix sleep all sleep/gran speed 1e3 force 1.0 wake 1e-8 time 0 every 1000000",
          "reset_timestep 999999", "run 1"});
  ASSERT_EQ(l.var("f_sleep[2]"), 4.0) << "the chain sleeps";
  l.cmd("velocity all set 0 0 -0.3 sum no");
  l.cmd("velocity chain set 0 0 0");
  int steps = 0;
  while (l.var("f_sleep[4]") == 0.0 && steps < 400) {
    l.cmd("run 1 pre no post no");
    steps++;
  }
  ASSERT_GT(l.var("f_sleep[4]"), 0.0) << "sphere 5 reaches sphere 2 within 400 steps";
  std::vector<double> sleeping(5);
  lammps_gather(l.lmp, "f_sleep", 1, 1, sleeping.data());
  EXPECT_EQ(sleeping[1], 0.0) << "sphere 2, pushed, wakes";
  EXPECT_EQ(sleeping[0], 0.0) << "sphere 1 touches sphere 2";
  EXPECT_EQ(sleeping[2], 0.0) << "sphere 3 touches sphere 2";
  EXPECT_EQ(sleeping[3], 1.0) << "sphere 4 touches only sleepers, no push: it sleeps";
  EXPECT_EQ(l.var("f_sleep[4]"), 3.0) << "three woken on step " << steps;
}

// 27 touching spheres on a JKR floor fall asleep; 5 spheres far above them stay awake
TEST(SleepWake, CountsRightAfterReadRestart)
{
  const std::string file = "sleep_wake_counts.restart";
  const std::string model = std::string(" ") + MODEL;
  {
    Lmp l;
    l.cmds({"units si", "atom_style sphere", "atom_modify map array", "boundary p p f",
            "newton off", "comm_modify vel yes", "lattice sc 1.995e-6",
            "region box block 0 3 0 3 -1 12", "create_box 1 box",
            "region cells block 0 3 0 3 0 2", "create_atoms 1 region cells",
            "create_atoms 1 single 0.5 0.5 6", "create_atoms 1 single 0.5 0.5 8",
            "create_atoms 1 single 0.5 0.5 10", "create_atoms 1 single 1.5 1.5 7",
            "create_atoms 1 single 1.5 1.5 9", "set group all diameter 2.0e-6",
            "set group all density 2500", "pair_style granular/opt", "pair_coeff * *" + model,
            "fix floor all wall/gran granular" + model + " zplane -0.999e-6 NULL",
            "neighbor 2e-7 bin", "fix integrate all nve/sphere", "timestep 5e-9", "thermo 0",
            "fix sleep all sleep/gran speed 1e3 force 1.0 wake 10.0 time 0 every 1", "run 1"});
    ASSERT_EQ(l.var("f_sleep[2]"), 27.0);
    ASSERT_EQ(l.var("f_sleep"), 5.0);
    l.cmd("write_restart " + file);
  }
  Lmp l;
  l.cmds({"read_restart " + file, "pair_style granular/opt", "pair_coeff * *" + model,
          "comm_modify vel yes", "neighbor 2e-7 bin", "fix integrate all nve/sphere",
          "fix sleep all sleep/gran speed 1e3 force 1.0 wake 10.0 time 0 every 1"});
  EXPECT_EQ(l.var("f_sleep"), 5.0) << "awake, before any run";
  EXPECT_EQ(l.var("f_sleep[1]"), 5.0) << "awake, before any run";
  EXPECT_EQ(l.var("f_sleep[2]"), 27.0) << "asleep, before any run";
  EXPECT_EQ(l.var("f_sleep[3]"), 27.0) << "fallen asleep (global restart)";
  if (rank() == 0) std::remove(file.c_str());
}
