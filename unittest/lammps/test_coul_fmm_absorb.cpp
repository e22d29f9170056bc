/* GRANULAR-CHARGED: fix coul/fmm absorbing charge changes between evaluations (keyword qchange,
   doc/theory.md, eqs. (5.5)-(5.6)): the refreshed near pairs sum the changed charges exactly,
   the far part of the changes is bounded and forces an evaluation when the bound exceeds the
   allowance. Charges are changed within a run by fix adapt (owned and ghost atoms) and between
   runs by set (owned atoms only: the ghosts' charges are the fix's to refresh). Errors are
   relative RMS force errors, as for keyword check. */
#include "gc_testing.h"

#include "fix.h"
#include "library.h"
#include "modify.h"
#include "gtest/gtest.h"

#include <cmath>
#include <string>
#include <vector>

using gctest::gather;
using gctest::Lmp;
using gctest::nprocs;
using gctest::rel_rms;

namespace {

// 200 heavy charges +-1 moving at random (300 K), IDs 1-200 (rank-dependent positions: each
// test compares within one rank count)
void moving_charges(Lmp &l, const std::string &boundary, int n = 200)
{
  l.cmds({"units real", "atom_style charge", "atom_modify map array sort 0 0",
          "boundary " + boundary, "region box block 0 20 0 20 0 40", "create_box 1 box",
          fmt::format("create_atoms 1 random {} 61 NULL overlap 0.5 maxtry 200", n),
          "mass 1 1000.0", "variable qq atom 2*(id%2)-1", "set group all charge v_qq",
          "neighbor 1.0 bin", "velocity all create 300 5 loop geom", "fix nve all nve",
          "timestep 1.0"});
}

// every step from now on: atoms 3 (+1) and 10 (-1) exchange a growing charge (a transfer, +x
// and -x) and atom 21 (+1) gains charge (a net change, as from a grounded wall); rate per step
void change_charges_every_step(Lmp &l, double rate)
{
  const int now = (int) l.var("step");
  l.cmds({"group ga id 3", "group gb id 10", "group gc id 21",
          fmt::format("variable qa equal 1.0+{}*(step-{})", rate, now),
          fmt::format("variable qb equal -1.0-{}*(step-{})", rate, now),
          fmt::format("variable qc equal 1.0+{}*(step-{})", 0.5 * rate, now),
          "fix ada ga adapt 1 atom charge v_qa reset no",
          "fix adb gb adapt 1 atom charge v_qb reset no",
          "fix adc gc adapt 1 atom charge v_qc reset no"});
}

// the forces of fix `id` against a fresh fix at the same positions and charges (order 30:
// round-off level; the fix is removed)
double error_against_fresh(Lmp &l, const std::string &id)
{
  const auto f = gather(l, "f", 3);
  l.cmds({"unfix " + id, "fix fresh all coul/fmm accuracy 1e-10 order 30", "run 0 post no"});
  return rel_rms(f, gather(l, "f", 3));
}

// a fix that declares charge transfers as fix tribo/charge does (extract "charge_transfers")
class FixDeclaresTransfers : public LAMMPS_NS::Fix {
 public:
  FixDeclaresTransfers(LAMMPS_NS::LAMMPS *lmp, int narg, char **arg) : Fix(lmp, narg, arg) {}
  int setmask() override { return 0; }
  void *extract(const char *name, int &dim) override
  {
    dim = 0;
    return std::string(name) == "charge_transfers" ? &transfers : nullptr;
  }
  int transfers = 1;
};

void register_transfers_fix(Lmp &l)
{
  (*l.lmp->modify->fix_map)["transfers/test"] = [](LAMMPS_NS::LAMMPS *lmp, int narg,
                                                   char **arg) -> LAMMPS_NS::Fix * {
    return new FixDeclaresTransfers(lmp, narg, arg);
  };
}

}    // namespace

