/* GRANULAR-CHARGED: fix sleep/gran with pair_style granular/opt and pair_style granular.

   - Held and computed: a bed whose atoms all sleep does not move by one bit, and its contacts
     are computed as without the fix (the pair style's count of evaluated contacts is the same).
   - The usual contact: an awake sphere hitting a sleeper follows, bit for bit, the trajectory it
     has when the other sphere is simply not integrated (zero velocity and spin): the contact has
     the pair's effective mass m_i m_j / (m_i + m_j), not the fixed-body mass of fix freeze.
   - Waking: a sleeper pushed beyond `wake` wakes, and so does the sleeper touching it; with the
     wake threshold above the push nothing wakes.
   - Restart and migration: the flags survive write_restart/read_restart and atoms moving to
     another rank (displace_atoms by half the box: on 2 ranks every atom changes rank).
   - Static sleepers in fix coul/fmm: the forces on the awake atoms and the energy, with the
     sleeping charges as a static source at accuracy 1e-4 and 1e-6, against a full evaluation
     of all charges at 1e-9 (sleepers full), on 1 and 2 ranks; the refused combinations.
   - With pair_style granular: a bed whose atoms all sleep does not move by one bit (an atom
     sleeps only with a counted contact), a pushed sleeper wakes with the sleeper touching it,
     and below the threshold nothing wakes. (test_sleep_styles.cpp: the same trajectory with
     both styles.)
   - A sphere alone on a JKR floor (fix wall/gran or wall/gran/opt) falls asleep, one at rest
     in the air does not.
   - Bad input: every refused keyword value, a pair style other than granular[/opt], a point
     particle atom style, a fix that adds forces after it, an injection into another group.

   Checked against broken code: without zeroing the velocities of sleepers HeldAndComputed fails
   (the bed moves); with the sleeper a fixed body (m* the awake atom's mass)
   ContactWithASleeperIsTheUsualContact fails (vx of the awake sphere -0.00970849 against
   -0.00929428), and without restoring the history around the fix's single() it fails in the
   last bits (the step after a slip); with the sleeper's push summed with the wrong sign or
   not at all, WakesWhenPushed fails; without pack_exchange of the flags the two-rank migration
   fails; without pack_restart the restart fails; with the fix's own contact count removed
   BaseStyleHoldsAndWakes fails (nothing sleeps), and with its push sum removed it fails
   (nothing wakes); without the wall contacts counted AnAtomAloneOnTheFloorSleeps fails (no
   sleeper). */
#include "gc_testing.h"

#include "atom.h"
#include "exceptions.h"
#include "force.h"
#include "pair_granular_opt.h"
#include "sleep_bed_reach.h"

#include "gtest/gtest.h"
#include "library.h"

#include <cmath>
#include <cstdio>

#include <regex>
#include <string>
#include <vector>

using gctest::Lmp;
using gctest::nprocs;
using gctest::rel_rms;
using gctest::gather;
using gctest::error_of;

namespace {
const char *MODEL = "jkr/marshall 2e8 0.7 0.33 0.01 damping marshall tangential marshall 0.3 "
                    "rolling marshall 0.01 twisting marshall/jkr";

// 27 spheres on a slightly compressed 3 x 3 x 3 lattice on a JKR floor: every sphere touches
// its lattice neighbours
std::vector<std::string> bed(const std::string &pair = "granular/opt")
{
  return {"units si", "atom_style sphere", "atom_modify map array", "boundary p p f",
          "newton off", "comm_modify vel yes", "lattice sc 1.995e-6",
          "region box block 0 3 0 3 -1 4", "create_box 1 box",
          "region cells block 0 3 0 2 0 2", "create_atoms 1 region cells",
          "set group all diameter 2.0e-6", "set group all density 2500",
          "pair_style " + pair, std::string("pair_coeff * * ") + MODEL,
          std::string("fix floor all wall/gran granular ") + MODEL + " zplane -0.999e-6 NULL",
          "neighbor 2e-7 bin", "neigh_modify every 1 delay 0 check yes",
          "fix integrate all nve/sphere", "fix grav all gravity 9.81 vector 0 0 -1",
          "timestep 5e-9", "thermo 0"};
}

// per-atom x y z of all atoms, gathered by ID
std::vector<double> positions(Lmp &l)
{
  const int n = static_cast<int>(l.lmp->atom->natoms);
  std::vector<double> x(3 * n);
  for (int id = 1; id <= n; ++id) {
    x[3 * (id - 1) + 0] = l.var("x[" + std::to_string(id) + "]");
    x[3 * (id - 1) + 1] = l.var("y[" + std::to_string(id) + "]");
    x[3 * (id - 1) + 2] = l.var("z[" + std::to_string(id) + "]");
  }
  return x;
}

LAMMPS_NS::bigint contacts(Lmp &l)
{
  auto *pair = dynamic_cast<LAMMPS_NS::PairGranularOpt *>(l.lmp->force->pair);
  LAMMPS_NS::bigint mine = pair ? pair->contacts_computed() : -1, all = 0;
  MPI_Allreduce(&mine, &all, 1, MPI_LMP_BIGINT, MPI_SUM, MPI_COMM_WORLD);
  return all;
}

}    // namespace

