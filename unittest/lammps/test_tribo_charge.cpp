/* GRANULAR-CHARGED: fix tribo/charge, the condenser model of contact charging, against its
   closed forms (doc/fix_tribo_charge.rst, eqs. (T.1)-(T.5)):

   - a sphere that hits the floor and rebounds gains eps0 A_max (V_p - V_w) / z0, A_max its
     largest contact area (Hertz: pi R delta_max, delta_max read off the trajectory), and the
     wall's counter says it gave exactly that charge; an adhesive sphere that sticks gains it for
     the largest JKR area of its first impact and nothing while it rings down;
   - two spheres pressed together again and again at one overlap: without the field the charge
     grows by eps0 A (V_a - V_b) / z0 per contact exactly; with the field of fix coul/fmm it
     converges to the saturation charge (T.5), where the field of the two charges at the contact
     cancels the contact potential;
   - like materials do not charge, unlike ones charge with opposite signs, and a bipolar binary
     powder poured on a floor separates its signs by species as the potentials order them;
   - charge is conserved exactly (in quanta) on 1 and 2 ranks;
   - the contact records go through a restart file (a contact pressed deeper after it charges
     only for the new area);
   - bad input stops with a message naming the keyword and value.

   Checked by breaking the code: the sign of the field term in contact_drive (the saturation
   test fails: the charge runs away), the area (pi a instead of pi a^2: the wall and pair tests
   fail), a factor 2 in condenser_charge (all closed-form tests fail), the rank of the lower tag
   no longer adding its quanta for a pair of two ranks or images (the conservation test fails),
   the records not read back from the restart file (the restart test fails), the per-atom
   vector not set for an atom received from another rank (the powder tests fail on 2 ranks). */
#include "gc_testing.h"

#include "gtest/gtest.h"

#include <cmath>
#include <string>
#include <vector>

using gctest::Lmp;

