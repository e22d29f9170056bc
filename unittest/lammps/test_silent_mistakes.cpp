/* GRANULAR-CHARGED: inputs that LAMMPS accepts and that give another answer than the user
   meant, and the warning each now gives (read from the log file of rank 0).

   - TwistingMarshallWithJKRMarshall: `twisting marshall` (LAMMPS's built-in, whose cap on the
     moment is 13% above the Marshall-JKR one) with `normal jkr/marshall` warns, naming twisting
     marshall/jkr: once per pair_coeff (or fix wall/gran) that declares it, not again for the
     model LAMMPS mixes from two declared ones, not at all with twisting marshall/jkr.
   - RdfSlabOutsideTheBox: compute rdf/slab with a slab that reaches outside the non-periodic z
     range of the box (whose empty part it would count as slab volume: g(r) too high by the
     ratio of the widths) warns once, however often it is invoked; a slab inside the box does
     not warn.
   - ChargesWithoutCoulombSolver: atoms with charges but no fix coul/fmm, kspace or coul pair
     style under pair_style granular and granular/opt with jkr/marshall warn once over two runs;
     neutral atoms, or the same charges with fix coul/fmm, do not.

   Checked against broken code: without the warning in jkr/marshall's init() the first test
   finds no warning; without the check in compute_array() the second finds none; without
   FixChargeCheck::ensure() in jkr/marshall's init() the third finds none under pair_style
   granular, without the check in FixChargeCheck::init() none under either style. */
#include "gc_testing.h"

#include "gtest/gtest.h"

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

using gctest::rank;

namespace {

// the log of `cmds` run in a fresh instance (rank 0's log file; empty on the other ranks)
std::string log_of(const std::vector<std::string> &cmds)
{
  static int count = 0;
  const std::string file = "silent_mistakes_" + std::to_string(count++) + ".log";
  {
    std::vector<std::string> args = {"gctest", "-log", file, "-screen", "none", "-nocite"};
    std::vector<char *> argv;
    for (auto &a : args) argv.push_back(a.data());
    LAMMPS_NS::LAMMPS lmp(static_cast<int>(argv.size()), argv.data(), MPI_COMM_WORLD);
    for (const auto &c : cmds) lmp.input->one(c);
  }
  if (rank() != 0) return "";
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  std::remove(file.c_str());
  return text.str();
}

int occurrences(const std::string &text, const std::string &what)
{
  int n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) n++;
  return n;
}

std::string model(const std::string &twisting)
{
  return "jkr/marshall 2e8 0.7 0.33 0.01 damping marshall tangential marshall 0.3 "
         "rolling marshall 0.01 twisting " +
         twisting;
}

// two touching spheres of types 1 and 2
std::vector<std::string> spheres()
{
  return {"units si", "atom_style sphere", "atom_modify map array", "boundary p p f",
          "comm_modify vel yes", "region box block 0 10e-6 0 10e-6 0 10e-6", "create_box 2 box",
          "create_atoms 1 single 4e-6 5e-6 5e-6", "create_atoms 2 single 5.99e-6 5e-6 5e-6",
          "set group all diameter 2e-6", "set group all density 2500", "neighbor 2e-7 bin",
          "pair_style granular/opt", "timestep 5e-9", "thermo 0"};
}

}    // namespace

TEST(SilentMistakes, TwistingMarshallWithJKRMarshall)
{
  const std::string warning = "use twisting marshall/jkr";
  auto with = [](std::vector<std::string> extra) {
    auto c = spheres();
    c.insert(c.end(), extra.begin(), extra.end());
    c.push_back("run 10");
    c.push_back("run 10");
    return c;
  };
  const std::string stock = model("marshall"), jkr = model("marshall/jkr");
  const std::string one = log_of(with({"pair_coeff * * " + stock}));
  const std::string two = log_of(with({"pair_coeff 1 1 " + stock, "pair_coeff 2 2 " + stock}));
  const std::string none = log_of(with({"pair_coeff * * " + jkr}));
  const std::string wall =
      log_of(with({"pair_coeff * * " + jkr, "fix floor all wall/gran granular " + stock +
                                                " zplane 3.999e-6 NULL"}));
  if (rank() != 0) return;
  EXPECT_EQ(occurrences(one, warning), 1) << one;
  EXPECT_EQ(occurrences(one, "Twisting marshall with normal jkr/marshall"), 1);
  EXPECT_EQ(occurrences(one, "13% higher"), 1);
  EXPECT_EQ(occurrences(two, warning), 2) << "one per declared model, none for the mixed 1-2";
  EXPECT_EQ(occurrences(none, warning), 0);
  EXPECT_EQ(occurrences(wall, warning), 1) << "the wall's model";
}

TEST(SilentMistakes, RdfSlabOutsideTheBox)
{
  auto deck = [](const std::string &slab) {
    auto c = spheres();
    c.insert(c.end(), {"pair_coeff * * " + model("marshall/jkr"), "comm_modify cutoff 3e-6",
                       "compute g all rdf/slab 10 2.5e-6 z " + slab,
                       "thermo_style custom step c_g[1][2]", "run 0", "run 0"});
    return c;
  };
  const std::string warning = "reaches outside the box's non-periodic z range";
  const std::string far = log_of(deck("-1e-3 1e-3"));
  const std::string above = log_of(deck("2e-6 10.5e-6"));
  const std::string inside = log_of(deck("2e-6 8e-6"));
  const std::string open = log_of(deck("NULL NULL"));
  if (rank() != 0) return;
  EXPECT_EQ(occurrences(far, warning), 1) << far;
  EXPECT_EQ(occurrences(far, "choose zlo, zhi inside the box"), 1);
  EXPECT_EQ(occurrences(above, warning), 1) << above;
  EXPECT_EQ(occurrences(inside, warning), 0) << inside;
  EXPECT_EQ(occurrences(open, warning), 0) << open;
}

TEST(SilentMistakes, ChargesWithoutCoulombSolver)
{
  for (const std::string style : {"granular", "granular/opt"}) {
    auto deck = [&style](const std::string &charge, const std::string &solver) {
      auto c = spheres();
      c[1] = "atom_style hybrid sphere charge";
      for (auto &line : c)
        if (line == "pair_style granular/opt") line = "pair_style " + style;
      c.insert(c.end(),
               {"pair_coeff * * " + model("marshall/jkr"), "set group all charge " + charge});
      if (!solver.empty()) c.push_back(solver);
      c.push_back("run 10");
      c.push_back("run 10");
      return c;
    };
    const std::string warning = "Atoms carry charges, but no Coulomb interaction is computed";
    const std::string charged = log_of(deck("1e-16", ""));
    const std::string neutral = log_of(deck("0.0", ""));
    const std::string solved =
        log_of(deck("1e-16", "fix fmm all coul/fmm accuracy 1e-4 farfield none"));
    if (rank() != 0) continue;
    EXPECT_EQ(occurrences(charged, warning), 1) << style << "\n" << charged;
    EXPECT_EQ(occurrences(charged, "define fix coul/fmm"), 1);
    EXPECT_EQ(occurrences(neutral, warning), 0) << style << "\n" << neutral;
    EXPECT_EQ(occurrences(solved, warning), 0) << style << "\n" << solved;
  }
}
