/* GRANULAR-CHARGED: the Marshall contacts in SIMD lanes (marshall_lanes.h) against the scalar
   instantiation of the same kernel, on every instruction-set path the machine has (a path the
   CPU lacks is skipped with a message; the portable path always runs).

   Random contacts cover every decision of the kernel: loading and tension down to -delta_C
   (root s = 1), a fresh contact (zero history), sliding in stick and in slip, slip with no
   spring (zero history, no update), a history out of the tangent plane (rotated) and in it,
   rolling below and at its cap, twisting in stick and slip, rolling and twisting defined or
   not, a fixed body on either side, mixed radii, surface energies and damping conventions, and
   history_update on and off.

   Tolerance: none. The lanes perform the scalar kernel's IEEE operations (+ - * / sqrt, exact
   in every lane) in the same order, with no fused multiply-add on either side (this file and
   marshall_lanes.cpp are compiled with -ffp-contract=off), so forces, torques and histories
   must be equal bit for bit. Checked: scaling the tangential stiffness of lane 3 by
   (1 + 1e-15) in the lanes kernel (the body every path compiles) fails
   SameBitsAsScalarOnEveryPath. GenericPathSameRunAsDefault compares two paths with each other
   in a LAMMPS run (the bed with GCSIMD_MAX_PATH=generic and with the default path: the same dump
   of positions, velocities, forces and torques to the last digit).
*/
#include "marshall_lanes.h"

#include "gcsimd/simd.hpp"
#include "jkr_scaled.h"
#include "marshall_kernels.h"

#include "gtest/gtest.h"

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace MK = LAMMPS_NS::MarshallKernels;
namespace ML = LAMMPS_NS::MarshallLanes;
using gcsimd::SimdPath;

struct ContactSet {
  std::vector<std::vector<double>> inputs;    // one N_INPUT array per contact
};

