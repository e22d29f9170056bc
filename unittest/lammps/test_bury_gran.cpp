/* GRANULAR-CHARGED: fix bury/gran takes buried sleepers out of LAMMPS's per-atom work and gives
   the same trajectory as a run without it (doc/fix_bury_gran.rst).

   - SameTrajectoryWithoutTheBuried (1 and 2 ranks, newton off and on; pair_style granular,
     and granular/opt on the first grid with newton off): an 8 x 8 x 6 lattice
     bed falls asleep, 80 spheres rain on it at ~1 m/s and wake sleepers. With fix bury/gran
     (halo 6.5 um) the lower layers are buried (192 atoms before the rain lands, the lowest
     layer of 64 at the end) and every atom's position and sleeping flag after the run equal
     those of the run without it. Not bit for bit: atom_modify first reorders the owned atoms
     at every exchange, and the forced builds happen on other steps, so the pair style adds the
     forces on an atom in another order (relative round-off 1e-16 per step). Measured: 2e-18 m
     at most over 3000 steps; the tolerance 1e-16 m (5e-11 of a diameter) is 50 times that,
     and a contact missed for a single step moves an atom by orders of magnitude more (a
     sleeper woken next to the buried zone, its support missing on the step of the wake, with
     a halo below the one required: 3e-4 m/s in velocity on the next step). Positions are compared up to a
     box length in x and y (the runs wrap atoms into the box on different steps). Also checked
     at the end: buried atoms exist, none is in the pair's neighbor list (as atom or neighbor)
     nor a ghost on any rank, and the list holds exactly the group's owned atoms.
   - WokenSleeperGetsItsBuriedNeighbours (1 and 2 ranks): six touching sleepers stacked in z
     (contact histories built by spinning them before they fell asleep), a sphere 0.115 um
     above the top one: the lower three are buried. The sphere falls onto the top sleeper,
     which wakes with the fifth (touching it). On that step atoms 2 and 3 rejoin the group
     (atom 1 stays buried), but are not yet in the list; on the next step the pair's list
     holds them and their contacts, with the histories they had when they were buried (both
     atoms of contacts 2-3 and 3-4 asleep: nothing advances them).
   - KeptHistoriesSurviveARestart (1 and 2 ranks): the same, continued from a restart written
     while atoms 1-3 are buried and read by another instance (whose pair starts its own contact
     histories afresh): contacts 2-3 and 3-4 come back from fix bury/gran's restart data.
   - Errors: halo below the neighbor cutoff plus two diameters and the skin, the group missing from atom_modify
     first, neigh_modify include, comm_modify group, no such sleep fix, a fix of another style,
     fix bury/gran before the sleep fix, fix deposit after it.

   Checked against broken code: without the forced build after the group changed, the woken
   sleeper's test finds contacts 2-3 and 3-4 missing from the list on the next step; with the
   halo ignored (every sleeper buried: 384) the positions differ by 7.4e-6 m and the sleeping
   flags differ; with the histories not given back, the
   rejoined contacts start from zero (and, for the restart, with the kept histories not read
   back from the restart file). */
#include "gc_testing.h"

#include "bury_cells.h"

#include "atom.h"
#include "fix.h"
#include "fix_neigh_history.h"
#include "force.h"
#include "group.h"
#include "modify.h"
#include "neigh_list.h"
#include "pair.h"

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "library.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

using gctest::Lmp;
using gctest::nprocs;
using gctest::rank;
using LAMMPS_NS::NeighList;