namespace {

// LAMMPS's si Coulomb constant qqr2e = 8.9876e9 (5.4e-6 above 1/(4 pi eps0) of CODATA): the
// permittivity the fix uses, eps = 1 / (4 pi qqr2e)
constexpr double COULOMB = 8.9876e9;
const double EPS0 = 1.0 / (4.0 * M_PI * COULOMB);
constexpr double R = 1.0e-6;                 // particle radius
constexpr double Z0 = 4.0e-10;               // condenser gap
constexpr double RHO = 2500.0;

// jkr/marshall with restitution 1 (no damping) and no adhesion: Hertz's elastic contact
const std::string ELASTIC = "jkr/marshall 2e8 1.0 0.33 0.0 damping marshall tangential marshall 0.3";
// adhesive and damped: a sphere at 0.3 m/s sticks
const std::string STICKY = "jkr/marshall 2e8 0.3 0.33 0.05 damping marshall tangential marshall 0.3";

double estar(double e_mod, double nu)
{
  return e_mod / (2.0 * (1.0 - nu * nu));    // two bodies of the same material, or a wall
}

// a box of side 10 R, the floor z = 0 as fix wall/gran, one or two atom types
std::vector<std::string> base(const std::string &boundary, int ntypes, const std::string &model)
{
  return {"units si",
          "atom_style hybrid sphere charge",
          "atom_modify map array",
          "boundary " + boundary,
          "newton off",
          "comm_modify vel yes",
          "region box block -5e-6 5e-6 -5e-6 5e-6 0.0 1e-5",
          "create_box " + std::to_string(ntypes) + " box",
          "neighbor 2e-7 bin",
          "neigh_modify every 1 delay 0 check yes",
          "pair_style granular",
          "pair_coeff * * " + model};
}

double charge(Lmp &l, int id)
{
  return l.var("q[" + std::to_string(id) + "]");
}

/* ---------------------------------------------------------------------- */

// one sphere at 1 m/s onto the floor and back: q = -eps0 pi R delta_max (V_p - V_w) / z0
TEST(TriboCharge, WallContactGainsTheCondenserChargeOfItsLargestArea)
{
  Lmp l;
  l.cmds(base("p p f", 1, ELASTIC));
  l.cmds({"create_atoms 1 single 0.0 0.0 1.05e-6",
          "set atom 1 diameter 2e-6 density 2500 charge 0.0",
          "velocity all set 0.0 0.0 -1.0",
          "fix integrate all nve/sphere",
          "fix floor all wall/gran granular " + ELASTIC + " zplane 0.0 NULL",
          "fix tc all tribo/charge z0 4e-10 potential 0.5 wall floor 0.2 field no",
          "timestep 1.5e-10"});
  double zmin = 1.0;
  for (int s = 0; s < 1500; s++) {
    l.cmd("run 1 pre no post no");
    zmin = std::min(zmin, l.var("bound(all,zmin)"));
  }
  const double delta_max = R - zmin;
  // the sphere is on its way up and out of contact
  ASSERT_GT(l.var("bound(all,zmin)"), R);
  ASSERT_GT(l.var("vz[1]"), 0.0);

  // setup check: Hertz's closed form of the largest overlap of an elastic impact,
  // delta_max = (15 m v^2 / (16 E* sqrt(R)))^(2/5); the trajectory samples it with dt = t_c/400
  // (velocity Verlet, error O(dt^2)): within 2e-3
  const double m = 4.0 / 3.0 * M_PI * R * R * R * RHO;
  const double hertz = std::pow(15.0 * m / (16.0 * estar(2e8, 0.33) * std::sqrt(R)), 0.4);
  EXPECT_NEAR(delta_max / hertz, 1.0, 2e-3);

  // (T.1) summed over the growth: A_max = pi a^2 = pi R delta_max. The charge moves in quanta of
  // e/65536 rounded per step (at most 1/2 quantum per step over ~200 steps of growth, 100 quanta
  // = 2.4e-22 C against 5e-16 C): relative 1e-6
  const double expected = -EPS0 * M_PI * R * delta_max * (0.5 - 0.2) / Z0;
  EXPECT_NEAR(charge(l, 1) / expected, 1.0, 1e-6);
  // the wall gave it, and the counts balance exactly
  EXPECT_NEAR(l.var("f_tc[2]") / expected, 1.0, 1e-6);
  EXPECT_EQ(l.var("f_tc[5]"), 0.0);
  EXPECT_GE(l.var("f_tc[4]"), 10.0);
  EXPECT_EQ(l.var("f_tc[3]"), 0.0);
}

// an adhesive sphere that sticks: the charge of its largest JKR area, gained in the first
// impact; the ringing down afterwards never grows the area beyond it
TEST(TriboCharge, StickingSphereKeepsTheChargeOfItsFirstImpact)
{
  Lmp l;
  l.cmds(base("p p f", 1, STICKY));
  l.cmds({"create_atoms 1 single 0.0 0.0 1.02e-6",
          "set atom 1 diameter 2e-6 density 2500 charge 0.0",
          "velocity all set 0.0 0.0 -0.3",
          "fix integrate all nve/sphere",
          "fix floor all wall/gran granular " + STICKY + " zplane 0.0 NULL",
          "fix tc all tribo/charge z0 4e-10 potential -0.3 wall floor 0.0 field no",
          "timestep 1.5e-10"});
  double zmin = 1.0, q_first_rebound = 0.0;
  bool rebounding = false;
  for (int s = 0; s < 4000; s++) {
    l.cmd("run 1 pre no post no");
    zmin = std::min(zmin, l.var("bound(all,zmin)"));
    if (!rebounding && l.var("vz[1]") > 0.0) {
      rebounding = true;
      q_first_rebound = charge(l, 1);
    }
  }
  ASSERT_TRUE(rebounding);
  ASSERT_LT(l.var("bound(all,zmin)"), R + 1e-8) << "the sphere should stick";
  // the closed-form JKR radius (gc_testing.h) at the deepest overlap, R_eff = R for a plane
  const gctest::JKR jkr{R, estar(2e8, 0.33), 0.05};
  const double a = jkr.a0() * gctest::JKR::ahat_of_delta((R - zmin) / jkr.deltaC());
  // V_p < V_w: the sphere becomes positive. Bisection and quanta: relative 1e-6
  const double expected = -EPS0 * M_PI * a * a * (-0.3 - 0.0) / Z0;
  EXPECT_GT(expected, 0.0);
  EXPECT_NEAR(charge(l, 1) / expected, 1.0, 1e-6);
  EXPECT_EQ(charge(l, 1), q_first_rebound) << "no charge while the contact rings down";
}

/* ----------------------------------------------------------------------
   two spheres of radius R pressed to the overlap delta and pulled apart again, n times (the
   atoms are placed with set between runs of one step; no time integration)
------------------------------------------------------------------------- */

struct PressedPair {
  Lmp l;
  double delta;
  PressedPair(const std::string &tribo_args, double delta_, double q1 = 0.0, double q2 = 0.0,
              const std::string &v2 = "0.0") :
      delta(delta_)
  {
    l.cmds(base("f f f", 2, ELASTIC));
    l.cmds({"create_atoms 1 single 0.0 0.0 5e-6", "create_atoms 2 single 3e-6 0.0 5e-6",
            "set atom 1 diameter 2e-6 density 2500 charge " + std::to_string(q1),
            "set atom 2 diameter 2e-6 density 2500 charge " + std::to_string(q2),
            "fix coul all coul/fmm accuracy 2e-10",
            "fix tc all tribo/charge z0 4e-10 potential 0.5 " + v2 + " " + tribo_args,
            "timestep 1e-10"});
  }
  void press(int n)
  {
    char pressed[64];
    snprintf(pressed, sizeof pressed, "%.17g", 2.0 * R - delta);
    for (int c = 0; c < n; c++) {
      l.cmd(std::string("set atom 2 x ") + pressed);
      l.cmd("run 1 post no");
      l.cmd("set atom 2 x 3e-6");
      l.cmd("run 1 post no");
    }
  }
  double area() const { return M_PI * 0.5 * R * delta; }    // Hertz, R_eff = R/2
};

// field no: every contact moves eps0 A (V_1 - V_2) / z0, whatever the charges already are
TEST(TriboCharge, FieldFreeLawGrowsByTheSameChargePerContact)
{
  PressedPair p("field no", 0.2 * R);
  const double per_contact = -EPS0 * p.area() * 0.5 / Z0;
  p.press(1);
  // one rounding to a quantum (7.6e-6 e = 1.2e-24 C against 2.8e-16 C)
  EXPECT_NEAR(charge(p.l, 1) / per_contact, 1.0, 1e-8);
  EXPECT_EQ(charge(p.l, 1), -charge(p.l, 2));
  p.press(9);
  EXPECT_NEAR(charge(p.l, 1) / (10.0 * per_contact), 1.0, 1e-8);
  EXPECT_EQ(charge(p.l, 1), -charge(p.l, 2));
  EXPECT_EQ(p.l.var("f_tc[3]"), 10.0);
  EXPECT_NEAR(p.l.var("f_tc[1]") / (-10.0 * per_contact), 1.0, 1e-8);
}

// field yes: the charges' own field at the contact point stops the flow at (T.5)
TEST(TriboCharge, RepeatedContactsConvergeToTheSaturationCharge)
{
  const double delta = 0.4 * R;
  PressedPair p("", delta);
  // saturation at the contact plane da = db = R - delta/2, C = 1/(4 pi eps0); each contact
  // closes the gap by the factor a^2 / (2 d^2) = 0.156 here (eq. (T.5) in the doc), so 100
  // contacts leave (1 - 0.156)^100 = 4e-8 of it; fix coul/fmm's field at accuracy 2e-10
  const double d = R - 0.5 * delta;
  const double q_sat = -0.5 / (COULOMB * Z0 * (2.0 / (d * d)));
  p.press(10);
  const double q10 = charge(p.l, 1);
  EXPECT_LT(q10, 0.0);
  EXPECT_GT(q10, q_sat) << "approaches from above, never beyond";
  p.press(90);
  EXPECT_NEAR(charge(p.l, 1) / q_sat, 1.0, 1e-6);
  EXPECT_EQ(charge(p.l, 1), -charge(p.l, 2));
  // and stays there
  const double q100 = charge(p.l, 1);
  p.press(5);
  EXPECT_NEAR(charge(p.l, 1) / q100, 1.0, 1e-7);
}

// like materials (equal potentials) do not charge each other, with or without the field
TEST(TriboCharge, LikeMaterialsDoNotCharge)
{
  PressedPair p("", 0.2 * R, 0.0, 0.0, "0.5");
  p.press(5);
  EXPECT_EQ(charge(p.l, 1), 0.0);
  EXPECT_EQ(charge(p.l, 2), 0.0);
  EXPECT_EQ(p.l.var("f_tc[3]"), 0.0);
}

// the contact records and gained quanta go through a restart file: a contact pressed deeper
// after read_restart charges only for the area beyond the one it had charged over
TEST(TriboCharge, RestartKeepsTheContactRecords)
{
  const std::string file = "tribo_restart_" + std::to_string(gctest::nprocs()) + ".restart";
  double q_before = 0.0;
  {
    PressedPair p("field no", 0.1 * R);
    char pressed[64];
    snprintf(pressed, sizeof pressed, "%.17g", 2.0 * R - 0.1 * R);
    p.l.cmd(std::string("set atom 2 x ") + pressed);
    p.l.cmd("run 1 post no");
    q_before = charge(p.l, 1);
    EXPECT_LT(q_before, 0.0);
    p.l.cmd("write_restart " + file);
  }
  Lmp l;
  // the pair style is given again, as the deposition deck does after read_restart
  l.cmds({"read_restart " + file, "neighbor 2e-7 bin", "neigh_modify every 1 delay 0 check yes",
          "pair_style granular", "pair_coeff * * " + ELASTIC,
          "fix tc all tribo/charge z0 4e-10 potential 0.5 0.0 field no", "timestep 1e-10"});
  EXPECT_EQ(charge(l, 1), q_before);
  char deeper[64];
  snprintf(deeper, sizeof deeper, "%.17g", 2.0 * R - 0.3 * R);
  l.cmd(std::string("set atom 2 x ") + deeper);
  l.cmd("run 1 post no");
  // the contact went from A(0.1 R) to A(0.3 R) without breaking: in all, eps0 A(0.3 R) dV / z0
  const double expected = -EPS0 * M_PI * 0.5 * R * (0.3 * R) * 0.5 / Z0;
  EXPECT_NEAR(charge(l, 1) / expected, 1.0, 1e-8);
  EXPECT_EQ(charge(l, 1), -charge(l, 2));
  if (gctest::rank() == 0) std::remove(file.c_str());
}

/* ----------------------------------------------------------------------
   a bipolar binary powder: 2 x 40 spheres of two materials poured on a floor of a third,
   periodic in x and y, with the field of fix coul/fmm; on 1 and 2 ranks
------------------------------------------------------------------------- */

void pour_binary_powder(const std::string &pair_style, const std::string &wall_style)
{
  Lmp l;
  const std::string model = "jkr/marshall 2e8 0.5 0.33 0.02 damping marshall tangential marshall 0.3";
  l.cmds({"units si", "atom_style hybrid sphere charge", "atom_modify map array", "boundary p p f",
          "newton off", "comm_modify vel yes", "region box block 0 1.2e-5 0 1.2e-5 0 4e-5",
          "create_box 2 box", "neighbor 3e-7 bin", "neigh_modify every 1 delay 0 check yes",
          "pair_style " + pair_style, "pair_coeff * * " + model,
          "lattice sc 3e-6", "region pile block 0 1.2e-5 0 1.2e-5 2e-6 3.5e-5 units box",
          "create_atoms 1 region pile",
          "set type 1 type/fraction 2 0.5 4711",
          "set group all diameter 2e-6 density 2500 charge 0.0",
          // random speeds of ~0.3 m/s (m = 1e-14 kg: T = m v^2 / 3 k_B), falling at 0.5 m/s
          "velocity all create 2e7 4711 loop geom",
          "velocity all set NULL NULL -0.5 sum yes",
          "fix integrate all nve/sphere", "fix grav all gravity 9.81 vector 0 0 -1",
          "fix floor all " + wall_style + " granular " + model + " zplane 0.0 NULL",
          "fix coul all coul/fmm accuracy 1e-5 every 16 near 6e-6",
          "fix tc all tribo/charge z0 4e-10 potential 0.0 0.5 wall floor 0.25",
          "timestep 1e-9",
          "thermo 1000", "thermo_style custom step f_tc[1] f_tc[2] f_tc[3] f_tc[4] f_tc[5]"});
  const int n = (int) l.var("count(all)");
  ASSERT_GE(n, 60);
  // the per-atom vector is each atom's charge gained, here its whole charge (injected
  // uncharged): exactly, also for atoms that moved to another rank (read at the run's last
  // step, not after a new run's setup)
  l.cmds({"variable off atom abs(f_tc-q)", "compute offmax all reduce max v_off",
          "thermo_style custom step f_tc[1] f_tc[2] f_tc[3] f_tc[4] f_tc[5] c_offmax"});
  l.cmd("run 8000");
  EXPECT_EQ(l.var("c_offmax"), 0.0);
  // contacts happened, between particles and with the floor
  EXPECT_GT(l.var("f_tc[3]"), 10.0);
  EXPECT_GT(l.var("f_tc[4]"), 5.0);
  // exact: the quanta the particles gained are those the floor gave
  EXPECT_EQ(l.var("f_tc[5]"), 0.0);
  // the total charge is the floor's gift, up to the rounding of each atom's charge (one rounding
  // of relative 1.1e-16 per atom, summed over n <= 200 atoms: 1e-12 of the charge moved)
  l.cmd("compute qsum all property/atom q");
  l.cmd("compute qtot all reduce sum c_qsum");
  l.cmd("run 0 post no");
  const double total = l.var("c_qtot"), wall = l.var("f_tc[2]");
  EXPECT_NEAR(total, wall, 1e-12 * (l.var("f_tc[1]") + std::fabs(wall)));
  EXPECT_EQ(l.var("c_offmax"), 0.0);
  // type 2 (V = 0.5) below type 1 (V = 0): type 2 negative, type 1 positive on average
  l.cmd("group t1 type 1");
  l.cmd("group t2 type 2");
  l.cmd("compute q1 t1 reduce ave c_qsum");
  l.cmd("compute q2 t2 reduce ave c_qsum");
  l.cmd("run 0 post no");
  EXPECT_GT(l.var("c_q1"), 0.0);
  EXPECT_LT(l.var("c_q2"), 0.0);
}

TEST(TriboCharge, BinaryPowderSeparatesSignsAndConservesCharge)
{
  pour_binary_powder("granular", "wall/gran");
}

// the fused styles of the package hold the same contact models
TEST(TriboCharge, BinaryPowderWithTheFusedStyles)
{
  pour_binary_powder("granular/opt", "wall/gran/opt");
}

/* ---------------------------------------------------------------------- */

TEST(TriboCharge, BadInputStopsWithAMessage)
{
  auto with = [](const std::vector<std::string> &extra) {
    std::vector<std::string> c = base("p p f", 2, ELASTIC);
    c.push_back("fix floor all wall/gran granular " + ELASTIC + " zplane 0.0 NULL");
    c.insert(c.end(), extra.begin(), extra.end());
    return gctest::error_of(c);
  };
  EXPECT_NE(with({"fix tc all tribo/charge z0 -1 potential 0 0 field no"}).find("z0 must be a gap > 0"), std::string::npos);
  EXPECT_NE(with({"fix tc all tribo/charge z0 4e-10 potential 0.1 field no"}).find("one contact potential per atom type (2 values, volts): field is not a number"), std::string::npos);
  EXPECT_NE(with({"fix tc all tribo/charge potential 0 0"}).find("expected z0"), std::string::npos);
  EXPECT_NE(with({"fix tc all tribo/charge z0 4e-10 potential 0 nan field no"}).find("nan is not a number"), std::string::npos);
  EXPECT_NE(with({"fix tc all tribo/charge z0 4e-10 potential 0 0 field no bogus 1"}).find("Unknown fix tribo/charge keyword bogus"), std::string::npos);
  EXPECT_NE(with({"fix tc all tribo/charge z0 4e-10 potential 0 0 field no maxcontacts 0"}).find("maxcontacts must be 1-1000"), std::string::npos);
  EXPECT_NE(with({"fix tc all tribo/charge z0 4e-10 potential 0 0 wall nowall 0.1 field no", "run 0"}).find("no fix with ID nowall"), std::string::npos);
  EXPECT_NE(with({"fix tc all tribo/charge z0 4e-10 potential 0 0 wall tc 0.1 field no", "run 0"}).find("is not wall/gran"), std::string::npos);
  EXPECT_NE(with({"fix tc all tribo/charge z0 4e-10 potential 0 0", "run 0"}).find("needs exactly one fix coul/fmm"), std::string::npos);
  EXPECT_NE(with({"fix tc all tribo/charge z0 4e-10 potential 0 0", "fix coul all coul/fmm", "run 0"}).find("must be defined after fix coul/fmm"), std::string::npos);
  // another normal model has no JKR contact area here
  std::vector<std::string> hertz = base("p p f", 2, "hertz/material 2e8 0.5 0.33 tangential linear_nohistory 1.0 0.3");
  hertz.push_back("fix tc all tribo/charge z0 4e-10 potential 0 0 field no");
  hertz.push_back("run 0");
  EXPECT_NE(gctest::error_of(hertz).find("requires the jkr/marshall normal model"), std::string::npos);
}

}    // namespace