// thresholds that every atom meets at once (time 0, commit every step): all sleep after run 1
const char *ALL_SLEEP = "fix sleep all sleep/gran speed 1e3 force 1.0 wake 10.0 time 0 every 1";

TEST(FixSleepGran, HeldAndComputed)
{
  LAMMPS_NS::bigint awake_contacts = 0;
  {
    Lmp l;
    l.cmds(bed());
    l.cmd("run 1");
    awake_contacts = contacts(l);
    EXPECT_GT(awake_contacts, 20) << "the lattice touches";
  }
  Lmp l;
  l.cmds(bed());
  l.cmds({ALL_SLEEP, "compute nsleep all reduce sum f_sleep", "thermo_style custom step f_sleep c_nsleep", "run 1"});
  EXPECT_EQ(l.var("f_sleep[2]"), 27.0);
  EXPECT_EQ(l.var("c_nsleep"), 27.0) << "per-atom flag";
  EXPECT_EQ(l.var("f_sleep"), 0.0) << "awake atoms (the scalar)";
  EXPECT_EQ(contacts(l), awake_contacts) << "the pair style computes every contact";
  l.cmd("run 1");    // the pair forces of step 1 still had the velocities of step 1
  const auto x0 = positions(l);
  l.cmd("run 500");
  EXPECT_EQ(contacts(l), awake_contacts) << "the sleepers' contacts are computed";
  const auto x1 = positions(l);
  for (size_t k = 0; k < x0.size(); ++k) EXPECT_EQ(x0[k], x1[k]) << "coordinate " << k;
}

// sphere 1 and sphere 3 below it, touching (an atom sleeps only in contact), sleep (the fix
// group); sphere 2 hits sphere 1 at 0.3 m/s
std::vector<std::string> impact(const std::string &hold, const std::string &pair = "granular/opt")
{
  return {"units si", "atom_style sphere", "atom_modify map array", "boundary f f f",
          "newton off", "comm_modify vel yes", "region box block -1e-5 1e-5 -1e-5 1e-5 -1e-5 1e-5",
          "create_box 1 box", "create_atoms 1 single 0 0 0", "create_atoms 1 single 0.8e-6 0.3e-6 2.1e-6",
          "create_atoms 1 single 0 0 -1.999e-6",
          "set group all diameter 2.0e-6", "set group all density 2500", "group one id 1 3",
          "group two id 2", "pair_style " + pair, std::string("pair_coeff * * ") + MODEL,
          "neighbor 2e-7 bin", "neigh_modify every 1 delay 0 check yes",
          "velocity two set 0.01 -0.02 -0.3", "set atom 2 omega 1e4 -2e4 3e3",
          "fix integrate all nve/sphere", "timestep 5e-9", "thermo 0", hold};
}