// free space, near cutoff beyond the box diagonal: every pair is refreshed, so with the changed
// charges summed as q_j(now) K(r_now) - q_j(then) K(r_then) the applied field is a fresh
// evaluation's to round-off (the refresh is a direct sum of differences, as in
// NearRefreshAndCheck: 1e-9) with a single evaluation in 30 steps. Without the change's term
// (q_j(now) [K(r_now) - K(r_then)] only) the field is off by the change's own field, ~0.3 of a
// unit charge here: ~1e-3 of the RMS force.
TEST(CoulFMMAbsorb, ChangesWithinTheNearCutoffAreExact)
{
  Lmp l;
  moving_charges(l, "m m m");
  change_charges_every_step(l, 0.01);
  l.cmds({"fix fmm all coul/fmm accuracy 1e-10 order 30 every 64 near 100.0 qchange absorb "
          "check 5",
          "run 30 post no"});
  const double evaluations = l.var("f_fmm[10]"), absorbed = l.var("f_fmm[15]"),
               forced = l.var("f_fmm[16]"), checked = l.var("f_fmm[6]");
  const double by_hand = error_against_fresh(l, "fmm");
  std::printf("[ absorb, free space ] %g evaluations in 30 steps, %g changes absorbed, %g "
              "forced; checked error (largest) %.3g, at step 30 by hand %.3g\n",
              evaluations, absorbed, forced, checked, by_hand);
  EXPECT_EQ(evaluations, 1.0);
  EXPECT_EQ(absorbed, 3.0 * 30);    // three atoms on each of steps 1-30
  EXPECT_EQ(forced, 0.0);
  EXPECT_LT(checked, 1e-9);
  EXPECT_GT(checked, 0.0);
  EXPECT_LT(by_hand, 1e-9);
  // the same changes evaluated (qchange evaluate): an evaluation on every step
  Lmp e;
  moving_charges(e, "m m m");
  change_charges_every_step(e, 0.01);
  e.cmds({"fix fmm all coul/fmm accuracy 1e-10 order 30 every 64 near 100.0 qchange evaluate",
          "run 30 post no"});
  EXPECT_EQ(e.var("f_fmm[10]"), 31.0);
  EXPECT_EQ(e.var("f_fmm[15]"), 0.0);
}

// changes between runs stay absorbed across the runs: run ... pre no every 1 with set after
// each one-step run (set changes the owned atoms only, and pre no has no setup, so builds no
// ghosts: on two ranks the fix must hand the new charges to the ghosts, or the near refresh
// sums the old ones there). One evaluation in 22 steps, and the field a fresh evaluation's to
// round-off on every step (check 1) and at the end. The set after the last of the 20 runs is
// absorbed by the run 1 after them: 2 changes on each of 20 steps.
TEST(CoulFMMAbsorb, ChangesBetweenRunsStayAbsorbed)
{
  Lmp l;
  moving_charges(l, "m m m");
  l.cmds({"variable qa equal 1.0+0.02*step", "variable qb equal -1.0-0.02*step",
          "fix fmm all coul/fmm accuracy 1e-10 order 30 every 64 near 100.0 qchange absorb "
          "check 1",
          "run 1 post no",
          "run 20 pre no post no every 1 \"set atom 3 charge ${qa}\" \"set atom 10 charge ${qb}\"",
          "run 1 pre no post no"});
  const double evaluations = l.var("f_fmm[10]"), absorbed = l.var("f_fmm[15]"),
               checked = l.var("f_fmm[6]");
  const double error = error_against_fresh(l, "fmm");
  std::printf("[ absorb, between runs ] %g evaluations in 22 steps, %g changes absorbed, "
              "checked (largest) %.3g, error against fresh %.3g\n",
              evaluations, absorbed, checked, error);
  EXPECT_EQ(evaluations, 1.0);
  EXPECT_EQ(absorbed, 2.0 * 20);
  EXPECT_LT(checked, 1e-9);
  EXPECT_LT(error, 1e-9);
}