double uniform(std::mt19937_64 &rng, double lo, double hi)
{
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

// a random unit vector
void direction(std::mt19937_64 &rng, double *n)
{
  double len = 0.0;
  do {
    for (int k = 0; k < 3; k++) n[k] = uniform(rng, -1.0, 1.0);
    len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  } while (len < 0.1 || len > 1.0);
  for (int k = 0; k < 3; k++) n[k] /= len;
}

// contact number `c` of the set: its category is c modulo a few primes, so that every
// combination of the decisions occurs
std::vector<double> random_contact(std::mt19937_64 &rng, int c)
{
  std::vector<double> in(ML::N_INPUT, 0.0);
  // a contact with a wall (fix wall/gran/opt) is one with a fixed partner of radius 0 at rest
  const bool wall = c % 29 == 7;
  const double radi = uniform(rng, 1.0e-6, 3.0e-6), radj_drawn = uniform(rng, 1.0e-6, 3.0e-6);
  const double radj = wall ? 0.0 : radj_drawn;
  const double reff = wall ? radi : MK::effective_radius(radi, radj);
  const double gamma = (c % 2) ? 0.01 : 0.05, emix = (c % 3) ? 1.1e8 : 3.0e8;
  const MK::JKRScales sc = MK::jkr_scales(reff, gamma, emix);
  // overlap: tension down to exactly -delta_C, around zero, loading to a few delta_C
  double delta;
  switch (c % 5) {
    case 0: delta = -sc.deltac; break;
    case 1: delta = uniform(rng, -1.0, 0.0) * sc.deltac; break;
    case 2: delta = 0.0; break;
    default: delta = uniform(rng, 0.0, 6.0) * sc.deltac; break;
  }
  double n[3];
  direction(rng, n);
  const double r = radi + radj - delta;
  for (int k = 0; k < 3; k++) in[ML::DX + k] = r * n[k];
  // relative motion from still to 1 m/s, spins up to 1e6 rad/s
  const double vscale = (c % 7 == 0) ? 0.0 : std::pow(10.0, uniform(rng, -4.0, 0.0));
  const double wscale = (c % 11 == 0) ? 0.0 : std::pow(10.0, uniform(rng, 2.0, 6.0));
  for (int k = 0; k < 3; k++) {
    in[ML::VR + k] = vscale * uniform(rng, -1.0, 1.0);
    in[ML::OMEGA_I + k] = wscale * uniform(rng, -1.0, 1.0);
    in[ML::OMEGA_J + k] = wscale * uniform(rng, -1.0, 1.0);
    if (wall) in[ML::OMEGA_J + k] = 0.0;
  }
  in[ML::RAD_I] = radi;
  in[ML::RAD_J] = radj;
  in[ML::REFF] = reff;
  in[ML::ROOT] = LAMMPS_NS::JKRScaled::root(MK::scaled_overlap(sc, delta));
  in[ML::ASEP] = sc.asep;
  in[ML::FC] = sc.fc;
  in[ML::SQRT_KN_SEP] = sc.sqrt_kn_sep;
  in[ML::MASS_FACTOR] = (c % 2) ? 2.0 : 1.0;
  const double mass = 2500.0 * 4.0 / 3.0 * 3.141592653589793;
  in[ML::MASS_I] = mass * radi * radi * radi;
  in[ML::MASS_J] = mass * radj * radj * radj;
  in[ML::FIXED] = (c % 13 == 1) ? ML::FIXED_I : (c % 13 == 2) ? ML::FIXED_J : ML::FIXED_NONE;
  if (wall) in[ML::FIXED] = ML::FIXED_J;
  in[ML::LEVER_SHIFT] = wall ? ML::LEVER_SHIFT_WALL : ML::LEVER_SHIFT_PAIR;
  in[ML::ALPHA] = MK::damping_alpha(uniform(rng, 0.1, 0.9));
  in[ML::K_T] = 8.0 * emix / 2.6;
  in[ML::MU] = uniform(rng, 0.1, 0.5);
  in[ML::DT] = 6.1e-9;
  const bool rolling = c % 4 != 3, twisting = c % 3 != 2;
  in[ML::ROLLING] = rolling ? 1.0 : 0.0;
  in[ML::TWISTING] = twisting ? 1.0 : 0.0;
  in[ML::XI_CRIT] = rolling ? 0.01 * reff : 0.0;
  in[ML::HERTZ] = 0.0;
  in[ML::EMIX] = emix;
  // histories: zero (a fresh contact), small (stick), large (slip, rolling cap); in the tangent
  // plane or out of it
  const double hscale = (c % 17 < 4) ? 0.0 : std::pow(10.0, uniform(rng, -14.0, -6.0));
  double h[3];
  direction(rng, h);
  if (c % 19 < 6) {    // in the plane
    const double hn = h[0] * n[0] + h[1] * n[1] + h[2] * n[2];
    for (int k = 0; k < 3; k++) h[k] -= hn * n[k];
  }
  for (int k = 0; k < 3; k++) {
    in[ML::HIST_T + k] = hscale * h[k];
    in[ML::HIST_R + k] = rolling ? 3.0 * hscale * h[(k + 1) % 3] : 0.0;
  }
  in[ML::HIST_TW] = twisting ? uniform(rng, -1.0, 1.0) * ((c % 23 < 5) ? 0.0 : 1e-2) : 0.0;
  return in;
}

ContactSet contacts(int n)
{
  std::mt19937_64 rng(20261204);
  ContactSet set;
  for (int c = 0; c < n; c++) set.inputs.push_back(random_contact(rng, c));
  return set;
}

std::uint64_t bits(double x)
{
  std::uint64_t b;
  std::memcpy(&b, &x, sizeof b);
  return b;
}

const char *OUTPUT_NAMES[ML::N_OUTPUT] = {"fx", "fy", "fz", "tix", "tiy", "tiz", "tjx", "tjy",
                                          "tjz", "htx", "hty", "htz", "hrx", "hry", "hrz", "htw"};

void expect_same_as_scalar(SimdPath path, bool history_update)
{
  constexpr int W = ML::WIDTH;
  const int nblocks = 97;    // 776 contacts
  const ContactSet set = contacts(nblocks * W);
  std::vector<double> in(nblocks * ML::N_INPUT * W), out(nblocks * ML::N_OUTPUT * W, -1.0);
  for (int c = 0; c < nblocks * W; c++)
    for (int q = 0; q < ML::N_INPUT; q++)
      in[(c / W * ML::N_INPUT + q) * W + c % W] = set.inputs[c][q];
  ML::contacts_in_lanes(nblocks, in.data(), out.data(), history_update, path);

  int differences = 0;
  for (int c = 0; c < nblocks * W; c++) {
    double scalar[ML::N_OUTPUT];
    ML::marshall_contact(set.inputs[c].data(), scalar, history_update);
    for (int q = 0; q < ML::N_OUTPUT; q++) {
      const double lane = out[(c / W * ML::N_OUTPUT + q) * W + c % W];
      ASSERT_TRUE(std::isfinite(scalar[q])) << "contact " << c << " " << OUTPUT_NAMES[q];
      if (bits(lane) != bits(scalar[q]) && differences++ < 10)
        ADD_FAILURE() << gcsimd::simd_path_name(path) << ", history_update " << history_update
                      << ": contact " << c << " (lane " << c % W << ") " << OUTPUT_NAMES[q]
                      << " lanes " << lane << " scalar " << scalar[q];
    }
  }
  EXPECT_EQ(differences, 0);
}

TEST(MarshallLanes, SameBitsAsScalarOnEveryPath)
{
  for (SimdPath path : {SimdPath::Generic, SimdPath::AVX2, SimdPath::AVX512}) {
    if (!gcsimd::simd_path_available(path)) {
      std::printf("[  SKIPPED ] path %s: not available on this CPU or build\n",
                  gcsimd::simd_path_name(path));
      continue;
    }
    SCOPED_TRACE(gcsimd::simd_path_name(path));
    expect_same_as_scalar(path, true);
    expect_same_as_scalar(path, false);
  }
}

// The torque's lever arm (GranularModel::calculate_forces, dist_to_contact): R - delta / 2 on
// each particle of a pair, R at a wall. Without rolling and twisting both torques are the
// sliding torque t = -(n x F_t) times a lever arm, so torque_i (R_j - delta / 2) and
// torque_j (R_i - delta / 2) are t times the same two factors, and the same contact packed as a
// wall contact has torque_i R_i / (R_i - delta / 2) of the pair's. Tolerance 1e-14 relative:
// each side is t rounded by two multiplications (a few units of 2.2e-16); a wrong lever arm is
// off by delta / (2 R), here ~1e-3.
TEST(MarshallLanes, LeverArmOfPairAndWall)
{
  std::mt19937_64 rng(20261206);
  int checked = 0;
  for (int c = 0; c < 200; c++) {
    std::vector<double> in = random_contact(rng, c);
    if (in[ML::RAD_J] == 0.0) continue;    // a wall contact of the set
    in[ML::ROLLING] = in[ML::TWISTING] = 0.0;
    const double *dx = &in[ML::DX];
    const double delta = in[ML::RAD_I] + in[ML::RAD_J] -
        std::sqrt(dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2]);
    const double lever_i = in[ML::RAD_I] - 0.5 * delta, lever_j = in[ML::RAD_J] - 0.5 * delta;
    double pair[ML::N_OUTPUT], wall[ML::N_OUTPUT];
    ML::marshall_contact(in.data(), pair, true);
    in[ML::LEVER_SHIFT] = ML::LEVER_SHIFT_WALL;
    ML::marshall_contact(in.data(), wall, true);
    for (int k = 0; k < 3; k++) {
      const double ti = pair[ML::TORQUE_I + k], tj = pair[ML::TORQUE_J + k];
      if (ti == 0.0) continue;
      EXPECT_NEAR(ti * lever_j, tj * lever_i, 1e-14 * std::fabs(ti * lever_j))
          << "pair, contact " << c;
      EXPECT_NEAR(wall[ML::TORQUE_I + k] * lever_i, ti * in[ML::RAD_I],
                  1e-14 * std::fabs(ti * in[ML::RAD_I]))
          << "wall, contact " << c;
      EXPECT_EQ(wall[ML::FORCE + k], pair[ML::FORCE + k]) << "the lever arm moves no force";
      checked++;
    }
  }
  EXPECT_GT(checked, 300);
}