// the rule of doc/fix_sleep_gran.rst: the fix holds a sleeper, the pair style computes its
// contacts as without the fix. The reference holds spheres 1 and 3 by not integrating them
// (zero velocity and spin, forces unused); fix freeze, a fixed body (m* = the awake atom's
// mass), gives another trajectory
TEST(FixSleepGran, ContactWithASleeperIsTheUsualContact)
{
  if (nprocs() > 1) GTEST_SKIP() << "single-rank test";
  for (const std::string pair : {"granular/opt", "granular"}) {
    Lmp a, b, frozen;
    a.cmds(impact("fix sleep one sleep/gran speed 1e3 force 1.0 wake 1e3 time 0 every 1", pair));
    // step 1 moves spheres 1 and 3 (their contact snaps) until they fall asleep at its end, with
    // zero velocity: the references take the same step free, then hold them
    b.cmds(impact("thermo 0", pair));
    frozen.cmds(impact("thermo 0", pair));
    a.cmd("run 1");
    for (Lmp *r : {&b, &frozen}) r->cmds({"run 1", "velocity one set 0 0 0", "set group one omega 0 0 0"});
    b.cmds({"unfix integrate", "fix integrate two nve/sphere"});
    frozen.cmd("fix hold one freeze");
    EXPECT_EQ(a.var("f_sleep[2]"), 2.0);
    EXPECT_EQ(a.var("z[1]"), b.var("z[1]"));
    for (Lmp *r : {&a, &b, &frozen}) r->cmd("run 3000");
    EXPECT_EQ(a.var("f_sleep[4]"), 0.0) << pair << ": wake 1e3, nothing wakes";
    const char *q[] = {"x[2]", "y[2]", "z[2]", "vx[2]", "vy[2]", "vz[2]"};
    for (auto *e : q) EXPECT_EQ(a.var(e), b.var(e)) << pair << " " << e;
    EXPECT_EQ(a.var("z[1]"), b.var("z[1]")) << pair << ": the sleeper did not move";
    // the impact happened: the sphere stuck to the sleeper or rebounded
    EXPECT_GT(std::abs(b.var("vz[2]") + 0.3), 0.01) << pair;
    EXPECT_NE(a.var("vz[2]"), frozen.var("vz[2]")) << pair << ": a sleeper is not a fixed body";
  }
}

// sphere 3 below sphere 1, touching it: both sleep; sphere 2 hits 1. Below the wake threshold
// nothing wakes; above it sphere 1 wakes, and sphere 3 with it
void expect_wakes_when_pushed(const std::string &pair)
{
  auto cmds = impact("group bedg id 1 3", pair);
  {
    Lmp l;
    l.cmds(cmds);
    l.cmds({"fix sleep bedg sleep/gran speed 1e3 force 1e-6 wake 1e3 time 0 every 1", "run 3000"});
    EXPECT_EQ(l.var("f_sleep[2]"), 2.0) << pair;
    EXPECT_EQ(l.var("f_sleep[4]"), 0.0) << pair << ": push below wake, nothing wakes";
  }
  // the impact pushes with ~3e-8 N, m U / t_c (F_C = 3 pi gamma R = 9.4e-8 N)
  Lmp m;
  m.cmds(cmds);
  // the pair 1-3 snaps into JKR contact (3.6e-8 N): at rest means here a net force below 1e-6 N
  m.cmds({"fix sleep bedg sleep/gran speed 1e3 force 1e-6 wake 1e-8 time 0 every 1", "run 1"});
  EXPECT_EQ(m.var("f_sleep[2]"), 2.0) << pair << ": both at rest at step 1";
  const double z1 = m.var("z[1]");
  m.cmd("run 3000");
  EXPECT_GE(m.var("f_sleep[4]"), 2.0) << pair << ": sphere 1 pushed, sphere 3 touching it";
  EXPECT_NE(m.var("z[1]"), z1) << pair << ": sphere 1 moves once awake";
}

TEST(FixSleepGran, WakesWhenPushed)
{
  if (nprocs() > 1) GTEST_SKIP() << "single-rank test";
  expect_wakes_when_pushed("granular/opt");
}

// the base style: the fix holds the bed and finds the contacts and the push
TEST(FixSleepGran, BaseStyleHoldsAndWakes)
{
  {
    Lmp l;
    l.cmds(bed("granular"));
    l.cmds({ALL_SLEEP, "run 1"});
    EXPECT_EQ(l.var("f_sleep[2]"), 27.0) << "every atom touches another: all sleep";
    l.cmd("run 1");
    const auto x0 = positions(l);
    l.cmd("run 500");
    EXPECT_EQ(l.var("f_sleep[2]"), 27.0);
    const auto x1 = positions(l);
    for (size_t k = 0; k < x0.size(); ++k) EXPECT_EQ(x0[k], x1[k]) << "coordinate " << k;
  }
  if (nprocs() == 1) expect_wakes_when_pushed("granular");    // a single-rank set-up
}

