/* GRANULAR-CHARGED: fix coul/fmm validated against LAMMPS's own Coulomb solvers (direct
   coul/cut, ewald + slab) and against sums written here (image block, sheet field).
   Errors are relative RMS force errors, sqrt(sum |F - F_ref|^2 / sum |F_ref|^2), the quantity
   `accuracy` requests. */
#include "gc_testing.h"

#include "exceptions.h"
#include "library.h"
#include "gtest/gtest.h"

#include <cmath>
#include <regex>
#include <string>
#include <utility>
#include <vector>

using gctest::Lmp;
using gctest::rel_rms;
using gctest::gather;
using gctest::error_of;
using gctest::nprocs;

namespace {

// n random charges of both signs (alternating, so the system is neutral for even n) in a box
void random_charges(Lmp &l, const std::string &boundary, int n, double lx, double lz, int seed)
{
  l.cmds({"units real", "atom_style charge", "atom_modify map array sort 0 0",
          "boundary " + boundary, fmt::format("region box block 0 {} 0 {} 0 {}", lx, lx, lz),
          "create_box 1 box",
          fmt::format("create_atoms 1 random {} {} NULL overlap 0.5 maxtry 200", n, seed),
          "mass 1 1.0", "variable qq atom 2*(id%2)-1", "set group all charge v_qq",
          "neighbor 1.0 bin", "thermo_style custom step pe", "thermo_modify norm no"});
}

}    // namespace

// free space vs the exact direct sum (coul/cut beyond the box diagonal), 4000 charges: enough
// that the solver's cost model chooses multipole translations also at 1e-6 (with fewer charges
// every well-separated pair is cheaper to sum directly at the high order 1e-6 needs)
TEST(CoulFMM, FreeSpaceVsDirectSum)
{
  for (double acc : {1e-3, 1e-4, 1e-6}) {
    Lmp l;
    random_charges(l, "f f f", 4000, 40.0, 40.0, 4321);
    l.cmds({"neigh_modify one 4100 page 500000", "pair_style coul/cut 100.0", "pair_coeff * *",
            "run 0 post no"});
    const auto fref = gather(l, "f", 3);
    const double eref = l.var("pe");
    l.cmds({"pair_style zero 1.0", "pair_coeff * *",
            fmt::format("fix fmm all coul/fmm accuracy {}", acc), "fix_modify fmm energy yes",
            "run 0 post no"});
    const auto f = gather(l, "f", 3);
    const double err = rel_rms(f, fref);
    std::printf("[ free space ] accuracy %g: force error %.3g, energy error %.3g\n", acc, err,
                std::fabs(l.var("f_fmm") / eref - 1.0));
    EXPECT_LT(err, acc);
    EXPECT_LT(std::fabs(l.var("f_fmm") / eref - 1.0), acc);
    // the accuracy must come from the multipole method, not from summing everything directly
    EXPECT_GT(l.var("f_fmm[3]"), 0.0) << "no M2L translation was used";
    EXPECT_NEAR(l.var("pe"), l.var("f_fmm"), 1e-12 * std::fabs(eref)) << "fix_modify energy";
  }
}

// farfield none, images 1 vs the brute-force sum over the 3 x 3 block written here; 1500
// charges, so that the 1e-6 result uses multipole translations (see above)
TEST(CoulFMM, ImageBlockVsBruteForce)
{
  Lmp l;
  random_charges(l, "p p f", 1500, 20.0, 60.0, 777);
  l.cmds({"fix fmm all coul/fmm accuracy 1e-6 farfield none images 1", "run 0 post no"});
  const auto f = gather(l, "f", 3);
  const auto x = gather(l, "x", 3);
  const auto q = gather(l, "q", 1);
  const double c = 332.06371;    // LAMMPS real-units qqr2e
  const size_t n = q.size();
  std::vector<double> ref(3 * n, 0.0);
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j)
      for (int sx = -1; sx <= 1; ++sx)
        for (int sy = -1; sy <= 1; ++sy) {
          if (i == j && sx == 0 && sy == 0) continue;
          const double dx = x[3 * i] - x[3 * j] - sx * 20.0, dy = x[3 * i + 1] - x[3 * j + 1] - sy * 20.0,
                       dz = x[3 * i + 2] - x[3 * j + 2];
          const double r2 = dx * dx + dy * dy + dz * dz, s = c * q[i] * q[j] / (r2 * std::sqrt(r2));
          ref[3 * i] += s * dx;
          ref[3 * i + 1] += s * dy;
          ref[3 * i + 2] += s * dz;
        }
  const double err = rel_rms(f, ref);
  std::printf("[ image block ] force error %.3g, %g M2L, %g P2P pairs\n", err, l.var("f_fmm[3]"),
              l.var("f_fmm[4]"));
  EXPECT_LT(err, 1e-6);
  EXPECT_GT(l.var("f_fmm[3]"), 0.0) << "no M2L translation was used";
}

// farfield exact on a neutral system vs ewald + slab at 1e-10 (volfactor 3 and 6 agree)
TEST(CoulFMM, ExactFarFieldVsEwaldSlab)
{
  auto ewald = [](double slab) {
    Lmp l;
    random_charges(l, "p p f", 300, 20.0, 40.0, 99);
    l.cmds({"pair_style coul/long 9.0", "pair_coeff * *", "kspace_style ewald 1e-10",
            fmt::format("kspace_modify slab {}", slab), "run 0 post no"});
    return gather(l, "f", 3);
  };
  const auto f3 = ewald(3.0), f6 = ewald(6.0);
  const double conv = rel_rms(f3, f6);
  std::printf("[ ewald slab ] volfactor 3 vs 6: %.3g\n", conv);
  EXPECT_LT(conv, 1e-6) << "the slab reference must be converged in its volume factor";
  for (double acc : {1e-4, 1e-6}) {
    Lmp l;
    random_charges(l, "p p f", 300, 20.0, 40.0, 99);
    l.cmds({fmt::format("fix fmm all coul/fmm accuracy {} farfield exact", acc), "run 0 post no"});
    const double err = rel_rms(gather(l, "f", 3), f6);
    std::printf("[ exact far field ] accuracy %g: force error vs ewald+slab %.3g\n", acc, err);
    // the reference itself is converged to ~1e-7; the allowance is the requested accuracy
    EXPECT_LT(err, acc + 1e-6);
  }
}

// a net-charged layer: far above it the field tends to the sheet field 2 pi sum(q) / A
// (Gaussian units; times qqr2e in LAMMPS units); the total force on the layer vanishes
TEST(CoulFMM, NetChargedLayerSheetField)
{
  Lmp l;
  l.cmds({"units real", "atom_style charge", "atom_modify map array", "boundary p p f",
          "region box block 0 10 0 10 0 200", "create_box 2 box",
          "region layer block 0 10 0 10 0 2", "create_atoms 1 random 200 5 layer overlap 0.3",
          "create_atoms 2 single 3.3 7.1 150.0", "mass * 1.0", "set type 1 charge 1.0",
          "set type 2 charge 1e-3", "fix fmm all coul/fmm accuracy 1e-6 farfield exact",
          "run 0 post no"});
  const double sheet = 332.06371 * 2.0 * M_PI * 200.0 / 100.0;
  const double ez = l.var("fz[201]") / 1e-3;
  std::printf("[ sheet ] Ez far above / (2 pi sigma) = %.8f\n", ez / sheet);
  // at 150 A above a 10 A cell the non-uniform part decays like exp(-2 pi z / L): nothing left
  EXPECT_NEAR(ez / sheet, 1.0, 1e-5);
  double fz = 0.0, frms = 0.0;
  for (int i = 1; i <= 200; ++i) {
    fz += l.var(fmt::format("fz[{}]", i));
    frms += std::pow(l.var(fmt::format("fz[{}]", i)), 2);
  }
  // a periodic layer exerts no net force on itself; sum of 200 forces with relative errors
  // ~1e-6 each
  EXPECT_LT(std::fabs(fz), 1e-5 * std::sqrt(frms * 200.0));
}