// p p m (x and y periodic), near 5 (about 1.3 spacings), tolerance 1e-4, the changes starting after 60 steps of
// motion (the interval has grown): small changes are absorbed (no evaluation forced) and the
// checked error stays within the tolerance (in ToleranceAdaptsTheInterval, without changes,
// it is 2e-5); large ones exceed the bound on the far part and force evaluations, and the
// checked error stays within it too. The bound is C sum |dq| / rc^2 against tau E_rms:
// 1e-6 per step stays below it for the whole interval, 1e-3 per step exceeds it within a step.
TEST(CoulFMMAbsorb, FarBoundForcesEvaluationsOnlyForLargeChanges)
{
  auto run = [](double rate) {
    Lmp l;
    moving_charges(l, "p p m");
    l.cmds({"mass 1 100000.0",
            "fix fmm all coul/fmm accuracy 1e-10 order 30 every 64 near 5.0 tolerance 1e-4 "
            "qchange absorb check 3",
            "run 60 post no"});
    const double before = l.var("f_fmm[10]");
    change_charges_every_step(l, rate);
    l.cmd("run 120 post no");
    return std::vector<double>{l.var("f_fmm[10]") - before, l.var("f_fmm[15]"),
                               l.var("f_fmm[16]"), l.var("f_fmm[7]"), l.var("f_fmm[6]")};
  };
  const auto small = run(1e-6), large = run(1e-3);
  std::printf("[ absorb, p p m ] 1e-6 per step: %g evaluations in 120 steps, %g absorbed, %g "
              "forced, checked %.3g (largest %.3g); 1e-3: %g evaluations, %g absorbed, %g "
              "forced, checked %.3g\n",
              small[0], small[1], small[2], small[3], small[4], large[0], large[1], large[2],
              large[3]);
  EXPECT_LT(small[0], 30.0);
  EXPECT_EQ(small[2], 0.0);
  EXPECT_EQ(small[1], 3.0 * (120.0 - small[0]));    // three atoms on every step continued
  EXPECT_LE(small[3], 1e-4);
  EXPECT_GT(small[3], 0.0);
  EXPECT_GT(large[2], 0.0);
  EXPECT_GT(large[0], 60.0);
  EXPECT_LE(large[3], 1e-4);
}

// a fix declaring charge transfers turns absorbing on by default, whichever is defined first;
// qchange evaluate keeps evaluating
TEST(CoulFMMAbsorb, DeclaredTransfersTurnAbsorbingOn)
{
  auto run = [](const std::string &keyword, bool transfers_first) {
    Lmp l;
    register_transfers_fix(l);
    moving_charges(l, "m m m");
    change_charges_every_step(l, 0.01);
    const std::string coul = "fix fmm all coul/fmm accuracy 1e-6 every 64 near 100.0 " + keyword;
    if (transfers_first) l.cmd("fix tribo all transfers/test");
    l.cmd(coul);
    if (!transfers_first) l.cmd("fix tribo all transfers/test");
    l.cmd("run 10 post no");
    return l.var("f_fmm[10]");
  };
  EXPECT_EQ(run("", true), 1.0);
  EXPECT_EQ(run("", false), 1.0);
  EXPECT_EQ(run("qchange evaluate", true), 11.0);
  EXPECT_EQ(run("qchange absorb", false), 1.0);
}