TEST(FixSleepGran, RestartKeepsTheFlags)
{
  const std::string file = "sleep_gran.restart";
  {
    Lmp l;
    l.cmds(bed());
    l.cmds({ALL_SLEEP, "run 1", "write_restart " + file});
  }
  Lmp l;
  l.cmds({"read_restart " + file, "pair_style granular/opt", std::string("pair_coeff * * ") + MODEL,
          "comm_modify vel yes", "neighbor 2e-7 bin",
          std::string("fix floor all wall/gran granular ") + MODEL + " zplane -0.999e-6 NULL",
          "fix integrate all nve/sphere",
          // commits only every 10^6 steps: the flags can only come from the restart
          "fix sleep all sleep/gran speed 1e3 force 1.0 wake 10.0 time 0 every 1000000", "run 0"});
  EXPECT_EQ(l.var("f_sleep[2]"), 27.0);
  EXPECT_EQ(l.var("f_sleep[3]"), 27.0) << "event count from the global restart";
  int me;
  MPI_Comm_rank(MPI_COMM_WORLD, &me);
  if (me == 0) std::remove(file.c_str());
}

TEST(FixSleepGran, FlagsMigrateWithTheAtoms)
{
  Lmp l;
  l.cmds(bed());
  l.cmds({ALL_SLEEP, "run 1"});
  l.cmd("displace_atoms all move 2.9925e-6 2.9925e-6 0 units box");
  l.cmd("run 1");
  const auto x0 = positions(l);
  l.cmd("run 200");
  EXPECT_EQ(l.var("f_sleep[2]"), 27.0);
  const auto x1 = positions(l);
  for (size_t k = 0; k < x0.size(); ++k) EXPECT_EQ(x0[k], x1[k]) << "coordinate " << k;
}

// charged spheres (+-400 e) in a p p f box: a touching layer of 144 below with random signs,
// which sleeps at step 1 (group low, thresholds every atom meets; an atom sleeps only in
// contact), and 240 of alternating sign apart from each other above it, which move
void charged_spheres(Lmp &l, const std::string &coul)
{
  l.cmds({"units si", "atom_style hybrid sphere charge", "atom_modify map array sort 0 0",
          "boundary p p f", "newton off", "comm_modify vel yes",
          "region box block 0 24e-6 0 24e-6 0 48e-6", "create_box 1 box",
          "lattice sc 1.995e-6", "region bed block 0 11.5 0 11.5 0.5 1.5", "create_atoms 1 region bed",
          "region above block EDGE EDGE EDGE EDGE 8e-6 46e-6 units box",
          "create_atoms 1 random 240 4711 above overlap 2.4e-6 maxtry 500",
          "set group all diameter 2.0e-6", "set group all density 2500",
          "variable qq atom (2*(id%2)-1)*400*1.602176634e-19", "set group all charge v_qq",
          "group bedatoms region bed",
          "variable qb atom (2*(random(0,1,777)>0.5)-1)*400*1.602176634e-19",
          "set group bedatoms charge v_qb", "velocity all create 1e9 4711 loop geom",
          "region low block EDGE EDGE EDGE EDGE EDGE 4e-6 units box", "group low region low",
          "pair_style granular/opt", std::string("pair_coeff * * ") + MODEL, "neighbor 2e-7 bin",
          "fix integrate all nve/sphere", "timestep 1e-9", "thermo 0", coul,
          "fix_modify coul energy yes",
          "fix sleep low sleep/gran speed 1e6 force 1.0 wake 10.0 time 0 every 1",
          // step 1: every atom awake, the layer falls asleep at its end; step 2: the same
          // positions in every variant, evaluated with the sleepers split off (or not)
          "thermo_style custom step pe f_sleep", "run 2"});
}