// translating all atoms by any horizontal vector (incl. a lattice vector) changes nothing
TEST(CoulFMM, TranslationInvariance)
{
  std::vector<double> base;
  for (double shift : {0.0, 20.0, 7.3}) {
    Lmp l;
    random_charges(l, "p p f", 300, 20.0, 40.0, 123);
    if (shift != 0.0)
      l.cmd(fmt::format("displace_atoms all move {} {} 0 units box", shift, shift == 20.0 ? 20.0 : 0.5 * shift));
    l.cmds({"fix fmm all coul/fmm accuracy 1e-6", "run 0 post no"});
    const auto f = gather(l, "f", 3);
    if (base.empty()) base = f;
    const double d = rel_rms(f, base);
    std::printf("[ invariance ] shift %g: relative change %.3g\n", shift, d);
    // a lattice shift moves particles by exactly L (x + L - L round-off only); a general shift
    // changes the tree, so the FMM's own error (< 1e-6) is the bound
    EXPECT_LT(d, shift == 20.0 ? 1e-10 : 2e-6);
  }
}

TEST(CoulFMM, FarFieldAverageRunsAndDiffersFromExact)
{
  std::vector<double> fe, fa;
  for (const char *ff : {"exact", "average"}) {
    Lmp l;
    random_charges(l, "p p f", 300, 20.0, 40.0, 55);
    l.cmds({"set group all charge 1.0", fmt::format("fix fmm all coul/fmm farfield {}", ff),
            "run 0 post no"});
    (std::string(ff) == "exact" ? fe : fa) = gather(l, "f", 3);
  }
  const double d = rel_rms(fa, fe);
  std::printf("[ average vs exact ] relative RMS force difference %.3g\n", d);
  EXPECT_GT(d, 0.0);
  EXPECT_LT(d, 0.5);
}

TEST(CoulFMM, NoChargesAndCoincidentAtoms)
{
  {
    Lmp l;
    random_charges(l, "p p f", 50, 20.0, 40.0, 1);
    l.cmds({"set group all charge 0.0", "fix fmm all coul/fmm", "run 0 post no"});
    for (double v : gather(l, "f", 3)) EXPECT_EQ(v, 0.0);
    EXPECT_EQ(l.var("f_fmm"), 0.0);
  }
  // identical and nearly identical positions (1e-13 apart in a 10 A box, far below the
  // solver's coincidence radius) are one error that names the atoms by ID
  for (const char *second : {"1 1 1", "1.0000000000001 1 1"}) {
    const std::string msg =
        error_of({"units real", "atom_style charge", "boundary f f f",
                  "region box block 0 10 0 10 0 10", "create_box 1 box",
                  "create_atoms 1 single 5 5 5", "create_atoms 1 single 1 1 1",
                  std::string("create_atoms 1 single ") + second, "mass 1 1",
                  "set group all charge 1.0", "fix fmm all coul/fmm", "run 0 post no"});
    EXPECT_TRUE(std::regex_search(msg, std::regex("coul/fmm.*atoms 2 and 3 are at the same position")))
        << msg;
  }
}

TEST(CoulFMM, BadInput)
{
  auto run_with = [](const std::string &atom_style, const std::string &boundary,
                     const std::string &fix, const std::string &extra = "") {
    std::vector<std::string> c = {"units real", "atom_style " + atom_style};
    if (!extra.empty()) c.push_back(extra);
    c.insert(c.end(), {"boundary " + boundary, "region box block 0 10 0 10 0 10", "create_box 1 box",
                       "create_atoms 1 single 1 1 1", "mass 1 1", fix, "run 0 post no"});
    return error_of(c);
  };
  auto expect_match = [](const std::string &msg, const std::string &re) {
    EXPECT_TRUE(std::regex_search(msg, std::regex(re))) << "message: " << msg << "\nexpected: " << re;
  };
  expect_match(run_with("atomic", "p p f", "fix fmm all coul/fmm"), "requires an atom style with charge");
  expect_match(run_with("charge", "p p p", "fix fmm all coul/fmm"), "boundary f f f .* or p p f.*got periodicity p p p");
  expect_match(run_with("charge", "p f p", "fix fmm all coul/fmm"), "got periodicity p f p");
  expect_match(error_of({"units real", "atom_style charge", "boundary p p f",
                         "region box prism 0 10 0 10 0 10 1 0 0", "create_box 1 box", "mass 1 1",
                         "fix fmm all coul/fmm", "run 0 post no"}),
               "does not support triclinic");
  expect_match(error_of({"units lj", "dimension 2", "atom_style charge", "boundary p p p",
                         "region box block 0 10 0 10 -0.5 0.5", "create_box 1 box", "mass 1 1",
                         "fix fmm all coul/fmm", "run 0 post no"}),
               "requires a 3d simulation");
  expect_match(run_with("charge", "p p f", "fix fmm all coul/fmm bogus 1"), "Unknown fix coul/fmm keyword: bogus");
  expect_match(run_with("charge", "p p f", "fix fmm all coul/fmm accuracy 0"), "accuracy must be in \\(0,1\\), got 0");
  expect_match(run_with("charge", "p p f", "fix fmm all coul/fmm accuracy 1"), "accuracy must be in \\(0,1\\), got 1");
  expect_match(run_with("charge", "p p f", "fix fmm all coul/fmm order 31"), "order must be <= 30, got 31");
  expect_match(run_with("charge", "p p f", "fix fmm all coul/fmm leaf -1"), "leaf must be >= 0 \\(0 = auto\\), got -1");
  // checked once, by gcfmm::Options::validate() (0 means automatic for order, theta and leaf)
  expect_match(run_with("charge", "p p f", "fix fmm all coul/fmm theta 1"), "theta must be in \\[0,1\\) \\(0 = auto\\), got 1");
  expect_match(run_with("charge", "p p f", "fix fmm all coul/fmm images 21"), "images must be <= 20, got 21");
  expect_match(run_with("charge", "p p f", "fix fmm all coul/fmm images -1"), "images must be >= 0, got -1");
  expect_match(run_with("charge", "p p f", "fix fmm all coul/fmm images 0"), "farfield exact with boundary p p f needs images >= 1, got images 0");
  expect_match(run_with("charge", "p p f", "fix fmm all coul/fmm farfield maybe"), "farfield must be exact, average or none, got maybe");
  expect_match(run_with("charge", "p p f", "fix fmm all coul/fmm every 0"), "every must be >= 1, got 0");
  expect_match(run_with("charge", "p p f", "fix fmm all coul/fmm near -1"), "near cutoff must be >= 0, got -1");
  expect_match(run_with("charge", "p p f", "fix fmm all coul/fmm check -1"), "check must be >= 0, got -1");
  expect_match(run_with("charge", "p p f", "fix fmm all coul/fmm tolerance -1e-4 every 8"), "tolerance must be in \\[0, 1\\), got -0.0001");
  expect_match(run_with("charge", "p p f", "fix fmm all coul/fmm tolerance 1e-4"), "tolerance 0.0001 needs every > 1");
}

