/* GRANULAR-CHARGED: pair_style granular/opt (the fused Marshall kernel) against pair_style
   granular with the same sub-models, step by step: forces and torques on every atom at every
   step, and the state after many steps, for a polydisperse adhesive cluster with per-type-pair
   coefficients (both damping and both rolling conventions, with and without twisting), random
   spins (sliding, rolling and twisting slip), a JKR wall through fix wall/gran granular,
   contacts that form, load, unload and break beyond -delta_C, newton on and off, 1 and 2 ranks,
   a type pair the fused kernel does not cover, atoms of one type with several radii, and a
   restart in the middle of the contacts.

   Tolerance: the fused kernel performs the sub-models' floating-point operations in the same
   order (both call marshall_kernels.h), so the two styles agree to the last bit in practice;
   the tests allow 1e-12 of each quantity's scale, which leaves room for a compiler that
   contracts a product differently in the two inlining contexts and is 1e6 times below the
   effect of changing a factor of the fused kernel by 1e-6. Checked by changing the fused
   branch only: the contact point of the torque (0.5 -> 0.4999 delta), the sliding limit, the
   rolling limit and the rolling stiffness (each x (1 + 1e-6)) and dropping the tangential
   damping fail both SameAsGranularNewtonOnOff and TypePairOutsideTheFusedSet; the twisting
   limit x (1 + 1e-6) fails TypePairOutsideTheFusedSet. */
#include "gc_testing.h"

#include "force.h"
#include "pair_granular_opt.h"

#include "gtest/gtest.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

using gctest::Lmp;
using gctest::nprocs;