TEST(FixSleepGran, CoulombSleepersAreAStaticSource)
{
  Lmp ref;
  charged_spheres(ref, "fix coul all coul/fmm accuracy 1e-9 order 27 sleepers full");
  const double nsleep = ref.var("f_sleep[2]");
  EXPECT_EQ(nsleep, 144.0);
  const auto fref = gather(ref, "f", 3);
  const double eref = ref.var("f_coul");
  // with either solver: with solver distributed each rank adds the static field at its own
  // awake atoms
  for (const char *solver : {"replicated", "distributed"})
  for (double acc : {1e-4, 1e-6}) {
    Lmp l;
    charged_spheres(l, fmt::format("fix coul all coul/fmm accuracy {} sleepers static solver {}", acc, solver));
    EXPECT_EQ(l.var("f_sleep[2]"), nsleep);
    const auto f = gather(l, "f", 3);
    // the sleepers' forces are zero in both (fix sleep/gran). The awake atoms' forces must meet
    // the requested accuracy (the split: Solver over the awake charges + the static field of the
    // sleeping ones; the reference's own error is 1e-9). Measured ~1e-11: the contact forces of
    // the pair style dominate f, so the test guards the split's
    // bookkeeping (the sleepers' field at the right atoms: 0.96 when it was not, 0.96 without
    // the static field); the Coulomb forces alone are checked by
    // CoulombStaticSleepersMeetTheRequestAtTheAwakeAtoms, the split with multipole translations by
    // fmm.static_field (SplitPlusStaticEqualsWholeSolver)
    const double err = rel_rms(f, fref);
    std::printf("[ static sleepers, %s ] accuracy %g: force error %.3g, energy error %.3g\n", solver,
                acc, err, std::abs(l.var("f_coul") / eref - 1.0));
    EXPECT_LT(err, acc);
    EXPECT_GT(err, 0.0) << "two different evaluations";
    // the energy sums pair energies (awake-awake, awake-sleeping, sleeping-sleeping); its
    // relative error is at most the force error (potentials converge one order faster)
    EXPECT_LT(std::abs(l.var("f_coul") / eref - 1.0), acc);
  }
}

// the static source is rebuilt when the cell changes (the sleeping set does not): after
// change_box the sleepers' periodic copies are at the new period, as with all charges in the
// solver. The bound is the requested accuracy (as above; measured: forces 1e-15, the nearest
// pairs dominate them, energy 2e-9); with the static source of the old cell the energy, which
// holds the sleepers' energy among their copies, is 3.6 off (the forces 5e-8).
TEST(FixSleepGran, CoulombStaticSleepersFollowTheCell)
{
  const std::vector<std::string> widen = {"change_box all x final 0 30e-6 y final 0 30e-6 units box",
                                          "run 0 post no"};
  Lmp ref, l;
  charged_spheres(ref, "fix coul all coul/fmm accuracy 1e-9 order 27 sleepers full");
  charged_spheres(l, "fix coul all coul/fmm accuracy 1e-6 sleepers static");
  ref.cmds(widen);
  l.cmds(widen);
  EXPECT_EQ(l.var("f_sleep[2]"), 144.0);
  const double err = rel_rms(gather(l, "f", 3), gather(ref, "f", 3));
  const double eerr = std::abs(l.var("f_coul") / ref.var("f_coul") - 1.0);
  std::printf("[ static sleepers, new cell ] force error %.3g, energy error %.3g\n", err, eerr);
  EXPECT_LT(err, 1e-6);
  EXPECT_LT(eerr, 1e-6);
}

namespace {
// the Coulomb forces q E at the awake atoms (E: fix coul/fmm's per-atom field), by atom ID: the
// forces fix coul/fmm's accuracy is defined for, without the contact forces that f also holds
std::vector<double> awake_coulomb_forces(Lmp &l, const std::vector<double> &sleeping)
{
  const size_t n = sleeping.size();
  std::vector<double> field(4 * n), out;
  lammps_gather(l.lmp, "f_coul", 1, 4, field.data());
  const auto q = gather(l, "q", 1);
  for (size_t i = 0; i < n; i++)
    if (sleeping[i] == 0.0)
      for (int k = 0; k < 3; k++) out.push_back(q[i] * field[4 * i + k]);
  return out;
}
}    // namespace