// settings that were accepted without a word or refused with a message that
// did not fit. Warnings are read from the screen output of rank 0.
TEST(CoulFMM, CoulombPairStyleFreeSpaceKeywordsNearCutoff)
{
  auto screen_of = [](const std::vector<std::string> &cmds) {
    ::testing::internal::CaptureStdout();
    std::string error;
    try {
      Lmp l(MPI_COMM_WORLD, false);
      l.cmds(cmds);
    } catch (LAMMPS_NS::LAMMPSException &e) {
      error = e.what();
    }
    return ::testing::internal::GetCapturedStdout() + error;
  };
  int me;
  MPI_Comm_rank(MPI_COMM_WORLD, &me);
  auto expect_match = [me](const std::string &out, const std::string &re) {
    if (me == 0)
      EXPECT_TRUE(std::regex_search(out, std::regex(re))) << "output: " << out << "\nexpected: " << re;
  };
  auto base = [](const std::string &boundary) {
    return std::vector<std::string>{"units real", "atom_style charge", "boundary " + boundary,
                                    "region box block 0 10 0 10 0 10", "create_box 1 box",
                                    "create_atoms 1 single 1 1 1", "create_atoms 1 single 5 5 5",
                                    "mass 1 1", "set group all charge 1.0"};
  };
  auto with = [&](const std::string &boundary, const std::vector<std::string> &extra) {
    auto c = base(boundary);
    c.insert(c.end(), extra.begin(), extra.end());
    c.push_back("run 0 post no");
    return c;
  };
  // a pair style with a Coulomb part counts the pairs within its cutoff twice
  const std::vector<std::pair<std::string, std::string>> coul_pairs = {
      {"coul/cut", "pair_coeff * *"}, {"lj/cut/coul/cut", "pair_coeff * * 0.1 1.0"}};
  for (const auto &pair : coul_pairs) {
    const auto out = screen_of(with("p p f", {"pair_style " + pair.first + " 5.0", pair.second,
                                              "fix fmm all coul/fmm"}));
    expect_match(out, "WARNING: Fix coul/fmm fmm is used together with pair style " + pair.first +
                          ", which computes Coulomb interactions too");
  }
  {
    const auto out = screen_of(with("p p f", {"pair_style lj/cut 5.0", "pair_coeff * * 0.1 1.0",
                                              "fix fmm all coul/fmm"}));
    if (me == 0) EXPECT_EQ(out.find("computes Coulomb interactions too"), std::string::npos) << out;
  }
  // free space has no images: images 0 runs (before: an error about the exact far field),
  // images and farfield are reported as without effect
  for (const char *kw : {"images 0", "farfield average", "farfield none"}) {
    const auto out = screen_of(with("f f f", {std::string("fix fmm all coul/fmm ") + kw}));
    expect_match(out, "WARNING: Fix coul/fmm fmm: keyword " +
                          std::string(kw).substr(0, std::string(kw).find(' ')) +
                          " has no effect in free space");
  }
  EXPECT_EQ(error_of(with("f f f", {"fix fmm all coul/fmm images 0"})), "no error");
  // near beyond the periodic cell: an error naming near and the cell (before: LAMMPS's
  // neighbor-list overflow once the list held every pair with its images)
  const std::string msg = error_of(with("p p f", {"fix fmm all coul/fmm every 5 near 12"}));
  EXPECT_TRUE(std::regex_search(msg, std::regex("coul/fmm near 12 must be smaller than the "
                                                "periodic cell \\(Lx = 10, Ly = 10\\)")))
      << msg;
  EXPECT_EQ(error_of(with("p p f", {"fix fmm all coul/fmm every 5 near 9.9"})), "no error");
  // free space: near beyond the system is allowed (every pair refreshed, test below)
  EXPECT_EQ(error_of(with("f f f", {"fix fmm all coul/fmm every 5 near 50"})), "no error");
}

// per-atom output (Ex, Ey, Ez, phi), every N, fix_modify virial, dielectric
TEST(CoulFMM, PerAtomFieldEveryVirialDielectric)
{
  // per-atom field: F = q E exactly; energy = 1/2 sum q phi
  {
    Lmp l;
    random_charges(l, "p p f", 200, 20.0, 40.0, 17);
    l.cmds({"fix fmm all coul/fmm accuracy 1e-6", "variable fxe atom q*f_fmm[1]-fx",
            "variable ue atom 0.5*q*f_fmm[4]", "compute sfx all reduce sumabs v_fxe",
            "compute ue all reduce sum v_ue", "run 0 post no"});
    EXPECT_LT(l.var("c_sfx"), 1e-12 * l.var("sqrt(c_ue^2)"));
    EXPECT_NEAR(l.var("c_ue"), l.var("f_fmm"), 1e-12 * std::fabs(l.var("f_fmm")));
  }
  // every 5: between evaluations the stored field is applied; moving atoms feel the field of
  // the last evaluation until the next one
  {
    Lmp l;
    random_charges(l, "p p f", 200, 20.0, 40.0, 17);
    l.cmds({"velocity all create 300 5 loop geom", "fix nve all nve", "timestep 1.0",
            "fix fmm all coul/fmm accuracy 1e-6 every 5", "run 0 post no"});
    const auto f0 = gather(l, "f", 3);
    const auto q0 = gather(l, "q", 1);
    l.cmd("run 3 post no");
    const auto f3 = gather(l, "f", 3);
    EXPECT_EQ(rel_rms(f3, f0), 0.0) << "steps 1-4 reuse the field of step 0";
    l.cmd("run 2 post no");
    EXPECT_GT(rel_rms(gather(l, "f", 3), f0), 1e-8) << "step 5 recomputes";
  }
  // virial in free space: sum x_i F_i equals the pairwise virial of coul/cut
  {
    Lmp l;
    random_charges(l, "f f f", 300, 30.0, 30.0, 8);
    l.cmds({"pair_style coul/cut 100.0", "pair_coeff * *", "compute p all pressure NULL virial",
            "thermo_style custom step c_p[1] c_p[3] c_p[6]", "run 0 post no"});
    const double pxx = l.var("c_p[1]"), pzz = l.var("c_p[3]"), pyz = l.var("c_p[6]");
    l.cmds({"pair_style zero 1.0", "pair_coeff * *", "fix fmm all coul/fmm accuracy 1e-6",
            "fix_modify fmm virial yes", "run 0 post no"});
    const double scale = std::fabs(pxx) + std::fabs(pzz);
    EXPECT_NEAR(l.var("c_p[1]"), pxx, 1e-5 * scale);
    EXPECT_NEAR(l.var("c_p[3]"), pzz, 1e-5 * scale);
    EXPECT_NEAR(l.var("c_p[6]"), pyz, 1e-5 * scale);
  }
  // the dielectric constant divides all Coulomb forces (force->qqrd2e)
  {
    Lmp l1, l2;
    random_charges(l1, "p p f", 100, 20.0, 40.0, 3);
    random_charges(l2, "p p f", 100, 20.0, 40.0, 3);
    l1.cmds({"fix fmm all coul/fmm", "run 0 post no"});
    l2.cmds({"dielectric 2.0", "fix fmm all coul/fmm", "run 0 post no"});
    auto f1 = gather(l1, "f", 3), f2 = gather(l2, "f", 3);
    for (auto &v : f2) v *= 2.0;
    EXPECT_LT(rel_rms(f2, f1), 1e-14);
  }
}

// atoms inserted by fix deposit between two scheduled evaluations (every 10) feel the field
// from their first step: the fix recomputes when the atom count changes (and a created atom
// starts from a zero stored field, never uninitialised memory)
TEST(CoulFMM, EveryWithDeposit)
{
  {
    FILE *fp = fopen("coul_fmm_particle.mol", "w");
    fputs("# charged particle\n\n1 atoms\n\nCoords\n\n1 0 0 0\n\nTypes\n\n1 1\n\nCharges\n\n1 1.0\n", fp);
    fclose(fp);
  }
  Lmp l;
  random_charges(l, "p p f", 100, 20.0, 60.0, 5);
  l.cmds({"region top block 0 20 0 20 50 55", "molecule part coul_fmm_particle.mol",
          "fix nve all nve", "timestep 0.1",
          "fix feed all deposit 3 0 7 4711 region top mol part near 1.0 vz -0.01 -0.01",
          "fix fmm all coul/fmm accuracy 1e-6 every 10", "run 0 post no", "run 8 post no"});
  // fix deposit inserts on steps 1 and 8: neither is a scheduled evaluation (0, 10)
  ASSERT_EQ(l.var("count(all)"), 102.0);
  const double ez_new = l.var("F_fmm[102][3]");    // stored field of the atom inserted at step 8
  EXPECT_NE(ez_new, 0.0);
  l.cmd("run 0 post no");    // a fresh evaluation at the same positions
  EXPECT_NEAR(l.var("F_fmm[102][3]"), ez_new, 1e-9 * std::fabs(ez_new));
  std::remove("coul_fmm_particle.mol");
}

