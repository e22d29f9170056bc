/* GRANULAR-CHARGED: fix coul/fmm refuses what it cannot compute: a charge that is not finite
   (it would make every field and force NaN) and an accuracy finer than the solver reaches
   (it would be served with a larger error). One rank: a bad charge is found by the rank that
   owns the atom, which stops alone (error->one). */
#include "gc_testing.h"

#include "atom.h"
#include "exceptions.h"
#include "gtest/gtest.h"

#include <cmath>
#include <limits>
#include <regex>
#include <string>
#include <vector>

using gctest::Lmp;

namespace {

// 20 charges of both signs in a box of side 10 (real units)
void charges(Lmp &l, const std::string &boundary, const std::string &style = "charge")
{
  l.cmds({"units real", "atom_style " + style, "atom_modify map array sort 0 0",
          "boundary " + boundary, "region box block 0 10 0 10 0 10", "create_box 1 box",
          "create_atoms 1 random 20 4242 NULL overlap 1.0 maxtry 200", "variable qq atom 2*(id%2)-1",
          "set group all charge v_qq", "neighbor 1.0 bin", "thermo_style custom step pe"});
  if (style != "charge") l.cmds({"set group all diameter 1.0", "set group all density 1.0"});
  if (style == "charge") l.cmd("mass 1 1.0");
}

// the message of the LAMMPS error raised by `lines` on `l`, or "no error"
std::string error_in(Lmp &l, const std::vector<std::string> &lines)
{
  try {
    l.cmds(lines);
  } catch (LAMMPS_NS::LAMMPSException &e) {
    return e.what();
  }
  return "no error";
}

void expect_match(const std::string &msg, const std::string &pattern)
{
  EXPECT_TRUE(std::regex_search(msg, std::regex(pattern))) << msg;
}

void set_charge(Lmp &l, int tag, double q)
{
  l.lmp->atom->q[l.lmp->atom->map(tag)] = q;
}

}    // namespace

// a NaN or inf charge (e.g. `set ... charge` from a variable that overflowed) stops the run at
// the evaluation, naming the atom and the value, in both schemes and between evaluations
TEST(CoulFMMInputChecks, NonFiniteChargeIsAnError)
{
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  {
    Lmp l;
    charges(l, "f f f");
    set_charge(l, 7, nan);
    expect_match(error_in(l, {"fix fmm all coul/fmm", "run 0 post no"}),
                 "Fix coul/fmm fmm: atom 7 has charge nan");
  }
  {
    Lmp l;
    charges(l, "p p f");
    set_charge(l, 12, -inf);
    expect_match(error_in(l, {"fix fmm all coul/fmm", "run 0 post no"}),
                 "atom 12 has charge -inf");
  }
  {
    // with every 5 the charge turns bad between evaluations: the changed charge forces one
    Lmp l;
    charges(l, "f f f");
    l.cmds({"fix fmm all coul/fmm every 5", "fix nve all nve", "run 3 post no"});
    set_charge(l, 3, inf);
    expect_match(error_in(l, {"run 2 post no"}), "atom 3 has charge inf");
  }
  {
    Lmp l;
    charges(l, "f f f", "hybrid sphere charge");
    set_charge(l, 5, nan);
    expect_match(error_in(l, {"fix fmm all coul/fmm polarize 4.0", "run 0 post no"}),
                 "atom 5 has charge nan");
  }
  {
    // an atom outside the group does not count
    Lmp l;
    charges(l, "f f f");
    set_charge(l, 20, nan);
    l.cmds({"group some id 1:19", "fix fmm some coul/fmm", "run 0 post no"});
    EXPECT_TRUE(std::isfinite(l.var("f_fmm")));
  }
}

// order 30 at theta 0.6 reaches 1.66e-10 (gcfmm::predicted_error), the exact periodic far field
// 1e-8, the induced dipoles a margin of 16 above the charges': finer requests are refused,
// naming what is reachable; an explicit order is the user's choice and is kept
TEST(CoulFMMInputChecks, UnreachableAccuracyIsAnError)
{
  auto refused = [](const std::string &boundary, const std::string &fix,
                    const std::string &style = "charge") {
    Lmp l;
    charges(l, boundary, style);
    return error_in(l, {fix, "run 0 post no"});
  };
  expect_match(refused("f f f", "fix fmm all coul/fmm accuracy 1e-12"),
               "accuracy 1e-12 is finer than the solver reaches with these settings: 1.66e-10 "
               "\\(order 30 at theta 0.6\\); request accuracy 1.7e-10 or larger");
  expect_match(refused("p p f", "fix fmm all coul/fmm accuracy 1e-15"),
               "accuracy 1e-15 is finer .*: 1e-08 \\(the exact periodic far field is calibrated "
               "down to 1e-08\\)");
  expect_match(refused("p p f", "fix fmm all coul/fmm accuracy 1e-12 farfield none"),
               "reaches with these settings: 1.66e-10");
  expect_match(refused("f f f", "fix fmm all coul/fmm accuracy 1e-9 polarize 4.0",
                       "hybrid sphere charge"),
               "reaches with these settings: 2.65e-09 \\(order 30 at theta 0.6, times 16 for "
               "the induced dipoles\\)");
  // a smaller theta reaches further
  EXPECT_EQ(refused("f f f", "fix fmm all coul/fmm accuracy 1e-12 theta 0.4"), "no error");
  // with fix sleep/gran the sleepers' static field runs at half the request (gcfmm::Options::
  // static_share): 1.5e-8 is within the exact far field's 1e-8, not within its half
  auto with_sleepers = [](const std::string &fix) {
    Lmp l;
    charges(l, "p p f", "hybrid sphere charge");
    return error_in(l, {"comm_modify vel yes", "pair_style granular",
                        "pair_coeff * * hooke 1000 50 tangential linear_nohistory 1.0 0.0", fix,
                        "fix sleep all sleep/gran speed 1 force 1 wake 1 time 0", "run 0 post no"});
  };
  expect_match(with_sleepers("fix fmm all coul/fmm accuracy 1.5e-8"),
               "accuracy 1.5e-08 is finer than the solver reaches with these settings: 2e-08 "
               "\\(the exact periodic far field is calibrated down to 1e-08, over 0.5 for the "
               "static sleepers' share\\); request accuracy 2e-08 or larger");
  EXPECT_EQ(with_sleepers("fix fmm all coul/fmm accuracy 2e-8"), "no error");
  EXPECT_EQ(with_sleepers("fix fmm all coul/fmm accuracy 1.5e-8 sleepers full"), "no error");
  EXPECT_EQ(refused("f f f", "fix fmm all coul/fmm accuracy 2e-10"), "no error");
  EXPECT_EQ(refused("p p f", "fix fmm all coul/fmm accuracy 1e-8"), "no error");
  EXPECT_EQ(refused("f f f", "fix fmm all coul/fmm accuracy 1e-12 order 12"), "no error");
}