// accuracy is the relative RMS Coulomb force error over the atoms the solver evaluates
// (doc/fmm-accuracy.md): with static sleepers, the awake atoms, whose field is the sum of the
// solver over the awake charges and the sleepers' static field (gcfmm::static_part_options)
TEST(FixSleepGran, CoulombStaticSleepersMeetTheRequestAtTheAwakeAtoms)
{
  Lmp ref;
  charged_spheres(ref, "fix coul all coul/fmm accuracy 1e-9 order 27 sleepers full");
  std::vector<double> sleeping((size_t) ref.var("count(all)"));
  lammps_gather(ref.lmp, "f_sleep", 1, 1, sleeping.data());
  const auto fref = awake_coulomb_forces(ref, sleeping);
  for (const char *solver : {"replicated", "distributed"})
    for (double acc : {1e-4, 1e-6}) {
      Lmp l;
      charged_spheres(l, fmt::format("fix coul all coul/fmm accuracy {} sleepers static solver {}", acc, solver));
      const double err = rel_rms(awake_coulomb_forces(l, sleeping), fref);
      std::printf("[ static sleepers, %s ] accuracy %g: Coulomb force error at the awake atoms %.3g\n",
                  solver, acc, err);
      // measured 2.8e-5 to 3.7e-5 at 1e-4, 5.3e-9 to 2.1e-8 at 1e-6, with either solver on 1
      // and 2 ranks (the bed's random signs do not cancel: the request holds against the force
      // itself, doc/fmm-accuracy.md, "Fields that cancel"); 4.5e-4 at 1e-4 with the static
      // field run 50 times looser. The reference's own error (1e-9) is 1e-3 of the smaller
      // request.
      EXPECT_LT(err, acc);
      EXPECT_GT(err, 0.0) << "two different evaluations";
    }
}

TEST(FixSleepGran, CoulombSleepersRefusedCombinations)
{
  auto err = [&](const std::string &coul, const std::string &extra = "") {
    std::vector<std::string> c = {"units si", "atom_style hybrid sphere charge", "boundary p p f", "comm_modify vel yes",
                                  "region box block 0 24e-6 0 24e-6 0 48e-6", "create_box 1 box",
                                  "create_atoms 1 single 1e-5 1e-5 1e-5", "set group all charge 1e-17",
                                  "set group all diameter 2e-6 density 2500", "neighbor 2e-7 bin",
                                  "pair_style granular/opt", std::string("pair_coeff * * ") + MODEL,
                                  coul, "fix sleep all sleep/gran speed 1 force 1 wake 1 time 0"};
    if (!extra.empty()) c.push_back(extra);
    c.push_back("run 0");
    return error_of(c);
  };
  auto expect_match = [](const std::string &msg, const std::string &re) {
    EXPECT_TRUE(std::regex_search(msg, std::regex(re))) << "message: " << msg << "\nexpected: " << re;
  };
  expect_match(err("fix coul all coul/fmm farfield average"), "farfield average cannot treat the sleepers");
  EXPECT_EQ(err("fix coul all coul/fmm farfield average sleepers full"), "no error");
  expect_match(err("fix coul all coul/fmm", "fix_modify coul virial yes"), "virial with the static sleepers");
  expect_match(err("fix coul all coul/fmm sleepers maybe"), "sleepers must be static or full, got maybe");
}

// a 3 x 3 x 6 lattice stack at rest on the floor (54 spheres, every one touching its lattice
// neighbours; top of the bed 10.975e-6 m) and, with hovering, two touching spheres at rest at
// z = 29.9e-6 m, far above it: a cluster that met in flight over a charged bed
std::vector<std::string> stack(bool hovering)
{
  std::vector<std::string> c = {
      "units si", "atom_style sphere", "atom_modify map array", "boundary p p f", "newton off",
      "comm_modify vel yes", "lattice sc 1.995e-6", "region box block 0 3 0 3 -1 20",
      "create_box 1 box", "region cells block 0 3 0 2 0 5", "create_atoms 1 region cells"};
  if (hovering)
    c.insert(c.end(), {"create_atoms 1 single 0.5 0.5 15", "create_atoms 1 single 1.5 0.5 15"});
  c.insert(c.end(),
           {"set group all diameter 2.0e-6", "set group all density 2500",
            "pair_style granular/opt", std::string("pair_coeff * * ") + MODEL,
            std::string("fix floor all wall/gran granular ") + MODEL + " zplane -0.999e-6 NULL",
            "neighbor 2e-7 bin", "neigh_modify every 1 delay 0 check yes",
            "fix integrate all nve/sphere", "timestep 5e-9", "thermo 0",
            // the depth rule alone: 6e-6 m below the top, the three lowest layers (z <= 3.99e-6)
            "fix sleep all sleep/gran speed 1e-2 force 1e-9 wake 1e-7 time none depth 6e-6 every 1",
            "variable zsleep atom z*f_sleep", "compute zs all reduce max v_zsleep",
            "thermo_style custom step f_sleep[2] c_zs"});
  return c;
}