// ---- the stored field must be re-evaluated whenever it no longer belongs to
// the charges (values, atom IDs), qqrd2e or the boundary. Each case compares the fix's energy
// and forces with a fresh evaluation at the same positions and charges: the same tree, so the
// two agree to round-off (1e-10 allows for the order of the MPI sums); a stale field is off
// by 1e-2 or more in every case (before the fix: 25% in energy for fix adapt, the
// dielectric's factor 2, the 3 x 3 image block missing after change_box).

namespace {
// forces by atom ID 1 .. max(id) (zero for IDs no atom has: fix evaporate leaves gaps, which
// lammps_gather_atoms does not allow)
std::vector<double> forces_by_id(Lmp &l, int n)
{
  std::vector<int> ids(n);
  for (int i = 0; i < n; i++) ids[i] = i + 1;
  std::vector<double> f(3 * (size_t) n);
  lammps_gather_atoms_subset(l.lmp, (char *) "f", 1, 3, n, ids.data(), f.data());
  return f;
}

// energy and forces of a fresh fix at the current state of l (the old fix removed)
std::pair<double, std::vector<double>> fresh_evaluation(Lmp &l, const std::string &old_fix,
                                                        int maxid)
{
  l.cmds({"unfix " + old_fix, "fix fresh all coul/fmm accuracy 1e-6", "run 0 post no"});
  return {l.var("f_fresh"), forces_by_id(l, maxid)};
}

// energy and forces of fix fmm as they stand against a fresh fix at the same positions
void expect_as_fresh(Lmp &l, const char *what, int maxid)
{
  const double e = l.var("f_fmm");
  const auto f = forces_by_id(l, maxid);
  const auto ref = fresh_evaluation(l, "fmm", maxid);
  std::printf("[ stale: %s ] energy %.8g vs fresh %.8g, forces %.3g\n", what, e, ref.first,
              rel_rms(f, ref.second));
  EXPECT_NEAR(e, ref.first, 1e-10 * std::fabs(ref.first));
  EXPECT_LT(rel_rms(f, ref.second), 1e-10);
}
}    // namespace

// fix adapt changes charges during a run, between scheduled evaluations (every 10)
TEST(CoulFMM, StaleFieldChargesAdapted)
{
  Lmp l;
  random_charges(l, "p p f", 200, 20.0, 40.0, 17);
  l.cmds({"group odd id 1:200:2", "variable qa equal 1.0+0.2*step",
          "fix ad odd adapt 1 atom charge v_qa reset no",
          "fix fmm all coul/fmm accuracy 1e-6 every 10", "run 3 post no", "unfix ad"});
  expect_as_fresh(l, "fix adapt", 200);
}

// fix deposit inserts a charge and fix evaporate removes one on the same step (step 8): the
// atom count is unchanged, but the new charge must feel and exert the field, the removed one no
// longer act
TEST(CoulFMM, StaleFieldInsertAndDeleteSameStep)
{
  {
    FILE *fp = fopen("coul_fmm_swap.mol", "w");
    fputs("# charged particle\n\n1 atoms\n\nCoords\n\n1 0 0 0\n\nTypes\n\n1 1\n\nCharges\n\n1 1.0\n", fp);
    fclose(fp);
  }
  Lmp l;
  random_charges(l, "p p f", 100, 20.0, 60.0, 5);
  l.cmds({"region top block 0 20 0 20 50 55", "region low block 0 20 0 20 0 30",
          "molecule part coul_fmm_swap.mol", "fix nve all nve", "timestep 0.1",
          "fix feed all deposit 3 0 7 4711 region top mol part near 1.0 vz -0.01 -0.01",
          "fix gone all evaporate 8 1 low 99",
          "fix fmm all coul/fmm accuracy 1e-6 every 10", "run 0 post no", "run 8 post no"});
  std::remove("coul_fmm_swap.mol");
  // deposit on steps 1 and 8, evaporate on step 8: 100 + 2 - 1
  ASSERT_EQ(l.var("count(all)"), 101.0);
  l.cmds({"unfix feed", "unfix gone"});
  // IDs 1-100, 101 and 102 inserted, one of 1-100 gone
  expect_as_fresh(l, "deposit + evaporate", 102);
}

// dielectric changed between runs: run 0 must report the new energy (qqrd2e changed)
TEST(CoulFMM, StaleFieldDielectricChanged)
{
  for (const char *every : {"1", "10"}) {
    Lmp l;
    random_charges(l, "p p f", 100, 20.0, 40.0, 3);
    l.cmds({fmt::format("fix fmm all coul/fmm accuracy 1e-6 every {}", every), "run 0 post no"});
    const double e1 = l.var("f_fmm");
    const auto f1 = gather(l, "f", 3);
    l.cmds({"dielectric 2.0", "run 0 post no"});
    auto f2 = gather(l, "f", 3);
    for (auto &v : f2) v *= 2.0;
    std::printf("[ stale: dielectric ] every %s: 2 E(eps = 2) / E(eps = 1) = %.15g\n", every,
                2.0 * l.var("f_fmm") / e1);
    EXPECT_NEAR(2.0 * l.var("f_fmm"), e1, 1e-12 * std::fabs(e1));
    EXPECT_LT(rel_rms(f2, f1), 1e-12);
  }
}

// change_box from free space to p p f between runs: the periodic field, not the free one
TEST(CoulFMM, StaleFieldBoundaryChanged)
{
  Lmp l;
  random_charges(l, "f f f", 100, 20.0, 40.0, 3);
  l.cmds({"fix fmm all coul/fmm accuracy 1e-6", "run 0 post no", "change_box all boundary p p f",
          "run 0 post no"});
  expect_as_fresh(l, "change_box", 100);
}

// 100 charges in a 10 A cell and one charge 1e6 A above them (H/L = 1e5):
// the exact far field would need ~1e5 boxes (before: std::bad_alloc; H/L = 1e4 was killed by
// the out-of-memory killer): a clear error before anything is allocated, naming the cost and
// what to do; farfield average is not limited
TEST(CoulFMM, TallColumnStopsWithItsCost)
{
  auto cmds = [](const std::string &farfield) {
    return std::vector<std::string>{"units real", "atom_style charge", "atom_modify map array",
                                    "boundary p p f", "region box block 0 10 0 10 0 1e6",
                                    "create_box 1 box", "region bed block 0 10 0 10 0 10",
                                    "create_atoms 1 random 100 5 bed overlap 0.5",
                                    "create_atoms 1 single 5 5 999990", "mass 1 1",
                                    "set group all charge 1.0",
                                    "fix fmm all coul/fmm farfield " + farfield, "run 0 post no"};
  };
  const std::string msg = error_of(cmds("exact"));
  EXPECT_TRUE(std::regex_search(
      msg, std::regex("coul/fmm: FMM library: .*exact far field of a column 1.2e\\+05 cell sides "
                      "high needs .* boxes and about .* GB .*use farfield average or none")))
      << msg;
  EXPECT_EQ(error_of(cmds("average")), "no error");
}

