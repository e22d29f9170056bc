/* GRANULAR-CHARGED: the contact history across a switch between pair_style granular and
   granular/opt. Both keep it in the same fix NEIGH_HISTORY with the same per-pair values, so a
   restart written by one and read with the other must continue every contact (tangential,
   rolling and twisting springs, the JKR branch) as the unswitched run does. A switch within one
   input deletes the history with the old style: granular/opt warns when it is deleted with
   contacts, and when it starts with fresh histories on touching pairs after step 0.

   Tolerance: the restarted run repeats the unswitched one's floating-point operations (the two
   styles agree to the last bit, test_granular_opt.cpp), and the restart stores every value
   exactly; 1e-9 of each quantity's scale leaves room for the order in which the styles sum the
   forces of an atom, while a lost history changes the state by its own order (x 2). */
#include "gc_testing.h"

#include "gtest/gtest.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

using gctest::nprocs;

namespace {
constexpr int NATOMS = 27;

const std::string FLOOR = "fix floor all wall/gran granular jkr/marshall 2e8 0.7 0.33 0.01 damping "
                          "marshall tangential marshall 0.3 rolling marshall 0.01 twisting "
                          "marshall/jkr zplane -0.999e-6 NULL";
const std::string MARSHALL = "jkr/marshall 2e8 0.7 0.33 0.01 damping marshall tangential marshall "
                             "0.3 rolling marshall 0.01 twisting marshall/jkr";

// 27 adhesive spheres on a slightly compressed lattice above a JKR floor, random velocities and
// spins: contacts load, slip, roll and twist
std::vector<std::string> cluster(const std::string &pair_style)
{
  return {"units si", "atom_style sphere", "atom_modify map array", "boundary p p f",
          "newton off", "comm_modify vel yes", "lattice sc 1.995e-6",
          "region box block 0 3 0 3 -1 3", "create_box 1 box",
          "region cells block 0 3 0 3 0 3", "create_atoms 1 region cells",
          "set type 1 diameter 2.0e-6", "set group all density 2500",
          "pair_style " + pair_style, "pair_coeff * * " + MARSHALL, FLOOR,
          "neighbor 1e-8 bin", "neigh_modify every 20 delay 0 check no",
          "velocity all create 3e7 87287 loop geom", "set type 1 omega 2e5 -1e5 3e5",
          "fix integrate all nve/sphere", "timestep 2e-10", "thermo 0"};
}

std::vector<double> lmp_process(const std::vector<std::string> &lines, const std::string &tag)
{
  bool ok;
  auto s = gctest::lmp_process(GC_LMP_EXECUTABLE, lines, "granular_opt_switch_" + tag, &ok);
  if (!ok) ADD_FAILURE() << "lmp run " << tag << " failed";
  return s;
}

// the state after 1000 + 1000 steps of `writer`, and after reading its restart at step 1000
// and running 1000 steps with `reader` given again before the run
void expect_restart_continues(const std::string &writer, const std::string &reader,
                              const std::string &tag)
{
  const std::string file = "granular_opt_switch_" + tag + ".restart";
  auto lines = cluster(writer);
  lines.insert(lines.end(), {"run 1000", "write_restart " + file, "run 1000"});
  const auto straight = lmp_process(lines, tag + "_straight");
  const auto restarted = lmp_process(
      {"read_restart " + file, "pair_style " + reader, "pair_coeff * * " + MARSHALL,
       "comm_modify vel yes", "neighbor 1e-8 bin", "neigh_modify every 20 delay 0 check no",
       FLOOR, "fix integrate all nve/sphere", "run 1000"},
      tag + "_restarted");
  std::remove(file.c_str());
  ASSERT_EQ(straight.size(), 5u * NATOMS);
  ASSERT_EQ(restarted.size(), straight.size());
  const double scale[5] = {1e-5, 1e-5, 1e-5, 0.1, 1e5};
  for (size_t k = 0; k < straight.size(); ++k)
    EXPECT_NEAR(straight[k], restarted[k], 1e-9 * scale[k % 5]) << "component " << k;
}

// the screen output of `lines` run by a separate lmp process
std::string screen_of(const std::vector<std::string> &lines, const std::string &tag)
{
  const std::string input = "in.granular_opt_switch_" + tag, out = input + ".out";
  {
    std::ofstream in(input);
    for (const auto &l : lines) in << l << "\n";
  }
  const std::string cmd = std::string(GC_LMP_EXECUTABLE) + " -in " + input + " -log none > " + out;
  EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
  std::ifstream f(out);
  std::stringstream s;
  s << f.rdbuf();
  std::remove(input.c_str());
  std::remove(out.c_str());
  return s.str();
}
}    // namespace

TEST(PairGranularOptSwitch, RestartOfGranularReadWithOpt)
{
  if (nprocs() > 1) GTEST_SKIP() << "single-rank test";
  expect_restart_continues("granular", "granular/opt", "to_opt");
}

TEST(PairGranularOptSwitch, RestartOfOptReadWithGranular)
{
  if (nprocs() > 1) GTEST_SKIP() << "single-rank test";
  expect_restart_continues("granular/opt", "granular", "to_granular");
}

// a switch within one input loses the contacts: both directions say so
TEST(PairGranularOptSwitch, SwitchWithinOneInputWarns)
{
  if (nprocs() > 1) GTEST_SKIP() << "single-rank test";
  auto lines = cluster("granular/opt");
  lines.insert(lines.end(), {"run 200", "pair_style granular", "pair_coeff * * " + MARSHALL,
                             "run 10"});
  const auto from_opt = screen_of(lines, "from_opt");
  EXPECT_NE(from_opt.find("WARNING: Pair granular/opt deleted with"), std::string::npos) << from_opt;

  lines = cluster("granular");
  lines.insert(lines.end(), {"run 200", "pair_style granular/opt", "pair_coeff * * " + MARSHALL,
                             "run 10"});
  const auto to_opt = screen_of(lines, "to_opt");
  EXPECT_NE(to_opt.find("WARNING: Pair granular/opt starts at step 200"), std::string::npos)
      << to_opt;

  // an unswitched run and a restart read with the same style do not warn
  lines = cluster("granular/opt");
  lines.insert(lines.end(), {"run 200", "pair_style granular/opt", "run 10"});
  EXPECT_EQ(screen_of(lines, "same").find("WARNING: Pair granular/opt"), std::string::npos);
}