TEST(FixSleepGran, DepthRuleSleepsWhatLiesDeepBelowTheTop)
{
  Lmp l;
  l.cmds(stack(false));
  l.cmd("run 1");
  EXPECT_EQ(l.var("f_sleep[2]"), 27.0) << "the three lowest layers of nine spheres";
  EXPECT_DOUBLE_EQ(l.var("c_zs"), 2 * 1.995e-6) << "the highest sleeper is in the third layer";
}

// the cluster is in contact and slow, as the bed's top atoms are; taken for the top of its
// columns it would put those columns' six layers to sleep (45 sleepers instead of 27)
TEST(FixSleepGran, DepthRuleIgnoresAClusterHoveringAboveTheBed)
{
  Lmp l;
  l.cmds(stack(true));
  l.cmd("run 1");
  EXPECT_EQ(l.var("f_sleep[2]"), 27.0) << "the same sleepers as without the cluster";
  EXPECT_DOUBLE_EQ(l.var("c_zs"), 2 * 1.995e-6);
}

// sphere 1 rests alone on a JKR floor, sphere 2 is at rest in the air; the thresholds are met
// by both at once. A wall contact counts as a contact: sphere 1 sleeps (a sphere that lands
// on the floor far from the others would otherwise stay awake under a tall bed), sphere 2 does
// not (nothing holds it)
std::vector<std::string> alone(const std::string &pair, const std::string &wall)
{
  return {"units si", "atom_style sphere", "atom_modify map array", "boundary p p f", "newton off",
          "comm_modify vel yes", "region box block 0 2e-5 0 2e-5 -1e-6 2e-5", "create_box 1 box",
          "create_atoms 1 single 5e-6 5e-6 0 units box", "create_atoms 1 single 1.5e-5 1.5e-5 8e-6 units box",
          "set group all diameter 2.0e-6", "set group all density 2500", "pair_style " + pair,
          std::string("pair_coeff * * ") + MODEL,
          "fix floor all " + wall + " granular " + MODEL + " zplane -0.999e-6 NULL",
          "neighbor 2e-7 bin", "neigh_modify every 1 delay 0 check yes",
          "fix integrate all nve/sphere", "timestep 5e-9", "thermo 0", ALL_SLEEP,
          "variable idsleep atom id*f_sleep", "compute ids all reduce max v_idsleep",
          "thermo_style custom step f_sleep[2] c_ids"};
}

TEST(FixSleepGran, AnAtomAloneOnTheFloorSleeps)
{
  for (const auto &[pair, wall] : {std::pair<std::string, std::string>{"granular/opt", "wall/gran/opt"},
                                   {"granular", "wall/gran"}}) {
    Lmp l;
    l.cmds(alone(pair, wall));
    l.cmd("run 1");
    EXPECT_EQ(l.var("f_sleep[2]"), 1.0) << pair << " + " << wall << ": one sleeper";
    EXPECT_EQ(l.var("c_ids"), 1.0) << pair << " + " << wall << ": the sphere on the floor";
  }
}

// the bed's reach in a column, without LAMMPS: layers up to the first run of more than
// max_gap empty ones, occupancy over the column and its eight neighbours
TEST(SleepBedReach, EndsAtAGapAndBridgesPores)
{
  const int nbx = 4, nby = 4, nbz = 12;
  std::vector<unsigned char> occ(nbx * nby * nbz, 0);
  auto set = [&](int bx, int by, int bz) { occ[(by * nbx + bx) * nbz + bz] = 1; };
  for (int bz = 0; bz < 4; ++bz) set(1, 1, bz);    // a bed four layers tall in column (1, 1)
  set(1, 1, 9);                                    // a cluster five empty layers above it
  auto reach = GranularCharged::bed_reach(occ, nbx, nby, nbz, true, true, 2);
  EXPECT_EQ(reach[1 * nbx + 1], 4) << "the cluster is not the bed";
  EXPECT_EQ(reach[1 * nbx + 2], 4) << "a neighbour column shares the bed's reach";
  EXPECT_EQ(reach[3 * nbx + 3], 0) << "a column far from every occupied one has no bed";
  // the column filled in layers 6 and 7: its pores of two layers (4, 5) and one (8) are bridged
  set(1, 1, 6);
  set(1, 1, 7);
  reach = GranularCharged::bed_reach(occ, nbx, nby, nbz, true, true, 2);
  EXPECT_EQ(reach[1 * nbx + 1], 10) << "one bed up to the cluster";
  occ.assign(occ.size(), 0);
  for (int bz = 2; bz < 5; ++bz) set(3, 0, bz);    // starts above the grid's first layer
  reach = GranularCharged::bed_reach(occ, nbx, nby, nbz, true, true, 2);
  EXPECT_EQ(reach[0 * nbx + 0], 5) << "periodic in x: column 0 neighbours column 3";
  reach = GranularCharged::bed_reach(occ, nbx, nby, nbz, false, true, 2);
  EXPECT_EQ(reach[0 * nbx + 0], 0) << "not periodic: no neighbour across the box";
  EXPECT_EQ(reach[0 * nbx + 3], 5);
}