// a run continued from a restart file equals the uninterrupted run
TEST(CoulFMM, Restart)
{
  const std::string file = "coul_fmm.restart";
  std::vector<double> straight, restarted;
  {
    Lmp l;
    random_charges(l, "p p m", 200, 20.0, 40.0, 21);    // m: shrink-wrapped open z
    l.cmds({"mass 1 1000.0", "velocity all create 300 5 loop geom", "fix nve all nve",
            "timestep 0.5",
            "fix fmm all coul/fmm accuracy 1e-6", "run 20 post no", "write_restart " + file,
            "run 20 post no"});
    straight = gather(l, "x", 3);
  }
  {
    Lmp l;
    l.cmds({"read_restart " + file, "fix nve all nve", "fix fmm all coul/fmm accuracy 1e-6",
            "run 20 post no"});
    restarted = gather(l, "x", 3);
  }
  std::remove(file.c_str());
  EXPECT_LT(rel_rms(restarted, straight), 1e-13);
}

// 1 and 2 ranks agree to 1e-12 (every target is computed by one rank, in the same order)
TEST(CoulFMM, OneVersusTwoRanks)
{
  if (nprocs() != 2) GTEST_SKIP() << "needs mpirun -np 2";
  auto forces = [](MPI_Comm comm) {
    Lmp l(comm);
    // create_atoms random assigns IDs in a rank-dependent way: use a jittered lattice instead
    // (displace_atoms random seeds per atom from its coordinates: the same on any rank count)
    l.cmds({"units real", "atom_style charge", "atom_modify map array sort 0 0", "boundary p p f",
            "lattice sc 2.5", "region box block 0 8 0 8 0 24", "create_box 1 box",
            "region inner block INF INF INF INF 1 23", "create_atoms 1 region inner", "mass 1 1.0",
            "displace_atoms all random 0.8 0.8 0.8 31 units box",
            "variable qq atom 2*(id%2)-1", "set group all charge v_qq"});
    l.cmds({"fix fmm all coul/fmm accuracy 1e-5", "run 0 post no"});
    auto f = gather(l, "f", 3);
    f.push_back(l.var("f_fmm"));
    return f;
  };
  const auto two = forces(MPI_COMM_WORLD);
  int me;
  MPI_Comm_rank(MPI_COMM_WORLD, &me);
  std::vector<double> one(two.size());
  if (me == 0) one = forces(MPI_COMM_SELF);
  MPI_Bcast(one.data(), (int) one.size(), MPI_DOUBLE, 0, MPI_COMM_WORLD);
  const double d = rel_rms(two, one);
  if (me == 0) std::printf("[ ranks ] 2 vs 1 rank: relative RMS difference %.3g\n", d);
  EXPECT_LT(d, 1e-12);
}

// ---- inputs that once gave a silent wrong answer: now the right answer or a clear error ----

// results are matched to atoms by ID: without IDs the fix must refuse
TEST(CoulFMM, RequiresAtomIDs)
{
  const std::string msg = error_of({"units real", "atom_style charge", "atom_modify id no",
                                    "boundary p p f", "region box block 0 10 0 10 0 10",
                                    "create_box 1 box", "create_atoms 1 single 1 1 1",
                                    "create_atoms 1 single 5 5 5", "mass 1 1",
                                    "set group all charge 1.0", "fix fmm all coul/fmm",
                                    "run 0 post no"});
  EXPECT_TRUE(std::regex_search(msg, std::regex("coul/fmm requires atom IDs"))) << msg;
}

// run_style respa with one inner step per outer step is velocity Verlet: the trajectory with
// the Coulomb force applied at the outer level equals the verlet one to round-off
TEST(CoulFMM, RespaAppliesTheForce)
{
  // heavy atoms, short run: no close approach of opposite charges (no repulsion here)
  auto trajectory = [](const std::string &run_style) {
    Lmp l;
    random_charges(l, "p p m", 100, 20.0, 40.0, 44);
    l.cmds({"mass 1 1000.0", "pair_style zero 5.0", "pair_coeff * *", "velocity all create 100 5 loop geom",
            "fix nve all nve", "timestep 0.5", run_style,
            "fix fmm all coul/fmm accuracy 1e-8 farfield exact", "fix_modify fmm energy yes",
            "run 20 post no"});
    auto x = gather(l, "x", 3);
    x.push_back(l.var("pe"));
    return x;
  };
  const auto verlet = trajectory("run_style verlet");
  const auto respa = trajectory("run_style respa 2 1");
  auto noforce = [] {
    Lmp l;
    random_charges(l, "p p m", 100, 20.0, 40.0, 44);
    l.cmds({"mass 1 1000.0", "pair_style zero 5.0", "pair_coeff * *", "velocity all create 100 5 loop geom",
            "fix nve all nve", "timestep 0.5", "run 20 post no"});
    auto x = gather(l, "x", 3);
    x.push_back(0.0);
    return x;
  }();
  // the Coulomb force must have moved the atoms measurably in 20 steps
  ASSERT_GT(rel_rms(noforce, verlet), 1e-9);
  EXPECT_LT(rel_rms(respa, verlet), 1e-12);
}

// a minimizer's line search evaluates several positions within one step: every evaluation
// must be fresh, also with every N > 1 (ignored there, with a warning)
TEST(CoulFMM, MinimizeUsesCurrentPositions)
{
  Lmp l;
  l.cmds({"units real", "atom_style charge", "atom_modify map array sort 0 0", "boundary m m m",
          "lattice sc 3.0", "region box block 0 4 0 4 0 4", "create_box 1 box",
          "create_atoms 1 region box", "mass 1 1.0", "variable qq atom 0.5*(2*(id%2)-1)",
          "set group all charge v_qq", "displace_atoms all random 0.4 0.4 0.4 7 units box",
          "pair_style lj/cut 6.0", "pair_coeff * * 0.2 2.8",
          "fix fmm all coul/fmm accuracy 1e-8 every 5", "fix_modify fmm energy yes",
          "thermo_style custom step pe", "minimize 0 1e-10 200 2000"});
  const auto f_end = gather(l, "f", 3);
  const double e_end = l.var("pe");
  l.cmd("run 0 post no");    // a fresh evaluation at the final positions
  const auto f_fresh = gather(l, "f", 3);
  EXPECT_LT(rel_rms(f_end, f_fresh), 1e-10);
  EXPECT_NEAR(e_end, l.var("pe"), 1e-10 * std::fabs(e_end));
}

TEST(CoulFMM, ConflictingOrIgnoredSettings)
{
  auto setup = std::vector<std::string>{"units real",
                                        "atom_style charge",
                                        "boundary p p f",
                                        "region box block 0 10 0 10 0 10",
                                        "create_box 1 box",
                                        "create_atoms 1 single 1 1 1",
                                        "create_atoms 1 single 5 5 5",
                                        "mass 1 1",
                                        "set group all charge 1.0",
                                        "group low id 1"};
  auto with = [&](std::vector<std::string> extra) {
    auto c = setup;
    c.insert(c.end(), extra.begin(), extra.end());
    c.push_back("run 0 post no");
    return error_of(c);
  };
  auto expect_match = [](const std::string &msg, const std::string &re) {
    EXPECT_TRUE(std::regex_search(msg, std::regex(re))) << "message: " << msg << "\nexpected: " << re;
  };
  expect_match(with({"fix a all coul/fmm", "fix b low coul/fmm"}),
               "coul/fmm a and fix coul/fmm b share 1 charged atoms");
  expect_match(with({"fix a all coul/fmm farfield exact bed 0 5"}),
               "bed applies only to farfield average");
  expect_match(with({"fix a all coul/fmm farfield none bed 0 5"}),
               "bed applies only to farfield average");
  EXPECT_EQ(with({"fix a all coul/fmm farfield average bed 0 5"}), "no error");
  // cells beyond the aspect ratio the exact far field is accurate for
  expect_match(with({"change_box all x final 0 25 units box", "fix a all coul/fmm farfield exact"}),
               "farfield exact supports cells with max\\(Lx, Ly\\) / min\\(Lx, Ly\\) <= 2, got 2.5");
  EXPECT_EQ(with({"change_box all x final 0 25 units box", "fix a all coul/fmm farfield none"}),
            "no error");
}