// a group without any charge at the start (a deposition charged by contacts): no error, no
// division by zero; the first charges are added charges (evaluated), later changes absorbed
// or evaluated by the bound, and the applied forces stay within the tolerance of a fresh
// evaluation (here at the requested accuracy's level 1e-4 plus the time stepping's)
TEST(CoulFMMAbsorb, NeutralStartChargedLater)
{
  Lmp l;
  l.cmds({"units real", "atom_style charge", "atom_modify map array sort 0 0", "boundary p p f",
          "region box block 0 20 0 20 0 40", "create_box 1 box",
          "create_atoms 1 random 200 61 NULL overlap 0.5 maxtry 200", "mass 1 100000.0",
          "neighbor 1.0 bin", "velocity all create 300 5 loop geom", "fix nve all nve",
          "timestep 1.0",
          "fix fmm all coul/fmm accuracy 1e-6 every 64 near 5.0 tolerance 1e-4 qchange absorb",
          "fix_modify fmm energy yes", "run 20 post no"});
  EXPECT_EQ(l.var("f_fmm"), 0.0);
  EXPECT_EQ(l.var("f_fmm[15]"), 0.0);
  l.cmds({"group some id 1:40", "variable qq atom (2*(id%2)-1)*(1.0+1e-6*step)",
          "set group some charge v_qq", "run 10 post no"});
  // from now on the charges of some change by 1e-6 per step
  l.cmds({"variable qs equal 1.0+1e-6*step", "group plus id 1:40:2",
          "fix adp plus adapt 1 atom charge v_qs reset no", "run 40 post no"});
  const double energy = l.var("f_fmm");
  const double absorbed = l.var("f_fmm[15]");
  const double error = error_against_fresh(l, "fmm");
  std::printf("[ absorb, neutral start ] energy %.6g, %g changes absorbed, error against "
              "fresh %.3g\n",
              energy, absorbed, error);
  EXPECT_TRUE(std::isfinite(energy));
  EXPECT_NE(energy, 0.0);
  EXPECT_GT(absorbed, 0.0);
  EXPECT_LT(error, 1e-3);
}

// 1 and 2 ranks agree to round-off with charges absorbed (and ghosts of changed atoms): a
// jittered lattice (the same atoms on any rank count, as in CoulFMM.OneVersusTwoRanks), moving,
// near 3 (about one spacing), p p f. The near pairs are summed in another order on two ranks
// (~1e-13 after 80 steps in NearRefreshHeldPairsAsTakenEveryStep), hence 1e-10.
TEST(CoulFMMAbsorb, OneVersusTwoRanks)
{
  if (nprocs() != 2) GTEST_SKIP() << "needs mpirun -np 2";
  auto forces = [](MPI_Comm comm) {
    Lmp l(comm);
    l.cmds({"units real", "atom_style charge", "atom_modify map array sort 0 0",
            "boundary p p f", "lattice sc 2.5", "region box block 0 8 0 8 0 24",
            "create_box 1 box", "region inner block INF INF INF INF 1 23",
            "create_atoms 1 region inner", "mass 1 1000.0",
            "displace_atoms all random 0.8 0.8 0.8 31 units box", "variable qq atom 2*(id%2)-1",
            "set group all charge v_qq", "neighbor 1.0 bin",
            "velocity all create 300 5 loop geom", "fix nve all nve", "timestep 1.0"});
    change_charges_every_step(l, 1e-5);
    l.cmds({"fix fmm all coul/fmm accuracy 1e-5 every 16 near 3.0 tolerance 1e-3 qchange absorb",
            "run 40 post no"});
    auto f = gather(l, "f", 3);
    f.push_back(l.var("f_fmm[10]"));
    f.push_back(l.var("f_fmm[15]"));
    return f;
  };
  const auto two = forces(MPI_COMM_WORLD);
  int me;
  MPI_Comm_rank(MPI_COMM_WORLD, &me);
  std::vector<double> one(two.size());
  if (me == 0) one = forces(MPI_COMM_SELF);
  MPI_Bcast(one.data(), (int) one.size(), MPI_DOUBLE, 0, MPI_COMM_WORLD);
  const size_t n = two.size();
  const double d = rel_rms(std::vector<double>(two.begin(), two.end() - 2),
                           std::vector<double>(one.begin(), one.end() - 2));
  if (me == 0)
    std::printf("[ absorb, ranks ] 2 vs 1 rank: %.3g; evaluations %g / %g, absorbed %g / %g\n",
                d, two[n - 2], one[n - 2], two[n - 1], one[n - 1]);
  EXPECT_GT(two[n - 1], 0.0);
  EXPECT_EQ(two[n - 2], one[n - 2]);
  EXPECT_EQ(two[n - 1], one[n - 1]);
  EXPECT_LT(d, 1e-10);
}