namespace {
const char *MODEL = "jkr/marshall 2e8 0.7 0.33 0.01 damping marshall tangential marshall 0.3 "
                    "rolling marshall 0.01 twisting marshall/jkr";
constexpr double A = 1.995e-6;
constexpr int NSTEPS = 3000;
constexpr double HALO = 6.5e-6;    // >= the neighbor cutoff 2.2 um + 2 diameters + the skin

// the commands that make group `active` the one LAMMPS bins, lists, ghosts and integrates
const std::vector<std::string> ACTIVE = {"group active empty", "atom_modify first active",
                                         "neigh_modify include active",
                                         "comm_modify group active"};

// test_sleep_wake.cpp's rain deck with a bed of 6 layers: asleep at step 1000000, 80 spheres rain
std::vector<std::string> rain_deck(const std::string &grid, const std::string &newton, bool bury,
                                   const std::string &pair = "granular")
{
  std::vector<std::string> d = {"units si", "atom_style sphere", "atom_modify map array",
                                "boundary p p f", "newton " + newton, "comm_modify vel yes",
                                "processors " + grid, fmt::format("lattice sc {}", A),
                                "region box block 0 8 0 8 -1 40", "create_box 1 box"};
  if (bury) d.insert(d.end(), ACTIVE.begin(), ACTIVE.end());
  const std::string g = bury ? "active" : "all";
  // granular/opt: its floor wall/gran/opt on the group (looping over the first atoms only) and
  // gravity on all, so that the buried atoms get forces that nothing clears and must not move
  const bool opt = pair == "granular/opt";
  const std::string floor = opt ? "fix floor " + g + " wall/gran/opt granular " : "fix floor all wall/gran granular ";
  const std::string gravity = opt ? "all" : g;
  std::vector<std::string> rest = {
      "region cells block 0 8 0 8 0 5", "create_atoms 1 region cells", "group bed region cells",
      "set group all diameter 2.0e-6", "set group all density 2500", "pair_style " + pair,
      std::string("pair_coeff * * ") + MODEL,
      floor + MODEL + " zplane -0.999e-6 NULL",
      "neighbor 2e-7 bin", "neigh_modify every 1 delay 0 check yes",
      "fix integrate " + g + " nve/sphere", "fix grav " + gravity + " gravity 9.81 vector 0 0 -1",
      "timestep 5e-9", "thermo 0", "reset_timestep 999999",
      "fix sleep all sleep/gran speed 1e3 force 1.0 wake 1e-7 time 0 every 1000000"};
  d.insert(d.end(), rest.begin(), rest.end());
  if (bury) d.push_back(fmt::format("fix bury all bury/gran sleep sleep active active halo {}", HALO));
  std::vector<std::string> rain = {
      "run 1", "region above block EDGE EDGE EDGE EDGE 13.0e-6 24e-6 units box",
      "create_atoms 1 random 80 4711 above overlap 2.2e-6 maxtry 1000 units box",
      "group rain subtract all bed", "set group rain diameter 2.0e-6",
      "set group rain density 2500", "velocity rain create 1e8 77 loop geom",
      "velocity rain set NULL NULL -1.0 sum yes"};
  d.insert(d.end(), rain.begin(), rain.end());
  return d;
}

// The pair's list on this rank against the group: returns the owned atoms outside the group
// found in the list (as atom or neighbor) plus the ghosts outside the group; sets `listed` to
// the list's atoms and `in_group` to the owned atoms of the group
int buried_in_list_or_ghost(Lmp &l, int &listed, int &in_group)
{
  auto *atom = l.lmp->atom;
  const int bit = l.lmp->group->bitmask[l.lmp->group->find("active")];
  NeighList *list = l.lmp->force->pair->list;
  int bad = 0;
  for (int ii = 0; ii < list->inum; ii++) {
    const int i = list->ilist[ii];
    if (!(atom->mask[i] & bit)) bad++;
    for (int jj = 0; jj < list->numneigh[i]; jj++)
      if (!(atom->mask[list->firstneigh[i][jj] & NEIGHMASK] & bit)) bad++;
  }
  for (int i = atom->nlocal; i < atom->nlocal + atom->nghost; i++)
    if (!(atom->mask[i] & bit)) bad++;
  listed = list->inum;
  in_group = 0;
  for (int i = 0; i < atom->nlocal; i++)
    if (atom->mask[i] & bit) in_group++;
  return bad;
}

// fix NEIGH_HISTORY's partner arrays (protected, no accessor in LAMMPS 4Feb2025)
struct History : public LAMMPS_NS::FixNeighHistory {
  static int dnum_of(LAMMPS_NS::FixNeighHistory *f) { return f->*(&History::dnum); }
};

LAMMPS_NS::FixNeighHistory *history_fix(Lmp &l)
{
  auto fixes = l.lmp->modify->get_fix_by_style("^NEIGH_HISTORY");
  return fixes.empty() ? nullptr : dynamic_cast<LAMMPS_NS::FixNeighHistory *>(fixes.front());
}

// the contact histories of the pair's list on this rank, keyed by (tag of i, tag of j) as the
// list holds them (i's side), touching pairs only
std::map<std::pair<int, int>, std::vector<double>> listed_histories(Lmp &l)
{
  auto *atom = l.lmp->atom;
  auto *h = history_fix(l);
  const int dnum = History::dnum_of(h);
  NeighList *list = l.lmp->force->pair->list;
  std::map<std::pair<int, int>, std::vector<double>> out;
  for (int ii = 0; ii < list->inum; ii++) {
    const int i = list->ilist[ii];
    for (int jj = 0; jj < list->numneigh[i]; jj++) {
      if (!h->firstflag[i][jj]) continue;
      const int j = list->firstneigh[i][jj] & NEIGHMASK;
      const double *v = &h->firstvalue[i][dnum * jj];
      out[{(int) atom->tag[i], (int) atom->tag[j]}] = std::vector<double>(v, v + dnum);
    }
  }
  return out;
}

// every contact of the lists of all ranks, on rank 0 (a pair listed on two ranks, newton off
// with a ghost, appears with both orientations; each must match)
std::map<std::pair<int, int>, std::vector<double>> all_histories(Lmp &l)
{
  auto mine = listed_histories(l);
  const int dnum = History::dnum_of(history_fix(l));
  std::vector<double> flat;
  for (auto &kv : mine) {
    flat.push_back(kv.first.first);
    flat.push_back(kv.first.second);
    flat.insert(flat.end(), kv.second.begin(), kv.second.end());
  }
  int n = (int) flat.size();
  std::vector<int> counts(nprocs()), displs(nprocs());
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, MPI_COMM_WORLD);
  int total = 0;
  for (int r = 0; r < nprocs(); r++) {
    displs[r] = total;
    total += counts[r];
  }
  std::vector<double> all(total);
  MPI_Allgatherv(flat.data(), n, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE,
                 MPI_COMM_WORLD);
  std::map<std::pair<int, int>, std::vector<double>> out;
  for (size_t k = 0; k < all.size(); k += 2 + dnum)
    out[{(int) all[k], (int) all[k + 1]}] =
        std::vector<double>(all.begin() + k + 2, all.begin() + k + 2 + dnum);
  return out;
}

}    // namespace