// with x and y periodic, only the zz virial is the lattice virial: the in-plane components
// are not tallied (a warning says so); in free space all six are (test above)
TEST(CoulFMM, VirialPeriodicOnlyZZ)
{
  Lmp l;
  random_charges(l, "p p f", 200, 20.0, 40.0, 8);
  l.cmds({"compute p all pressure NULL virial", "thermo_style custom step c_p[1] c_p[3]",
          "fix fmm all coul/fmm accuracy 1e-6", "fix_modify fmm virial yes", "run 0 post no"});
  EXPECT_EQ(l.var("c_p[1]"), 0.0);
  EXPECT_EQ(l.var("c_p[2]"), 0.0);
  EXPECT_EQ(l.var("c_p[4]"), 0.0);
  EXPECT_NE(l.var("c_p[3]"), 0.0);
}

// ---- multiple time stepping: schedule and near refresh ----

namespace {
// 200 heavy charges moving at random in a p p m box, `fix` given by the caller
void moving_charges(Lmp &l, const std::string &boundary = "p p m")
{
  random_charges(l, boundary, 200, 20.0, 40.0, 61);
  l.cmds({"mass 1 1000.0", "velocity all create 300 5 loop geom", "fix nve all nve",
          "timestep 1.0"});
}

// the positions after a new instance reads `file`, defines `fix` and runs `steps` more (a final
// run 0 wraps them as in the uninterrupted run)
std::vector<double> continued_from(const std::string &file, const std::string &fix, int steps)
{
  Lmp l;
  l.cmds({"read_restart " + file, "fix nve all nve", fix, fmt::format("run {} post no", steps),
          "run 0 post no"});
  return gather(l, "x", 3);
}
}    // namespace

// evaluations fall on multiples of every, whatever the run lengths: a run split at a step
// that is not a multiple, and one continued from a restart file written there, reproduce the
// uninterrupted run (before, every N counted from the start of each run)
TEST(CoulFMM, EveryScheduleIndependentOfRunSplit)
{
  const std::string fix = "fix fmm all coul/fmm accuracy 1e-6 every 5 near 6.0";
  std::vector<double> straight, split, restarted;
  {
    Lmp l;
    moving_charges(l);
    l.cmds({fix, "run 23 post no"});
    straight = gather(l, "x", 3);
  }
  {
    Lmp l;
    moving_charges(l);
    l.cmds({fix, "run 7 post no", "run 9 post no", "write_restart coul_fmm_every.restart",
            "run 7 post no"});
    split = gather(l, "x", 3);
  }
  {
    Lmp l;
    l.cmds({"read_restart coul_fmm_every.restart", "fix nve all nve", fix, "run 7 post no"});
    restarted = gather(l, "x", 3);
  }
  std::remove("coul_fmm_every.restart");
  EXPECT_LT(rel_rms(split, straight), 1e-14);
  EXPECT_LT(rel_rms(restarted, straight), 1e-14);
}

// near refresh: with a near cutoff beyond the system size in free space every pair is
// refreshed every step, so the field equals a fresh evaluation although the far part is never
// re-evaluated (every 1000); without it the frozen field is off by far more. Keyword check
// measures the same on every 5th step; its last value (step 15) is compared with the error
// measured by hand against a fresh fix.
TEST(CoulFMM, NearRefreshAndCheck)
{
  auto measured = [](const std::string &near) {
    Lmp l;
    moving_charges(l, "m m m");
    l.cmds({"fix fmm all coul/fmm accuracy 1e-10 order 30 every 1000 check 5 " + near, "run 15 post no"});
    const auto f = gather(l, "f", 3);
    std::vector<double> m = {l.var("f_fmm[5]"), l.var("f_fmm[6]"), l.var("f_fmm[7]")};
    l.cmds({"unfix fmm", "fix fresh all coul/fmm accuracy 1e-10 order 30", "run 0 post no"});
    m.push_back(rel_rms(f, gather(l, "f", 3)));    // the error at step 15, by hand
    return m;
  };
  const auto frozen = measured(""), refreshed = measured("near 100.0");
  std::printf("[ near/check ] frozen: last %.3g max %.3g all %.3g (by hand %.3g); refreshed: "
              "max %.3g (by hand %.3g)\n",
              frozen[0], frozen[1], frozen[2], frozen[3], refreshed[1], refreshed[3]);
  EXPECT_GT(frozen[3], 1e-6);
  // the refresh is a direct sum of differences: round-off of the field's cancellations only
  EXPECT_LT(refreshed[3], 1e-9);
  EXPECT_LT(refreshed[1], 1e-9);
  // the check at step 15 compares with an evaluation at 1e-10: agrees with the hand value
  EXPECT_NEAR(frozen[0], frozen[3], 1e-6 * frozen[3]);
  EXPECT_GE(frozen[1], frozen[0]);    // checks at steps 5, 10, 15: the error grows
}

// the near refresh holds each pair's separation at the evaluation (and the change its slope
// carries) from one neighbor list build or evaluation to the next, instead of taking it afresh
// from the displacements every step: a run that builds the lists every step (so the pairs are
// taken afresh every step) must give the same forces to round-off. every 32 with a slope
// (trend > 0 after step 64), fast atoms (30000 K) and a skin of 3: 5 list builds of its own in
// 80 steps, so held pairs outlive list builds between evaluations. A held pair kept over an
// evaluation, or over a list build, is off by the change of its field in between (~0.7 of the
// force here). On two ranks the atom IDs, hence the charges, differ from one rank: there a
// pair 1 A apart at the evaluation of step 32 flies apart at 0.5 A per step, beyond the near
// cutoff + skin (8) by step 39. A list built then no longer holds it: without the evaluation
// brought forward (CoulFMMNearRefresh::pair_leaving) its field would fall back to the one of
// step 32 (an error of 350 kcal/mol/A, the whole pair force then, on both atoms) on a step that
// depends on when the lists are built, and the two runs would differ by 1.1e-4 at step 80.
TEST(CoulFMM, NearRefreshHeldPairsAsTakenEveryStep)
{
  auto run = [](const std::string &check) {
    Lmp l;
    moving_charges(l, "p p f");
    l.cmds({"mass 1 200.0", "velocity all create 30000 5 loop geom", "neighbor 3.0 bin",
            "fix lid all wall/reflect zlo EDGE zhi EDGE",
            "atom_modify sort 1 4.0",
            "neigh_modify every 1 delay 0 check " + check,
            "fix fmm all coul/fmm accuracy 1e-8 every 32 near 5.0", "run 80 post no"});
    return std::make_pair(gather(l, "f", 3), l.var("f_fmm[10]"));
  };
  const auto [held, held_evaluations] = run("yes");
  const auto [each, each_evaluations] = run("no");
  std::printf("[ near held ] forces %.3g apart, %g and %g evaluations\n", rel_rms(held, each),
              held_evaluations, each_evaluations);
  // measured 2.1e-13 on one rank, 4.3e-13 on two (7e-14 with the pairs taken every step in
  // both runs): round-off of the refreshed differences, grown over 80 steps of fast atoms
  EXPECT_LT(rel_rms(held, each), 1e-11);
  EXPECT_EQ(held_evaluations, each_evaluations);
}