TEST(FixSleepGran, BadInput)
{
  auto err = [&](const std::string &fix, const std::string &pair = "granular/opt",
                 const std::vector<std::string> &after = {}) {
    auto c = bed(pair);
    c.push_back(fix);
    c.insert(c.end(), after.begin(), after.end());
    c.push_back("run 0");
    return error_of(c);
  };
  auto expect_match = [](const std::string &msg, const std::string &re) {
    EXPECT_TRUE(std::regex_search(msg, std::regex(re))) << "message: " << msg << "\nexpected: " << re;
  };
  const std::string ok = "fix s all sleep/gran speed 1e-3 force 1e-8 wake 1e-7 time 1e-6";
  EXPECT_EQ(err(ok), "no error");
  expect_match(err("fix s all sleep/gran speed 0 force 1e-8 wake 1e-7 time 1e-6"), "sleep/gran speed must be > 0, got 0");
  expect_match(err("fix s all sleep/gran speed 1e-3 force -1 wake 1e-7 time 1e-6"), "force must be > 0, got -1");
  expect_match(err("fix s all sleep/gran speed 1e-3 force 1e-8 wake nan time 1e-6"), "wake must be > 0|Expected floating");
  expect_match(err("fix s all sleep/gran speed 1e-3 force 1e-8 wake 1e-7 time -1"), "time must be >= 0 or none, got -1");
  expect_match(err("fix s all sleep/gran speed 1e-3 force 1e-8 wake 1e-7 time none"), "time none needs keyword depth");
  EXPECT_EQ(err("fix s all sleep/gran speed 1e-3 force 1e-8 wake 1e-7 time none depth 1e-5"), "no error");
  expect_match(err(ok + " every 0"), "every must be >= 1, got 0");
  expect_match(err(ok + " depth -2e-6"), "depth must be > 0, got -2e-6");
  expect_match(err(ok + " bogus 1"), "Unknown fix sleep/gran keyword bogus");
  expect_match(err("fix s all sleep/gran speed 1e-3 force 1e-8"), "needs the keywords speed, force, wake and time");
  EXPECT_EQ(err(ok, "granular"), "no error");
  {
    auto c = bed("zero 1e-6");
    for (auto &line : c)
      if (line.rfind("pair_coeff", 0) == 0) line = "pair_coeff * *";
    c.insert(c.end(), {ok, "run 0"});
    expect_match(error_of(c), "requires pair_style granular or granular/opt, not zero");
  }
  expect_match(err(ok, "granular/opt", {"fix late all gravity 1 vector 0 0 -1"}),
               "must be defined after every fix that adds forces; fix late \\(gravity\\)");
  expect_match(err(ok, "granular/opt",
                   {"group none empty", "region ins block EDGE EDGE EDGE EDGE 3e-6 4e-6 units box",
                    "fix s2 none sleep/gran speed 1e-3 force 1e-8 wake 1e-7 time 1e-6",
                    "fix feed all deposit 1 1 100 4711 region ins near 2e-6 units box"}),
               "Only one fix sleep/gran|does not contain the atoms");
  {
    auto c = bed();
    c.insert(c.end(), {"group none empty", "region ins block EDGE EDGE EDGE EDGE 3e-6 4e-6 units box",
                       "fix feed all deposit 1 1 100 4711 region ins near 2e-6 units box",
                       "fix s none sleep/gran speed 1e-3 force 1e-8 wake 1e-7 time 1e-6", "run 0"});
    expect_match(error_of(c), "group none does not contain the atoms that fix deposit feed inserts");
  }
  expect_match(error_of({"units si", "atom_style atomic", "region box block 0 1 0 1 0 1", "create_box 1 box",
                         "fix s all sleep/gran speed 1 force 1 wake 1 time 0"}),
               "requires atom attributes radius, rmass, omega and torque");
}