// absorbed changes are part of the stored state: a run split into pieces and one continued
// from a restart file in a new instance (the charges at the evaluation, the charges when the
// field was last applied and the field scale in the file) reproduce the uninterrupted run. The
// restarted instance sums the near pairs in another order, hence 1e-10 as in
// ToleranceScheduleIndependentOfRunSplit; the split run to 1e-14.
TEST(CoulFMMAbsorb, RestartContinuesTheAbsorbedChanges)
{
  const std::string fix =
      "fix fmm all coul/fmm accuracy 1e-6 every 32 near 6.0 tolerance 1e-4 qchange absorb";
  auto charging = [](Lmp &l) {
    l.cmds({"group ga id 3", "group gb id 10", "variable qa equal 1.0+1e-5*step",
            "variable qb equal -1.0-1e-5*step", "fix ada ga adapt 1 atom charge v_qa reset no",
            "fix adb gb adapt 1 atom charge v_qb reset no"});
  };
  std::vector<double> straight, split, restarted;
  double absorbed = 0.0, evaluations = 0.0;
  {
    Lmp l;
    moving_charges(l, "p p m");
    charging(l);
    l.cmds({fix, "run 40 post no", "run 0 post no"});
    straight = gather(l, "x", 3);
    absorbed = l.var("f_fmm[15]");
    evaluations = l.var("f_fmm[10]");
  }
  {
    Lmp l;
    moving_charges(l, "p p m");
    charging(l);
    l.cmds({fix, "run 17 post no", "run 13 post no", "write_restart coul_fmm_absorb.restart",
            "run 10 post no", "run 0 post no"});
    split = gather(l, "x", 3);
    EXPECT_EQ(l.var("f_fmm[15]"), absorbed);
    EXPECT_EQ(l.var("f_fmm[10]"), evaluations);
  }
  {
    Lmp l;
    l.cmds({"read_restart coul_fmm_absorb.restart", "fix nve all nve"});
    charging(l);
    l.cmds({fix, "run 10 post no", "run 0 post no"});
    restarted = gather(l, "x", 3);
  }
  // a change so large that the bound forces the first evaluation of a new instance (at the
  // setup, a new slope not yet due: nothing of the near refresh computed before it)
  double forced = 0.0, error = 1.0;
  {
    Lmp l;
    l.cmds({"read_restart coul_fmm_absorb.restart", "fix nve all nve", "set atom 3 charge 1.5",
            fix, "run 0 post no"});
    forced = l.var("f_fmm[16]");
    error = error_against_fresh(l, "fmm");
  }
  EXPECT_EQ(forced, 1.0);
  EXPECT_LT(error, 1e-5);
  std::remove("coul_fmm_absorb.restart");
  std::printf("[ absorb, restart ] %g changes absorbed, %g evaluations in 40 steps; split %.3g, "
              "restarted %.3g\n",
              absorbed, evaluations, rel_rms(split, straight), rel_rms(restarted, straight));
  EXPECT_GT(absorbed, 0.0);
  EXPECT_LT(rel_rms(split, straight), 1e-14);
  EXPECT_LT(rel_rms(restarted, straight), 1e-10);
}

// a bad value of qchange is an error naming it
TEST(CoulFMMAbsorb, BadValue)
{
  const std::string msg = gctest::error_of(
      {"units real", "atom_style charge", "region box block 0 10 0 10 0 10", "create_box 1 box",
       "fix fmm all coul/fmm every 8 near 5 qchange maybe"});
  EXPECT_NE(msg.find("Fix coul/fmm qchange must be evaluate or absorb, got maybe"),
            std::string::npos)
      << msg;
}