// a pair closer than near at the evaluation stays refreshed until the next one, whenever the
// lists are built: two like charges 1 A apart fly apart at 0.2 A per step (heavy), near 2,
// skin 1, lists built every step. At step 8 they are 2.6 A apart, beyond near + skin/2 = 2.5: the field is evaluated
// there, brought forward from step 1000. At step 11 (3.2 A) the pair is beyond the list's
// cutoff near + skin = 3 and beyond near at the evaluation and now, so its field is the one
// of step 8, off from the fresh one by the closed form (r_11 / r_8)^2 - 1 = 0.51 (the field of
// a point charge). Without the early evaluation the list built at step 11 would no longer hold
// the pair, and its field would fall back to the one at 1 A: off by (3.2 / 1)^2 - 1 = 9.2.
TEST(CoulFMM, NearPairLeavingTheListsIsEvaluatedAfresh)
{
  Lmp l;
  l.cmds({"units real", "atom_style charge", "atom_modify map array", "boundary m m m",
          "region box block -10 10 -10 10 -10 10", "create_box 1 box",
          "create_atoms 1 single -0.5 0.0 0.0", "create_atoms 1 single 0.5 0.0 0.0",
          "mass 1 1.0e9", "set group all charge 1.0", "velocity all set 0.0 0.0 0.0",
          "group left id 1", "group right id 2", "velocity left set -0.1 0.0 0.0 units box",
          "velocity right set 0.1 0.0 0.0 units box", "fix nve all nve", "timestep 1.0",
          "neighbor 1.0 bin", "neigh_modify every 1 delay 0 check no",
          "fix fmm all coul/fmm accuracy 1e-10 order 30 every 1000 near 2.0", "run 8 post no"});
  auto separation = [&l]() {
    const auto x = gather(l, "x", 3);
    return std::hypot(x[3] - x[0], x[4] - x[1], x[5] - x[2]);
  };
  const double r_evaluated = separation();
  l.cmds({"run 3 post no"});
  const double r_now = separation(), evaluations = l.var("f_fmm[10]");
  const auto f = gather(l, "f", 3);
  l.cmds({"unfix fmm", "fix fresh all coul/fmm accuracy 1e-10 order 30", "run 0 post no"});
  const double error = std::fabs(f[0] / gather(l, "f", 3)[0] - 1.0);
  const double frozen = std::pow(r_now / r_evaluated, 2) - 1.0;
  std::printf("[ near leaving ] separations %.4g at step 8 and %.4g at step 11, %g evaluations; "
              "force off by %.6g (frozen since step 8: %.6g, %.2g apart)\n",
              r_evaluated, r_now, evaluations, error, frozen, std::fabs(error - frozen));
  EXPECT_EQ(evaluations, 2.0);
  // the closed form takes the separations the atoms had (their repulsion included); measured
  // to round-off, 1e-9 leaves room for the solver's accuracy (1e-10)
  EXPECT_NEAR(error, frozen, 1e-9);
}

// a pair closer than near at the evaluation that passes the list's cutoff (near + skin) between
// two steps, faster than the refresh's margin (skin/4 per step per atom): two like charges 1 A
// apart at the evaluation of step 0 fly apart at `speed` A per step each. The list built when
// they have passed near + skin no longer holds them; the field is evaluated afresh then (two
// evaluations), and the force equals LAMMPS's direct coul/cut at the same positions. Without
// it the pair's field would stay that of the evaluation at 1 A: off by (r / 1 A)^2 - 1,
// ~11x for the jump of 1.25 A (skin 0.4) and ~9x for 0.09 A per step with a skin of 0.01.
TEST(CoulFMM, NearPairJumpingOutOfTheListsIsEvaluatedAfresh)
{
  struct Case {
    double skin, speed;
    int steps;
  };
  for (const Case c : {Case{0.4, 1.25, 1}, Case{0.01, 0.09, 12}}) {
    Lmp l;
    l.cmds({"units real", "atom_style charge", "atom_modify map array", "boundary f f f",
            "region box block -10 10 -10 10 -10 10", "create_box 1 box",
            "create_atoms 1 single -0.5 0.0 0.0", "create_atoms 1 single 0.5 0.0 0.0",
            "mass 1 1.0e12", "set group all charge 1.0", "velocity all set 0.0 0.0 0.0",
            "group left id 1", "group right id 2",
            fmt::format("velocity left set {} 0.0 0.0 units box", -c.speed),
            fmt::format("velocity right set {} 0.0 0.0 units box", c.speed), "fix nve all nve",
            "timestep 1.0", fmt::format("neighbor {} bin", c.skin),
            "neigh_modify every 1 delay 0 check yes",
            "fix fmm all coul/fmm accuracy 1e-10 order 30 every 64 near 3.0",
            fmt::format("run {} post no", c.steps)});
    const auto f = gather(l, "f", 3);
    const double evaluations = l.var("f_fmm[10]");
    l.cmds({"unfix fmm", "pair_style coul/cut 50.0", "pair_coeff * *", "run 0 post no"});
    const auto reference = gather(l, "f", 3);
    const auto x = gather(l, "x", 3);
    const double r = x[3] - x[0];
    std::printf("[ near jump ] skin %g, %g A per step: %.4g A apart after %d steps, %g "
                "evaluations, force off by %.3g\n",
                c.skin, c.speed, r, c.steps, evaluations, rel_rms(f, reference));
    EXPECT_GT(r, 3.0 + c.skin);
    EXPECT_EQ(evaluations, 2.0);
    // a fresh evaluation at 1e-10 of two charges against the direct sum: the solver's accuracy
    EXPECT_LT(rel_rms(f, reference), 1e-6);
  }
}

// extrapolation of the far part: on nearly straight trajectories (heavy charges) the far part
// of the field changes nearly linearly between evaluations, so the slope of the last two
// evaluations removes most of the error of a frozen field; the close pairs, whose field is not
// linear in time, are refreshed (near). Measured at step 59, 9 steps after an evaluation.
TEST(CoulFMM, ExtrapolationFollowsSmoothMotion)
{
  auto measured = [](const std::string &extrapolate) {
    Lmp l;
    moving_charges(l, "p p m");
    l.cmds({"mass 1 100000.0",
            "fix fmm all coul/fmm accuracy 1e-10 order 30 every 10 near 5.0 check 59 extrapolate " +
                extrapolate,
            "run 59 post no"});
    return l.var("f_fmm[5]");
  };
  const double frozen = measured("no"), extrapolated = measured("yes");
  std::printf("[ extrapolate ] every 10, near 5: frozen far part %.3g, extrapolated %.3g\n",
              frozen, extrapolated);
  EXPECT_GT(frozen, 1e-7);
  EXPECT_LT(extrapolated, 0.1 * frozen);
}

// keyword tolerance: the interval adapts to the error the time stepping reaches, measured at
// each evaluation (field that would have been applied against the new one). A loose tolerance
// lets it grow beyond 1 with the checked error within the tolerance; a tolerance below what any
// interval of 2 can reach brings it down to 1 (every step evaluated, nothing left to check).
// 1e-10 accuracy: the solver's own error must not enter the measured time-stepping error.
TEST(CoulFMM, ToleranceAdaptsTheInterval)
{
  auto run = [](const std::string &tolerance) {
    Lmp l;
    moving_charges(l);
    // heavy: no pair of opposite charges collapses within the run (the atom IDs, hence the
    // charges, depend on the number of ranks)
    l.cmds({"mass 1 100000.0",
            "fix fmm all coul/fmm accuracy 1e-10 order 30 every 64 near 5.0 check 3 tolerance " +
                tolerance,
            "run 120 post no"});
    return std::vector<double>{l.var("f_fmm[7]"), l.var("f_fmm[8]"), l.var("f_fmm[9]"),
                               l.var("f_fmm[10]")};
  };
  const auto loose = run("1e-4"), tight = run("1e-12");
  std::printf("[ tolerance ] 1e-4: checked %.3g, stride %g, last estimate %.3g, %g evaluations "
              "in 120 steps; 1e-12: stride %g, %g evaluations\n",
              loose[0], loose[1], loose[2], loose[3], tight[1], tight[3]);
  EXPECT_GT(loose[1], 2.0);
  EXPECT_LT(loose[3], 60.0);
  // the estimate is the error at the end of an interval, where it is largest: the checks,
  // taken anywhere inside intervals, stay below the tolerance
  EXPECT_LE(loose[0], 1e-4);
  EXPECT_GT(loose[0], 0.0);
  EXPECT_LE(loose[2], 1e-4);
  EXPECT_EQ(tight[1], 1.0);
  EXPECT_GE(tight[3], 110.0);
}