// the contacts cover the decisions they are meant to: counted with the scalar kernel's inputs
TEST(MarshallLanes, ContactsCoverEveryBranch)
{
  const ContactSet set = contacts(97 * ML::WIDTH);
  int separating = 0, tension = 0, loading = 0, fresh = 0, out_of_plane = 0, tangential_slip = 0,
      tangential_stick = 0, rolling_capped = 0, rolling_free = 0, twisting_slip = 0,
      twisting_stick = 0, fixed = 0, no_rolling = 0, no_twisting = 0;
  for (const auto &in : set.inputs) {
    const double s = in[ML::ROOT];
    separating += s == 1.0;
    const double delta = in[ML::RAD_I] + in[ML::RAD_J] -
        std::sqrt(MK::lensq3(&in[ML::DX]));
    tension += delta < 0.0 && s > 1.0;
    loading += delta > 0.0;
    fresh += MK::lensq3(&in[ML::HIST_T]) == 0.0;
    out_of_plane += std::fabs(MK::dot3(&in[ML::HIST_T], &in[ML::DX])) > 0.0;
    double out[ML::N_OUTPUT];
    ML::marshall_contact(in.data(), out, true);
    // a slip resets the spring: |F_t| = mu F_crit; a stick keeps h + v_t dt (changes less)
    const MK::NormalForce nf = MK::jkr_normal_force_of_root(in[ML::ASEP], in[ML::FC],
                                                            in[ML::SQRT_KN_SEP], s);
    const double fscrit = MK::critical_force(nf) * in[ML::MU];
    double fn_free[3], ft[3];
    const double r = std::sqrt(MK::lensq3(&in[ML::DX]));
    for (int k = 0; k < 3; k++) fn_free[k] = in[ML::DX + k] / r;
    const double fn = MK::dot3(&out[ML::FORCE], fn_free);
    for (int k = 0; k < 3; k++) ft[k] = out[ML::FORCE + k] - fn * fn_free[k];
    const double ft_len = std::sqrt(MK::lensq3(ft));
    if (std::fabs(ft_len - fscrit) <= 1e-6 * fscrit)
      tangential_slip++;
    else if (ft_len < fscrit)
      tangential_stick++;
    if (in[ML::ROLLING] != 0.0) {
      const double xi = std::sqrt(MK::lensq3(&out[ML::OUT_HIST_R]));
      if (std::fabs(xi - in[ML::XI_CRIT]) <= 1e-12 * in[ML::XI_CRIT])
        rolling_capped++;
      else
        rolling_free++;
    } else {
      no_rolling++;
    }
    if (in[ML::TWISTING] != 0.0) {
      // stick: phi advanced by omega_T dt exactly; slip: reset to another value
      double relrot[3];
      for (int k = 0; k < 3; k++) relrot[k] = in[ML::OMEGA_I + k] - in[ML::OMEGA_J + k];
      double nx[3];
      for (int k = 0; k < 3; k++) nx[k] = (1.0 / r) * in[ML::DX + k];
      const double advanced = in[ML::HIST_TW] + MK::dot3(relrot, nx) * in[ML::DT];
      if (out[ML::OUT_HIST_TW] == advanced)
        twisting_stick++;
      else
        twisting_slip++;
    } else {
      no_twisting++;
    }
    fixed += in[ML::FIXED] != ML::FIXED_NONE;
  }
  for (auto [name, count] :
       {std::pair<const char *, int>{"separating (s = 1)", separating}, {"tension", tension},
        {"loading", loading}, {"fresh", fresh}, {"history out of plane", out_of_plane},
        {"tangential slip", tangential_slip}, {"tangential stick", tangential_stick},
        {"rolling capped", rolling_capped}, {"rolling free", rolling_free},
        {"twisting slip", twisting_slip}, {"twisting stick", twisting_stick},
        {"fixed body", fixed}, {"no rolling", no_rolling}, {"no twisting", no_twisting}})
    EXPECT_GE(count, 10) << name;
}