TEST(BuryGran, SameTrajectoryWithoutTheBuried)
{
  const int np = nprocs();
  std::vector<std::string> grids;
  if (np == 1) grids = {"1 1 1"};
  if (np == 2) grids = {"2 1 1", "1 2 1"};
  if (grids.empty()) GTEST_SKIP() << "grids for 1 and 2 ranks";
  for (const auto &grid : grids) {
    // pair_style granular, newton off and on; granular/opt (its own contact list) newton off
    for (const auto &[newton, pair] : std::vector<std::pair<std::string, std::string>>{
             {"off", "granular"}, {"on", "granular"}, {"off", "granular/opt"}}) {
      if (pair == "granular/opt" && grid != grids.front()) continue;
      Lmp ref, bur;
      ref.cmds(rain_deck(grid, newton, false, pair));
      bur.cmds(rain_deck(grid, newton, true, pair));
      ref.cmd("run " + std::to_string(NSTEPS));
      bur.cmd("run " + std::to_string(NSTEPS));
      const auto xr = gctest::gather(ref, "x", 3), xb = gctest::gather(bur, "x", 3);
      ASSERT_EQ(xr.size(), xb.size());
      double worst = 0.0;
      // the same position up to a box length in x and y (periodic): the runs build their lists,
      // and so wrap the atoms into the box, on different steps
      const double len[3] = {8 * A, 8 * A, 0.0};
      for (size_t k = 0; k < xr.size(); k++) {
        double d = xr[k] - xb[k];
        if (len[k % 3] > 0.0) d -= len[k % 3] * std::round(d / len[k % 3]);
        worst = std::max(worst, std::fabs(d));
      }
      std::vector<double> sr(xr.size() / 3), sb(xr.size() / 3);
      lammps_gather(ref.lmp, "f_sleep", 1, 1, sr.data());
      lammps_gather(bur.lmp, "f_sleep", 1, 1, sb.data());
      const double woken = ref.var("f_sleep[4]"), buried = bur.var("f_bury[2]");
      int listed = 0, in_group = 0;
      const int bad = buried_in_list_or_ghost(bur, listed, in_group);
      int bad_all = 0;
      MPI_Allreduce(&bad, &bad_all, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
      if (rank() == 0)
        std::printf("[ %s grid %s newton %s ] woken %g, buried %g, active %g, recomputes %g, "
                    "forced builds %g, largest |dx| %.3g m\n",
                    pair.c_str(), grid.c_str(), newton.c_str(), woken, buried, bur.var("f_bury[1]"),
                    bur.var("f_bury[3]"), bur.var("f_bury[4]"), worst);
      const std::string where = pair + ", grid " + grid + ", newton " + newton;
      EXPECT_GT(woken, 10.0) << where << ": the rain wakes sleepers";
      EXPECT_GE(buried, 64.0) << where << ": the lowest layer is buried";
      EXPECT_EQ(bur.var("f_bury[1]") + buried, bur.var("count(all)")) << where;
      EXPECT_LT(worst, 1e-16) << where << ": positions as without fix bury/gran";
      EXPECT_EQ(sr, sb) << where << ": the same sleepers";
      EXPECT_EQ(bad_all, 0) << where << ": buried atoms in the list or sent as ghosts";
      EXPECT_EQ(listed, in_group) << where << ": the list holds the group's owned atoms";
    }
  }
}

// sleepers 1-6 stacked in z (touching: 1.995 um apart), sphere 7 0.115 um above sleeper 6:
// sleepers 1-3 (more than 6.5 um below sphere 7) are buried; on 2 ranks the column is owned by
// rank 0 and is a ghost of rank 1
// via_restart: the run is continued from a restart written while atoms 1-3 are buried, read by
// another LAMMPS instance of this process (which starts the pair's own contact histories afresh:
// LAMMPS names its fix NEIGH_HISTORY per instance), so that the rejoined contacts' histories come
// from fix bury/gran's per-atom restart data alone
void woken_sleeper(bool via_restart)
{
  const int np = nprocs();
  auto owner = std::make_unique<Lmp>();
  Lmp &l = *owner;
  l.cmds({"units si", "atom_style sphere", "atom_modify map array", "boundary p p f",
          "newton off", "comm_modify vel yes", fmt::format("processors {} 1 1", np),
          "region box block 0 24e-6 0 8e-6 0 20e-6", "create_box 1 box"});
  l.cmds(ACTIVE);
  for (int k = 0; k < 6; k++)
    l.cmd(fmt::format("create_atoms 1 single 11.0e-6 4e-6 {} units box", 1.0e-6 + k * A));
  l.cmds({"create_atoms 1 single 11.0e-6 4e-6 13.09e-6 units box", "set group all diameter 2.0e-6",
          "set group all density 2500", "group column id 1:6", "group falling id 7",
          "pair_style granular", std::string("pair_coeff * * ") + MODEL, "neighbor 2e-7 bin",
          "neigh_modify every 1 delay 0 check yes", "fix integrate active nve/sphere",
          "timestep 5e-9", "thermo 0",
          "fix sleep all sleep/gran speed 1e3 force 1.0 wake 1e-8 time 0 every 1000000",
          fmt::format("fix bury all bury/gran sleep sleep active active halo {}", HALO),
          // spinning builds tangential, rolling and twisting histories; the column falls asleep
          // on step 1000000, sphere 7 (touching nothing) stays awake
          "set atom 1 omega 2e3 0 1e3", "set atom 2 omega 0 -1e3 3e3", "set atom 3 omega -1e3 2e3 0", "set atom 4 omega 1e3 1e3 -2e3",
          "reset_timestep 999800", "run 200"});
  ASSERT_EQ(l.var("f_sleep[2]"), 6.0) << "the column sleeps";
  // the histories of the column's contacts when it was buried (the list of the last build)
  const auto buried_with = all_histories(l);
  ASSERT_GE(buried_with.size(), 5u) << "contacts 1-2, ..., 5-6";
  bool nonzero = false;
  for (auto &kv : buried_with)
    for (double v : kv.second) nonzero = nonzero || std::fabs(v) > 0.0;
  ASSERT_TRUE(nonzero) << "the spin built histories";

  l.cmd("velocity falling set 0 0 -0.3 sum no");
  l.cmd("run 1");
  EXPECT_EQ(l.var("f_bury[2]"), 3.0) << "atoms 1, 2 and 3 buried";
  for (auto &kv : all_histories(l)) {
    EXPECT_GT(kv.first.first, 3) << "a buried atom listed";
    EXPECT_GT(kv.first.second, 3) << "a buried atom listed";
  }
  if (via_restart) {
    const std::string file = "bury_gran_woken.restart";
    l.cmd("write_restart " + file);
    owner = std::make_unique<Lmp>();
    owner->cmds({"read_restart " + file, "atom_modify first active", "neigh_modify include active",
                 "comm_modify group active", "comm_modify vel yes", "pair_style granular",
                 std::string("pair_coeff * * ") + MODEL, "neighbor 2e-7 bin",
                 "neigh_modify every 1 delay 0 check yes", "fix integrate active nve/sphere",
                 "thermo 0",
                 "fix sleep all sleep/gran speed 1e3 force 1.0 wake 1e-8 time 0 every 1000000",
                 fmt::format("fix bury all bury/gran sleep sleep active active halo {}", HALO),
                 "run 0"});
    MPI_Barrier(MPI_COMM_WORLD);
    if (rank() == 0) std::remove(file.c_str());
    EXPECT_EQ(owner->var("f_bury[2]"), 3.0) << "atoms 1, 2 and 3 buried after read_restart";
  }
  Lmp &l2 = *owner;
  int steps = 0;
  while (l2.var("f_sleep[4]") == 0.0 && steps < 400) {
    l2.cmd("run 1 pre no post no");
    steps++;
  }
  ASSERT_GT(l2.var("f_sleep[4]"), 0.0) << "sphere 7 reaches sphere 6 within 400 steps";
  std::vector<double> sleeping(7);
  lammps_gather(l2.lmp, "f_sleep", 1, 1, sleeping.data());
  EXPECT_EQ(sleeping[5], 0.0) << "sphere 6, pushed, wakes";
  EXPECT_EQ(sleeping[4], 0.0) << "sphere 5 touches sphere 6";
  EXPECT_EQ(sleeping[3], 1.0) << "sphere 4 sleeps";
  // sphere 5 (8.98 um) is the lowest awake: 4, 3 and 2 (6 um below it) rejoin, 1 stays buried
  EXPECT_EQ(l2.var("f_bury[2]"), 1.0) << "on the step of the wake, atoms 2 and 3 rejoin the group";
  int in_list_before = 0;
  for (auto &kv : all_histories(l2))
    if (kv.first.first == 2 || kv.first.second == 2) in_list_before++;
  EXPECT_EQ(in_list_before, 0) << "atom 2 not yet in the list of the last build";

  l2.cmd("run 1 pre no post no");
  const auto rejoined = all_histories(l2);
  int listed = 0, in_group = 0, bad = 0;
  const int mine = buried_in_list_or_ghost(l2, listed, in_group);
  MPI_Allreduce(&mine, &bad, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_EQ(bad, 0) << "atom 1, buried, in the list or a ghost";
  for (auto &kv : buried_with) {
    const auto &key = kv.first;
    if (key.first > 4 || key.second > 4) continue;    // 5 and 6 move from the wake on
    auto it = rejoined.find(key);
    // the pair may be listed the other way round after the build: compare i's side with the
    // side recorded for that orientation (both sides are recorded when a ghost is involved)
    if (key.first == 1 || key.second == 1) continue;    // atom 1 stays buried
    if (it == rejoined.end()) {
      bool flipped = rejoined.count({key.second, key.first}) > 0;
      EXPECT_TRUE(flipped) << "contact " << key.first << "-" << key.second
                           << " computed on the step after the wake";
      continue;
    }
    ASSERT_EQ(it->second.size(), kv.second.size());
    for (size_t k = 0; k < kv.second.size(); k++)
      // both atoms asleep since the record, or atom 3 woken with zero velocity and spin: no
      // increment; the tangent-plane projection of the history is the only operation (1e-12)
      EXPECT_NEAR(it->second[k], kv.second[k], 1e-12 * std::fabs(kv.second[k]) + 1e-30)
          << "contact " << key.first << "-" << key.second << " history value " << k;
  }
  for (auto &kv : rejoined) {
    EXPECT_NE(kv.first.first, 1) << "atom 1, still buried, listed";
    EXPECT_NE(kv.first.second, 1) << "atom 1, still buried, listed";
  }
  // the contacts of the rejoined atoms are in the list (either orientation)
  for (const std::pair<int, int> c : {std::make_pair(2, 3), std::make_pair(3, 4)})
    EXPECT_TRUE(rejoined.count(c) || rejoined.count({c.second, c.first}))
        << "contact " << c.first << "-" << c.second << " in the list after the wake";
}

TEST(BuryGran, WokenSleeperGetsItsBuriedNeighbours)
{
  if (nprocs() > 2) GTEST_SKIP() << "1 and 2 ranks";
  woken_sleeper(false);
}

TEST(BuryGran, KeptHistoriesSurviveARestart)
{
  if (nprocs() > 2) GTEST_SKIP() << "1 and 2 ranks";
  woken_sleeper(true);
}

// a one-atom deck with the group commands `active` and the fixes `fixes`, then run 0
std::vector<std::string> error_deck(const std::vector<std::string> &active,
                                    const std::vector<std::string> &fixes,
                                    const std::string &integrated = "active")
{
  std::vector<std::string> d = {"units si", "atom_style sphere", "boundary p p f",
                                "region box block 0 8e-6 0 8e-6 0 8e-6", "create_box 1 box",
                                "comm_modify vel yes", "group active empty", "group other empty"};
  d.insert(d.end(), active.begin(), active.end());
  for (const std::string &c : std::vector<std::string>{
           "create_atoms 1 single 4e-6 4e-6 3e-6 units box", "set group all diameter 2.0e-6",
        "set group all density 2500", "pair_style granular", "neighbor 2e-7 bin",
        "fix integrate " + integrated + " nve/sphere", "timestep 5e-9"})
    d.push_back(c);
  d.push_back(std::string("pair_coeff * * ") + MODEL);
  d.insert(d.end(), fixes.begin(), fixes.end());
  d.push_back("run 0");
  return d;
}

TEST(BuryGran, InputErrors)
{
  using ::testing::HasSubstr;
  const std::vector<std::string> all3 = {"atom_modify first active", "neigh_modify include active",
                                         "comm_modify group active"};
  const std::string sleep = "fix sleep all sleep/gran speed 1 force 1 wake 1 time 0";
  const std::string bury = "fix bury all bury/gran sleep sleep active active halo 6.5e-6";
  // the deck with all three commands and both fixes runs
  EXPECT_EQ(gctest::error_of(error_deck(all3, {sleep, bury})), "no error");
  // buried atoms are held by not being integrated
  for (const std::string g : {"all", "other"})
    EXPECT_THAT(gctest::error_of(error_deck(all3, {sleep, bury}, g)),
                HasSubstr("fix integrate (nve/sphere) integrates group " + g +
                          "; with buried atoms every integrator must have group active"));

  EXPECT_THAT(gctest::error_of(error_deck(all3, {sleep, "fix bury all bury/gran sleep sleep active active halo 6e-6"})),
              HasSubstr("halo 6e-06 is below the neighbor cutoff"));
  EXPECT_THAT(gctest::error_of(error_deck({"atom_modify first other", "neigh_modify include other",
                                           "comm_modify group other"},
                                          {sleep, bury})),
              HasSubstr("requires the command: atom_modify first active"));
  EXPECT_THAT(gctest::error_of(error_deck({"atom_modify first active", "comm_modify group active"},
                                          {sleep, bury})),
              HasSubstr("requires the command: neigh_modify include active"));
  EXPECT_THAT(gctest::error_of(error_deck({"atom_modify first active", "neigh_modify include active"},
                                          {sleep, bury})),
              HasSubstr("requires the command: comm_modify group active"));
  EXPECT_THAT(gctest::error_of(error_deck(all3, {sleep, "fix bury all bury/gran sleep nosuch active active halo 6.5e-6"})),
              HasSubstr("sleep: no fix with ID nosuch"));
  EXPECT_THAT(gctest::error_of(error_deck(all3, {sleep, "fix bury all bury/gran sleep integrate active active halo 6.5e-6"})),
              HasSubstr("fix integrate is nve/sphere, not sleep/gran"));
  EXPECT_THAT(gctest::error_of(error_deck(all3, {bury, sleep})),
              HasSubstr("must be defined after fix sleep (sleep/gran)"));
  EXPECT_THAT(gctest::error_of(error_deck(all3, {sleep, "fix bury all bury/gran sleep sleep active nosuch halo 6.5e-6"})),
              HasSubstr("active: no group nosuch"));
  EXPECT_THAT(gctest::error_of(error_deck(all3, {sleep, "fix bury all bury/gran sleep sleep active active halo -1"})),
              HasSubstr("halo must be > 0 (distance units), got -1"));
  EXPECT_THAT(gctest::error_of(error_deck(all3, {sleep, "fix bury all bury/gran sleep sleep active active halo 6.5e-6 every 0"})),
              HasSubstr("every must be >= 1, got 0"));
  EXPECT_THAT(gctest::error_of(error_deck(all3, {sleep, bury,
                                                 "region top block EDGE EDGE EDGE EDGE 6e-6 8e-6 units box",
                                                 "fix drop all deposit 1 1 100 12345 region top"})),
              HasSubstr("must be defined after fix drop (deposit)"));
}

// the cell window against its definition, on random grids: every axis periodic or clamped,
// windows from 0 cells to wider than the ring, sparse and dense flags
TEST(BuryCells, WindowAnyAsItsDefinition)
{
  std::mt19937 rng(20261207);
  for (int trial = 0; trial < 400; trial++) {
    const int n[3] = {1 + (int) (rng() % 9), 1 + (int) (rng() % 9), 1 + (int) (rng() % 13)};
    const int axis = (int) (rng() % 3), k = (int) (rng() % 12);
    const bool periodic = rng() % 2;
    const double density = (rng() % 4) * 0.1;
    std::vector<unsigned char> v(static_cast<size_t>(n[0]) * n[1] * n[2]);
    std::bernoulli_distribution flag(density);
    for (auto &f : v) f = flag(rng) ? 1 : 0;
    auto at = [&](const std::vector<unsigned char> &g, int c[3]) {
      return g[(static_cast<size_t>(c[2]) * n[1] + c[1]) * n[0] + c[0]];
    };
    std::vector<unsigned char> expected(v.size());
    for (int z = 0; z < n[2]; z++)
      for (int y = 0; y < n[1]; y++)
        for (int x = 0; x < n[0]; x++) {
          int c[3] = {x, y, z};
          const int e = c[axis];
          bool any = false;
          for (int o = e - k; o <= e + k && !any; o++) {
            int m = o;
            if (periodic) m = ((o % n[axis]) + n[axis]) % n[axis];
            else if (o < 0 || o >= n[axis]) continue;
            int d[3] = {x, y, z};
            d[axis] = m;
            any = at(v, d) != 0;
          }
          expected[(static_cast<size_t>(z) * n[1] + y) * n[0] + x] = any ? 1 : 0;
        }
    GranularCharged::window_any(v, n, axis, k, periodic);
    ASSERT_EQ(v, expected) << "grid " << n[0] << "x" << n[1] << "x" << n[2] << ", axis " << axis
                           << ", k " << k << (periodic ? ", periodic" : ", clamped");
  }
}

TEST(BuryCells, ColumnIndexWrapsOrClamps)
{
  using GranularCharged::column_index;
  EXPECT_EQ(column_index(0.5, 0.0, 1.0, 4, true), 0);
  EXPECT_EQ(column_index(-0.5, 0.0, 1.0, 4, true), 3);
  EXPECT_EQ(column_index(4.5, 0.0, 1.0, 4, true), 0);
  EXPECT_EQ(column_index(-0.5, 0.0, 1.0, 4, false), 0);
  EXPECT_EQ(column_index(9.0, 0.0, 1.0, 4, false), 3);
  EXPECT_EQ(column_index(2.5, 1.0, 0.5, 8, false), 3);
}