// the adapted interval is part of the state: a run split anywhere evaluates on the same steps
// as the uninterrupted one (to round-off), and so does one continued from a restart file in a
// new instance (there the near pairs are summed in another order: round-off grows over the
// steps after the restart, ~1e-12 after 31 steps with a fixed every too, hence 1e-10 after 10).
// A final run 0 wraps every copy the same way before positions are compared.
TEST(CoulFMM, ToleranceScheduleIndependentOfRunSplit)
{
  const std::string fix = "fix fmm all coul/fmm accuracy 1e-6 every 32 near 6.0 tolerance 1e-4";
  std::vector<double> straight, split, restarted;
  double evaluations = 0.0;
  {
    Lmp l;
    moving_charges(l);
    l.cmds({fix, "run 40 post no", "run 0 post no"});
    straight = gather(l, "x", 3);
    evaluations = l.var("f_fmm[10]");
  }
  {
    Lmp l;
    moving_charges(l);
    l.cmds({fix, "run 17 post no", "run 13 post no", "write_restart coul_fmm_tol.restart",
            "run 10 post no", "run 0 post no"});
    split = gather(l, "x", 3);
    EXPECT_EQ(l.var("f_fmm[10]"), evaluations);
  }
  restarted = continued_from("coul_fmm_tol.restart", fix, 10);
  std::remove("coul_fmm_tol.restart");
  EXPECT_LT(rel_rms(split, straight), 1e-14);
  EXPECT_LT(rel_rms(restarted, straight), 1e-10);
}

// a restart file written within a run (the restart command, here at step 30) continues the
// schedule as one written between runs: the positions at which the field was last applied,
// which a continued run checks its atoms against, are those of the step the file is written on
// (tolerance as above: the near pairs are summed in another order after the restart). Started
// afresh, the continued run would evaluate at once and adapt its interval again from 1.
TEST(CoulFMM, RestartWrittenWithinARunContinuesTheSchedule)
{
  const std::string fix = "fix fmm all coul/fmm accuracy 1e-6 every 32 near 6.0 tolerance 1e-4";
  std::vector<double> straight, restarted;
  {
    Lmp l;
    moving_charges(l);
    l.cmds({fix, "restart 30 coul_fmm_within.restart", "run 40 post no", "run 0 post no"});
    straight = gather(l, "x", 3);
  }
  restarted = continued_from("coul_fmm_within.restart.30", fix, 10);
  std::remove("coul_fmm_within.restart.30");
  EXPECT_LT(rel_rms(restarted, straight), 1e-10);
}

// charges created between two runs (the deposition deck's one-by-one insertion) are a known
// change: the next run's first step evaluates them with the others, as fix deposit's insertion
// within a run is, and the adapted interval and the other atoms' slopes go on. Started again,
// the schedule would fall back to an interval of 1 after every insertion. The forces right
// after an insertion are those of a fresh evaluation (same solver settings, so to round-off),
// and the checked error of the steps after it stays within the tolerance. Heavy atoms and
// 1e-10 as in ToleranceAdaptsTheInterval (the charges depend on the number of ranks).
TEST(CoulFMM, ToleranceScheduleGoesOnOverChargesAddedBetweenRuns)
{
  const std::string solver = "accuracy 1e-10 order 30";
  Lmp l;
  moving_charges(l);
  l.cmds({"mass 1 100000.0",
          "fix fmm all coul/fmm " + solver + " every 64 near 5.0 check 3 tolerance 1e-4",
          "run 60 post no"});
  const double interval = l.var("f_fmm[8]"), evaluations = l.var("f_fmm[10]");
  ASSERT_GT(interval, 1.0);
  l.cmds({"create_atoms 1 single 10.3 9.7 36.0", "set atom 201 charge 1.0", "run 0 post no"});
  ASSERT_EQ(l.var("count(all)"), 201.0);
  EXPECT_EQ(l.var("f_fmm[8]"), interval);
  EXPECT_EQ(l.var("f_fmm[10]"), evaluations + 1.0);    // the insertion's step, evaluated
  l.cmd("run 40 post no");
  std::printf("[ added between runs ] interval %g before, %g 40 steps after; checked error %.3g\n",
              interval, l.var("f_fmm[8]"), l.var("f_fmm[7]"));
  EXPECT_GT(l.var("f_fmm[8]"), 1.0);
  EXPECT_LE(l.var("f_fmm[7]"), 1e-4);
  EXPECT_GT(l.var("f_fmm[7]"), 0.0);
  l.cmds({"create_atoms 1 single 4.1 15.2 36.0", "set atom 202 charge -1.0", "run 0 post no"});
  const double energy = l.var("f_fmm");
  const auto forces = forces_by_id(l, 202);
  l.cmds({"unfix fmm", "fix fresh all coul/fmm " + solver, "run 0 post no"});
  const double fresh_energy = l.var("f_fresh");
  const auto fresh = forces_by_id(l, 202);
  std::printf("[ added between runs ] energy %.12g vs fresh %.12g, forces %.3g\n", energy,
              fresh_energy, rel_rms(forces, fresh));
  EXPECT_NEAR(energy, fresh_energy, 1e-10 * std::fabs(fresh_energy));
  EXPECT_LT(rel_rms(forces, fresh), 1e-10);
}

// farfield average with a net-charged layer: the reported energy is the one whose gradient is
// the applied force (the smeared far images act as an external field, so no 1/2 for their
// part); central differences of the fix energy against the force on one atom in x and z
TEST(CoulFMM, AverageFarFieldEnergyMatchesForces)
{
  Lmp l;
  random_charges(l, "p p f", 100, 20.0, 40.0, 71);
  l.cmds({"set group all charge 1.0", "group one id 7",
          "fix fmm all coul/fmm accuracy 1e-10 order 30 farfield average bed 0 40",
          "fix_modify fmm energy yes", "run 0 post no"});
  const double fx = l.var("fx[7]"), fz = l.var("fz[7]");
  const double h = 1e-4;    // A: central-difference error ~h^2 |F'''|, far below 1e-6 |F|
  auto energy_at = [&](double dx, double dz) {
    l.cmd(fmt::format("displace_atoms one move {} 0 {} units box", dx, dz));
    l.cmd("run 0 post no");
    const double e = l.var("f_fmm");
    l.cmd(fmt::format("displace_atoms one move {} 0 {} units box", -dx, -dz));
    return e;
  };
  const double dEdx = (energy_at(h, 0) - energy_at(-h, 0)) / (2 * h);
  const double dEdz = (energy_at(0, h) - energy_at(0, -h)) / (2 * h);
  const double scale = std::hypot(fx, fz);
  std::printf("[ average energy ] fx %.8g vs -dE/dx %.8g, fz %.8g vs -dE/dz %.8g\n", fx, -dEdx,
              fz, -dEdz);
  // round-off of the energy differences (~1e-12 |E| / h) and the FMM at 1e-10: 1e-5 of |F|
  EXPECT_NEAR(-dEdx, fx, 1e-5 * scale);
  EXPECT_NEAR(-dEdz, fz, 1e-5 * scale);
}