#ifdef GC_LMP_EXECUTABLE
// the settled paper-size bed run on with granular/opt: the dump of GCSIMD_MAX_PATH=generic is that
// of the default path, to the last digit
std::string run_bed(const std::string &simd, const std::string &tag)
{
  const std::string dir = std::string(GC_SOURCE_DIR);
  // the dumps go to a folder of their own, never into the working directory
  std::string scratch_template =
      (std::filesystem::temp_directory_path() / "gc_lanes_bed_XXXXXX").string();
  if (!mkdtemp(scratch_template.data())) return "";
  const std::string scratch = scratch_template;
  const std::string input = scratch + "/bed.dump";
  const std::string dump = scratch + "/forces_" + tag + ".dump";
  const std::string bed = dir + "/doc/data/paper-size/runs/rp2um_U1_g10mJ_q0_N2000_s1";
  if (std::system(("zcat " + bed + "/final.dump.gz > " + input).c_str()) != 0) return "";
  std::ifstream f(input);
  std::string line, step;
  std::getline(f, line);
  std::getline(f, step);
  const std::string cmd = (simd.empty() ? std::string("env -u GCSIMD_MAX_PATH -u GCFMM_SIMD ")
                                        : "env GCSIMD_MAX_PATH=" + simd + " ") +
      GC_LMP_EXECUTABLE + " -log none -echo none -screen none -nocite -in " + dir +
      "/bench/kernels/in.bed -var dump " + input + " -var step " + step +
      " -var steps 200 -var pair granular/opt -var forces " + dump;
  if (std::system(cmd.c_str()) != 0) return "";
  std::ifstream d(dump);
  std::stringstream all;
  all << d.rdbuf();
  d.close();
  std::filesystem::remove_all(scratch);
  return all.str();
}

TEST(MarshallLanes, GenericPathSameRunAsDefault)
{
  const std::string generic = run_bed("generic", "generic");
  const std::string best = run_bed("", "default");
  ASSERT_FALSE(generic.empty()) << "the bed run with GCSIMD_MAX_PATH=generic failed";
  ASSERT_FALSE(best.empty()) << "the bed run on the default path failed";
  EXPECT_TRUE(generic == best) << "the generic and the default path wrote different dumps";
}
#endif

}    // namespace