namespace {
constexpr int NATOMS = 27;
constexpr double TOL = 1e-12;


const char *MARSHALL_11 = "jkr/marshall 2e8 0.7 0.33 0.01 damping marshall tangential marshall "
                          "0.3 rolling marshall 0.01 twisting marshall/jkr";
const char *MARSHALL_22 = "jkr/marshall 3e8 0.5 0.3 0.015 damping marshall/printed tangential "
                          "marshall 0.4 rolling marshall/particle 0.02";
const char *MARSHALL_12 = "jkr/marshall 2.5e8 0.6 0.32 0.012 damping marshall tangential "
                          "marshall 0.35";
const char *HERTZ_12 = "hertz/material 2.5e8 0.5 0.32 damping tsuji tangential mindlin NULL 1.0 0.35";

// A cluster of 27 spheres of two sizes on a slightly compressed lattice above a JKR floor, with
// random velocities and spins: contacts load, unload, slip and some break and form again.
std::vector<std::string> cluster(const std::string &pair_style, const std::string &newton,
                                 const char *coeff12 = MARSHALL_12)
{
  return {"units si", "atom_style sphere", "atom_modify map array", "boundary p p f",
          "newton " + newton, "comm_modify vel yes", "lattice sc 1.995e-6",
          "region box block 0 3 0 3 -1 3", "create_box 2 box",
          "region cells block 0 3 0 3 0 3", "create_atoms 1 region cells",
          "set group all type/fraction 2 0.4 4711", "set type 1 diameter 2.0e-6",
          "set type 2 diameter 2.012e-6", "set group all density 2500",
          "pair_style " + pair_style, std::string("pair_coeff 1 1 ") + MARSHALL_11,
          std::string("pair_coeff 2 2 ") + MARSHALL_22, std::string("pair_coeff 1 2 ") + coeff12,
          "fix floor all wall/gran granular jkr/marshall 2e8 0.7 0.33 0.01 damping marshall "
          "tangential marshall 0.3 rolling marshall 0.01 twisting marshall/jkr zplane -0.999e-6 NULL",
          "neighbor 1e-8 bin", "neigh_modify every 20 delay 0 check no",
          "velocity all create 3e7 87287 loop geom", "set type 1 omega 2e5 -1e5 3e5",
          "set type 2 omega -3e5 1e5 -2e5", "fix integrate all nve/sphere", "timestep 2e-10",
          "compute contacts all contact/atom", "compute nc all reduce sum c_contacts", "thermo 0"};
}

// every component of f and torque of every atom at every step of `steps`, from a dump
std::vector<double> forces_per_step(Lmp &l, int steps, const std::string &tag)
{
  const std::string dump = "granular_opt_" + tag + ".dump";
  l.cmd("dump f all custom 1 " + dump + " id fx fy fz tqx tqy tqz");
  l.cmd("dump_modify f sort id format float %.17g");
  l.cmd("run " + std::to_string(steps));
  l.cmd("undump f");
  std::vector<double> s;
  int me;
  MPI_Comm_rank(MPI_COMM_WORLD, &me);
  if (me == 0) {
    s = gctest::dump_rows(dump, 6);
    std::remove(dump.c_str());
  }
  int n = (int) s.size();
  MPI_Bcast(&n, 1, MPI_INT, 0, MPI_COMM_WORLD);
  s.resize(n);
  MPI_Bcast(s.data(), n, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  return s;
}

void expect_same_forces(const std::vector<double> &a, const std::vector<double> &b)
{
  gctest::expect_same_forces(a, b, TOL, NATOMS);
}

std::vector<double> state(Lmp &l)
{
  std::vector<double> s;
  for (int i = 1; i <= NATOMS; ++i)
    for (const char *q : {"x", "y", "z", "vx", "vz"}) s.push_back(l.var(fmt::format("{}[{}]", q, i)));
  return s;
}

void expect_same_state(const std::vector<double> &a, const std::vector<double> &b)
{
  ASSERT_EQ(a.size(), b.size());
  const double scale[5] = {1e-5, 1e-5, 1e-5, 0.1, 0.1};
  for (size_t k = 0; k < a.size(); ++k)
    EXPECT_NEAR(a[k], b[k], TOL * scale[k % 5]) << "component " << k;
}

LAMMPS_NS::PairGranularOpt *opt_pair(Lmp &l)
{
  return dynamic_cast<LAMMPS_NS::PairGranularOpt *>(l.lmp->force->pair);
}

// forces of 300 steps, then the state after 1700 more, and the contact count after each, for one
// style
struct Record {
  std::vector<double> forces, after, contacts;
};

Record record(const std::string &style, const std::string &newton, const char *coeff12,
              const std::string &tag, std::vector<bool> *fused = nullptr)
{
  Record r;
  Lmp l;
  l.cmds(cluster(style, newton, coeff12));
  r.forces = forces_per_step(l, 300, tag);
  r.contacts.push_back(l.var("c_nc"));
  l.cmd("run 1700");
  r.after = state(l);
  r.contacts.push_back(l.var("c_nc"));
  if (fused) {
    auto *p = opt_pair(l);
    fused->clear();
    if (p)
      for (int n = 0; n < p->nmodels; ++n) fused->push_back(p->model_is_fused(n));
  }
  return r;
}
}    // namespace

TEST(PairGranularOpt, SameAsGranularNewtonOnOff)
{
  for (const std::string newton : {"on", "off"}) {
    SCOPED_TRACE("newton " + newton);
    std::vector<bool> fused;
    const Record ref = record("granular", newton, MARSHALL_12, "ref" + newton);
    const Record opt = record("granular/opt", newton, MARSHALL_12, "opt" + newton, &fused);
    ASSERT_EQ(fused.size(), 3u);
    for (bool f : fused) EXPECT_TRUE(f) << "every type pair uses the Marshall set";
    // the run exercises contacts that break and form: the count changes
    EXPECT_NE(ref.contacts[0], ref.contacts[1]);
    expect_same_forces(ref.forces, opt.forces);
    expect_same_state(ref.after, opt.after);
  }
}

// atoms of one type with several radii: no type pair has one R_eff, so each contact's R_eff and
// JKR scales are its own (appended to the type pairs' table each step), checked step by step
// against granular; newton off, so the ghost neighbors' forces are not summed here
TEST(PairGranularOpt, RadiiDifferWithinAType)
{
  auto mixed_radii = [](const std::string &style) {
    std::vector<std::string> cmds = cluster(style, "off");
    auto sized = std::find(cmds.begin(), cmds.end(), "set type 2 diameter 2.012e-6");
    cmds.insert(sized + 1, "set atom 1*9 diameter 1.994e-6");
    return cmds;
  };
  std::vector<double> forces[2];
  int k = 0;
  for (const std::string style : {"granular", "granular/opt"}) {
    Lmp l;
    l.cmds(mixed_radii(style));
    forces[k] = forces_per_step(l, 300, "radii" + std::to_string(k));
    k++;
  }
  expect_same_forces(forces[0], forces[1]);
}

TEST(PairGranularOpt, TypePairOutsideTheFusedSet)
{
  std::vector<bool> fused;
  const Record ref = record("granular", "on", HERTZ_12, "mixref");
  const Record opt = record("granular/opt", "on", HERTZ_12, "mixopt", &fused);
  ASSERT_EQ(fused.size(), 3u);
  EXPECT_EQ(std::count(fused.begin(), fused.end(), true), 2) << "1-1 and 2-2 fused, 1-2 not";
  expect_same_forces(ref.forces, opt.forces);
  expect_same_state(ref.after, opt.after);
}

// compute pair/local asks the pair style's single(): the same contacts and forces
TEST(PairGranularOpt, PairLocalAsGranular)
{
  std::vector<double> sums[2];
  int k = 0;
  for (const std::string style : {"granular", "granular/opt"}) {
    Lmp l;
    l.cmds(cluster(style, "on"));
    l.cmds({"run 200", "compute pl all pair/local dist force p1 p2 p3 p4",
            "compute plsum all reduce sum c_pl[1] c_pl[2] c_pl[3] c_pl[4] c_pl[5] c_pl[6] inputs local",
            "run 0 post no"});
    for (int c = 1; c <= 6; ++c) sums[k].push_back(l.var(fmt::format("c_plsum[{}]", c)));
    ++k;
  }
  for (int c = 0; c < 6; ++c) {
    EXPECT_NE(sums[0][c], 0.0) << "column " << c;
    EXPECT_NEAR(sums[1][c], sums[0][c], TOL * std::fabs(sums[0][c])) << "column " << c;
  }
}

TEST(PairGranularOpt, SuffixSelectsIt)
{
  Lmp l;
  l.cmds({"units si", "atom_style sphere", "region box block 0 1 0 1 0 1", "create_box 1 box",
          "suffix opt", "pair_style granular"});
  EXPECT_EQ(std::string(l.lmp->force->pair_style), "granular/opt");
  l.cmds({"suffix off", "pair_style granular"});
  EXPECT_EQ(std::string(l.lmp->force->pair_style), "granular");
}

// Both runs are separate lmp processes (see test_jkr_marshall_reproducible.cpp for why).
namespace {
std::vector<double> lmp_process(const std::vector<std::string> &lines, const std::string &tag)
{
  bool ok;
  auto s = gctest::lmp_process(GC_LMP_EXECUTABLE, lines, "granular_opt_" + tag, &ok);
  if (!ok) ADD_FAILURE() << "lmp run " << tag << " failed";
  return s;
}
}    // namespace

TEST(PairGranularOpt, RestartInTheMiddleOfContacts)
{
  if (nprocs() > 1) GTEST_SKIP() << "single-rank test";
  const std::string file = "granular_opt_cluster.restart";
  auto writer = cluster("granular/opt", "off");
  writer.insert(writer.end(), {"run 1000", "write_restart " + file, "run 1000"});
  const auto straight = lmp_process(writer, "straight");
  // granular's global cutoff flag is not in the restart (test_jkr_marshall_reproducible.cpp):
  // the pair style is given again, which keeps the coefficients and the contact history
  const auto restarted = lmp_process(
      {"read_restart " + file, "pair_style granular/opt", "comm_modify vel yes",
       "neighbor 1e-8 bin", "neigh_modify every 20 delay 0 check no",
       "fix floor all wall/gran granular jkr/marshall 2e8 0.7 0.33 0.01 damping marshall "
       "tangential marshall 0.3 rolling marshall 0.01 twisting marshall/jkr zplane -0.999e-6 NULL",
       "fix integrate all nve/sphere", "run 1000"},
      "restarted");
  std::remove(file.c_str());
  ASSERT_EQ(straight.size(), 5u * NATOMS);
  ASSERT_EQ(restarted.size(), straight.size());
  const double scale[5] = {1e-5, 1e-5, 1e-5, 0.1, 1e5};
  for (size_t k = 0; k < straight.size(); ++k)
    EXPECT_NEAR(straight[k], restarted[k], 1e-9 * scale[k % 5]) << "component " << k;
}

// 2 ranks: granular/opt against granular, both on the same two ranks
TEST(PairGranularOpt, SameAsGranularOnTwoRanks)
{
  if (nprocs() != 2) GTEST_SKIP() << "needs mpirun -np 2";
  const Record ref = record("granular", "off", MARSHALL_12, "ref2");
  const Record opt = record("granular/opt", "off", MARSHALL_12, "opt2");
  expect_same_forces(ref.forces, opt.forces);
  expect_same_state(ref.after, opt.after);
}
