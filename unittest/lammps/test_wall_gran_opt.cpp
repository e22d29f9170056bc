/* GRANULAR-CHARGED: fix wall/gran/opt (the fused flat wall of the Marshall set) against fix
   wall/gran granular with the same sub-models: forces and torques of every atom at every step
   and the wall's contact history (touch flag, sliding, rolling and twisting values) of every
   atom, bit for bit, for spheres of two sizes that bounce on the floor (contacts that form,
   load, unload into tension and break beyond -delta_C), stick to it, slide on it, roll and
   twist on it; three sub-model variants, newton on and off, 1 and 2 ranks, a wall on the y axis
   with both planes, a restart written in a contact and read back with the other style, the
   fallback to wall/gran's own path (another model, a wiggling wall, the contacts output) and
   the selection by the opt suffix.

   Bit for bit: the fused loop performs the same floating-point operations in the same order as
   GranularModel::check_contact() and calculate_forces() with the Marshall sub-models (both call
   marshall_kernels.h, and the wall's zero velocity, spin and radius enter the same arithmetic),
   so exact equality is expected and asserted.

   Checked by changing one factor of the fused loop by 1e-6 at a time: the normal damping
   force, the sliding limit, the twisting limit, the rolling limit and the torque's lever arm
   each fail SameAsWallGranMarshallSet, SameAsWallGranYPlanes and RestartAcrossStyles (the
   rolling limit also RunReachesTheLimits). */
#include "gc_testing.h"

#include "fix_wall_gran.h"
#include "fix_wall_gran_opt.h"
#include "modify.h"

#include "gtest/gtest.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

using gctest::Lmp;
using gctest::nprocs;

namespace {

constexpr int NX = 5, NY = 4, NATOMS = NX * NY;
constexpr double RP1 = 1.0e-6, RP2 = 1.1e-6;    // radii of types 1 and 2
constexpr double SPACING = 2.6e-6;

// the deck's set; marshall/printed + marshall/particle without twisting; no adhesion, no
// rolling (Hertz's branch of jkr_normal_force)
const char *MARSHALL_FULL = "jkr/marshall 2e8 0.7 0.33 0.01 damping marshall tangential marshall "
                            "0.3 rolling marshall 0.01 twisting marshall/jkr";
const char *MARSHALL_PRINTED = "jkr/marshall 3e8 0.5 0.3 0.015 damping marshall/printed "
                               "tangential marshall 0.4 rolling marshall/particle 0.02";
const char *MARSHALL_NO_ADHESION = "jkr/marshall 2e8 0.6 0.33 0.0 damping marshall tangential "
                                   "marshall 0.3 twisting marshall/jkr";
const char *HERTZ = "hertz/material 2e8 0.5 0.33 damping tsuji tangential mindlin NULL 1.0 0.3 "
                    "rolling sds 1e3 1e2 0.1 twisting marshall";

// a reproducible uniform number in [lo, hi) (same on every rank and platform)
struct Lcg {
  uint64_t s = 88172645463325252ULL;
  double operator()(double lo, double hi)
  {
    s = s * 6364136223846793005ULL + 1442695040888963407ULL;
    return lo + (hi - lo) * (double) (s >> 11) / 9007199254740992.0;
  }
};

// 20 spheres on a grid above the floor z = 0 (or beside the wall y = 0 for axis 1), in four
// kinds: incoming ones that bounce (and leave in tension beyond -delta_C) or stick, ones
// pressed in and pulled away (held in tension or torn off), ones pressed in with a sliding
// speed, ones pressed in with spin (rolling and twisting)
std::vector<std::string> spheres(const std::string &wall_style, const std::string &wall_model,
                                 const std::string &newton, int axis = 2,
                                 const std::string &wall_args = "0.0 NULL",
                                 const std::string &extra = "")
{
  const int n = axis;                   // the wall's normal
  const int a = (axis + 1) % 3;         // the grid's axes
  const int b = (axis + 2) % 3;
  const char *plane[3] = {"xplane", "yplane", "zplane"};
  const char *bnd[3] = {"f p p", "p f p", "p p f"};
  // ranks side by side along the wall, each with wall contacts
  const char *procs[3] = {"1 * *", "* 1 *", "* * 1"};
  double hi[3];
  hi[a] = NX * SPACING;
  hi[b] = NY * SPACING;
  hi[n] = 20.0e-6;
  std::vector<std::string> c = {
      "units si", "atom_style sphere", "atom_modify map array", std::string("boundary ") + bnd[n],
      "newton " + newton, "comm_modify vel yes", std::string("processors ") + procs[n],
      fmt::format("region box block 0 {} 0 {} 0 {}", hi[0], hi[1], hi[2]), "create_box 2 box"};
  Lcg u;
  for (int k = 0; k < NATOMS; ++k) {
    const int type = (k % 3 == 0) ? 2 : 1;
    const double rp = type == 2 ? RP2 : RP1;
    double x[3], v[3] = {0, 0, 0}, w[3] = {0, 0, 0};
    x[a] = ((k % NX) + 0.5) * SPACING + u(-0.1, 0.1) * rp;
    x[b] = ((k / NX) + 0.5) * SPACING + u(-0.1, 0.1) * rp;
    switch (k % 4) {
      case 0:    // bounce, or stick when slow
        x[n] = rp + u(0.02, 0.15) * 1e-6;
        v[n] = -u(0.05, 2.5);
        v[a] = u(-0.1, 0.1);
        v[b] = u(-0.1, 0.1);
        for (double &wd : w) wd = u(-1e5, 1e5);
        break;
      case 1:    // pulled away from the wall: held in tension, or torn off beyond -delta_C
        x[n] = rp - u(0.5, 2.0) * 1e-9;
        v[n] = u(0.05, 0.5);
        v[a] = u(-0.02, 0.02);
        for (double &wd : w) wd = u(-2e4, 2e4);
        break;
      case 2:    // slide
        x[n] = rp - u(0.5, 2.0) * 1e-9;
        v[a] = u(0.3, 0.8);
        v[b] = u(-0.2, 0.2);
        break;
      default:    // roll and twist
        x[n] = rp - u(0.5, 2.0) * 1e-9;
        w[a] = u(-5e5, 5e5);
        w[b] = u(-5e5, 5e5);
        w[n] = u(-1e6, 1e6);
        break;
    }
    c.push_back(fmt::format("create_atoms {} single {:.17g} {:.17g} {:.17g} units box", type,
                            x[0], x[1], x[2]));
    c.push_back(fmt::format("set atom {} vx {:.17g} vy {:.17g} vz {:.17g} omega {:.17g} {:.17g} {:.17g}",
                            k + 1, v[0], v[1], v[2], w[0], w[1], w[2]));
  }
  c.insert(c.end(),
           {fmt::format("set type 1 diameter {}", 2 * RP1),
            fmt::format("set type 2 diameter {}", 2 * RP2), "set group all density 2500",
            "pair_style granular", std::string("pair_coeff * * ") + MARSHALL_FULL,
            "fix floor all " + wall_style + " granular " + wall_model + " " + plane[n] + " " +
                wall_args + (extra.empty() ? "" : " " + extra),
            "neighbor 2e-7 bin", "neigh_modify every 1 delay 0 check yes",
            "fix integrate all nve/sphere", "timestep 2e-9", "thermo 0"});
  return c;
}

// FixWallGran's history through a pointer to member named in a derived class
struct WallPeek : LAMMPS_NS::FixWallGran {
  static double **history(LAMMPS_NS::FixWallGran *f) { return f->*(&WallPeek::history_one); }
  static int size(LAMMPS_NS::FixWallGran *f) { return f->*(&WallPeek::size_history); }
};

LAMMPS_NS::FixWallGran *wall(Lmp &l)
{
  return dynamic_cast<LAMMPS_NS::FixWallGran *>(l.lmp->modify->get_fix_by_id("floor"));
}

// the wall's history of every atom, ordered by atom ID (every rank gets all of it)
std::vector<double> wall_history(Lmp &l)
{
  auto *fix = wall(l);
  const int nh = WallPeek::size(fix);
  double **h = WallPeek::history(fix);
  auto *atom = l.lmp->atom;
  std::vector<double> mine;
  for (int i = 0; i < atom->nlocal; ++i) {
    mine.push_back((double) atom->tag[i]);
    for (int k = 0; k < nh; ++k) mine.push_back(h[i][k]);
  }
  int nmine = (int) mine.size(), np = nprocs();
  std::vector<int> counts(np), displs(np, 0);
  MPI_Allgather(&nmine, 1, MPI_INT, counts.data(), 1, MPI_INT, MPI_COMM_WORLD);
  for (int p = 1; p < np; ++p) displs[p] = displs[p - 1] + counts[p - 1];
  std::vector<double> all(displs[np - 1] + counts[np - 1]);
  MPI_Allgatherv(mine.data(), nmine, MPI_DOUBLE, all.data(), counts.data(), displs.data(),
                 MPI_DOUBLE, MPI_COMM_WORLD);
  std::vector<double> sorted((size_t) NATOMS * nh, 0.0);
  for (size_t r = 0; r < all.size(); r += nh + 1) {
    const int id = (int) all[r];
    std::copy(all.begin() + r + 1, all.begin() + r + 1 + nh, sorted.begin() + (size_t) (id - 1) * nh);
  }
  return sorted;
}

// fx fy fz tqx tqy tqz z of every atom after each of `steps` steps (from a dump, every rank)
std::vector<double> dump_run(Lmp &l, int steps, const std::string &tag)
{
  const std::string dump = "wall_gran_opt_" + tag + ".dump";
  l.cmd("dump f all custom 1 " + dump + " id fx fy fz tqx tqy tqz x y z");
  l.cmd("dump_modify f sort id format float %.17g");
  l.cmd("run " + std::to_string(steps));
  l.cmd("undump f");
  std::vector<double> s;
  if (gctest::rank() == 0) {
    FILE *fp = fopen(dump.c_str(), "r");
    char line[1024];
    while (fp && fgets(line, sizeof line, fp)) {
      int id;
      double v[9];
      if (sscanf(line, "%d %lg %lg %lg %lg %lg %lg %lg %lg %lg", &id, v, v + 1, v + 2, v + 3,
                 v + 4, v + 5, v + 6, v + 7, v + 8) == 10)
        s.insert(s.end(), v, v + 9);
    }
    if (fp) fclose(fp);
    std::remove(dump.c_str());
  }
  int n = (int) s.size();
  MPI_Bcast(&n, 1, MPI_INT, 0, MPI_COMM_WORLD);
  s.resize(n);
  MPI_Bcast(s.data(), n, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  return s;
}

// what one style does: the dump of every step, and the history every 20 steps
struct Record {
  std::vector<double> dump, history;
  bool fused = false;
  // summed over the samples: overlapping the wall, touching it in tension (touch flag set, no
  // overlap) and contacts that ended since the last sample (touch flag reset)
  int overlapping = 0, tension = 0, ended = 0;
};

Record record(const std::vector<std::string> &setup, const std::string &tag, int axis = 2,
              int steps = 600)
{
  Record r;
  Lmp l;
  l.cmds(setup);
  int nlocal_min = l.lmp->atom->nlocal;
  MPI_Allreduce(MPI_IN_PLACE, &nlocal_min, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  EXPECT_GT(nlocal_min, 0) << "every rank has atoms at the wall";
  const int nh = WallPeek::size(wall(l));
  const bool beyond_contact = wall(l)->model->beyond_contact;    // history[0]: touch flag
  std::vector<double> last;
  for (int done = 0; done < steps; done += 20) {
    const auto d = dump_run(l, 20, tag);
    r.dump.insert(r.dump.end(), d.begin(), d.end());
    const auto h = wall_history(l);
    r.history.insert(r.history.end(), h.begin(), h.end());
    // the kinds of contact the run went through (the last dumped step is the current one)
    const size_t base = d.size() - 9 * (size_t) NATOMS;
    for (int i = 0; i < NATOMS; ++i) {
      const double rp = (i % 3 == 0) ? RP2 : RP1;
      const double dist = d[base + 9 * i + 6 + axis];
      if (dist < rp) ++r.overlapping;
      if (!beyond_contact) continue;
      if (h[(size_t) i * nh] != 0.0) {
        if (dist > rp) ++r.tension;
      } else if (!last.empty() && last[(size_t) i * nh] != 0.0) {
        ++r.ended;
      }
    }
    last = h;
  }
  auto *opt = dynamic_cast<LAMMPS_NS::FixWallGranOpt *>(wall(l));
  r.fused = opt && opt->is_fused();
  return r;
}

// exact equality of two records' values (NaN fails too)
void expect_identical(const std::vector<double> &a, const std::vector<double> &b, int per_record,
                      const char *what)
{
  ASSERT_EQ(a.size(), b.size()) << what;
  ASSERT_GT(a.size(), 0u) << what;
  int bad = 0;
  for (size_t k = 0; k < a.size() && bad < 10; ++k)
    if (!(a[k] == b[k])) {
      ++bad;
      ADD_FAILURE() << what << ": value " << k % per_record << " of record " << k / per_record
                    << ": " << a[k] << " vs " << b[k];
    }
}

void expect_same_run(const Record &ref, const Record &opt)
{
  expect_identical(ref.dump, opt.dump, 9, "forces, torques, positions");
  expect_identical(ref.history, opt.history, 1, "wall history");
}

}    // namespace

// the deck's set and two variants, newton on and off (on 2 ranks under mpirun)
TEST(FixWallGranOpt, SameAsWallGranMarshallSet)
{
  for (const char *model : {MARSHALL_FULL, MARSHALL_PRINTED, MARSHALL_NO_ADHESION}) {
    for (const std::string newton : {"on", "off"}) {
      SCOPED_TRACE(std::string(model) + ", newton " + newton);
      const Record ref = record(spheres("wall/gran", model, newton), "ref");
      const Record opt = record(spheres("wall/gran/opt", model, newton), "opt");
      EXPECT_FALSE(ref.fused);
      EXPECT_TRUE(opt.fused);
      // the run has wall contacts, contacts in tension and contacts that end
      EXPECT_GT(ref.overlapping, 20);
      if (model != MARSHALL_NO_ADHESION) EXPECT_GT(ref.tension, 0);
      EXPECT_GT(ref.ended, 0);
      expect_same_run(ref, opt);
    }
  }
}

// the rolling limit is reached in this run (else the test would not see a wrong one):
// |xi| = theta_crit r_p
TEST(FixWallGranOpt, RunReachesTheLimits)
{
  const Record opt = record(spheres("wall/gran/opt", MARSHALL_FULL, "on"), "limits");
  ASSERT_TRUE(opt.fused);
  // history: touch, sliding (3), rolling (3), twisting (1)
  constexpr int NH = 8;
  int capped = 0;
  for (size_t r = 0; r + NH <= opt.history.size(); r += NH) {
    const double xi = std::sqrt(opt.history[r + 4] * opt.history[r + 4] +
                                opt.history[r + 5] * opt.history[r + 5] +
                                opt.history[r + 6] * opt.history[r + 6]);
    const int id = (int) ((r / NH) % NATOMS) + 1;
    const double rp = ((id - 1) % 3 == 0) ? RP2 : RP1;
    if (std::fabs(xi - 0.01 * rp) <= 1e-12 * 0.01 * rp) ++capped;
  }
  EXPECT_GT(capped, 0) << "the rolling limit theta_crit r_p is reached";
}

// a wall on the y axis with both planes (the lower one touched)
TEST(FixWallGranOpt, SameAsWallGranYPlanes)
{
  const Record ref = record(spheres("wall/gran", MARSHALL_FULL, "off", 1, "0.0 20.0e-6"), "yref", 1);
  const Record opt = record(spheres("wall/gran/opt", MARSHALL_FULL, "off", 1, "0.0 20.0e-6"), "yopt", 1);
  EXPECT_TRUE(opt.fused);
  EXPECT_GT(ref.overlapping, 100);
  expect_same_run(ref, opt);
}

// everything the fused loop does not cover runs wall/gran's own code: the same results
TEST(FixWallGranOpt, FallbackIsWallGran)
{
  struct Case {
    const char *name, *model, *extra;
  };
  for (const Case &c : {Case{"hertz/material", HERTZ, ""},
                        Case{"wiggle", MARSHALL_FULL, "wiggle z 2e-8 2e-7"},
                        Case{"contacts output", MARSHALL_FULL, "contacts"}}) {
    SCOPED_TRACE(c.name);
    const Record ref = record(spheres("wall/gran", c.model, "on", 2, "0.0 NULL", c.extra), "fbref", 2, 200);
    const Record opt = record(spheres("wall/gran/opt", c.model, "on", 2, "0.0 NULL", c.extra), "fbopt", 2, 200);
    EXPECT_FALSE(opt.fused);
    EXPECT_GT(ref.overlapping, 5);
    expect_same_run(ref, opt);
  }
}

// suffix opt picks the variant for fix wall/gran, as -sf opt does
TEST(FixWallGranOpt, SuffixSelectsIt)
{
  Lmp l;
  auto setup = spheres("wall/gran", MARSHALL_FULL, "on");
  setup.insert(setup.begin(), "suffix opt");
  l.cmds(setup);
  EXPECT_NE(dynamic_cast<LAMMPS_NS::FixWallGranOpt *>(wall(l)), nullptr);
  l.cmds({"suffix off", "unfix floor",
          std::string("fix floor all wall/gran granular ") + MARSHALL_FULL + " zplane 0.0 NULL"});
  EXPECT_EQ(dynamic_cast<LAMMPS_NS::FixWallGranOpt *>(wall(l)), nullptr);
  EXPECT_NE(wall(l), nullptr);
}

// a restart written in the middle of the wall contacts by one style and read by the other:
// the history arrives unchanged, and the continued run is the same as with the writer's style
TEST(FixWallGranOpt, RestartAcrossStyles)
{
  const std::string file = "wall_gran_opt_" + std::to_string(nprocs()) + ".restart";
  for (const std::string writer : {"wall/gran", "wall/gran/opt"}) {
    SCOPED_TRACE("written by " + writer);
    std::vector<double> written, x;
    int touching = 0, tension = 0;
    {
      Lmp l;
      l.cmds(spheres(writer, MARSHALL_FULL, "off"));
      // contacts in the restart: touching ones, some of them in tension (the first such step
      // after step 10; the same for both writers)
      l.cmd("run 10");
      for (int chunk = 0; chunk < 100; ++chunk) {
        l.cmd("run 1");
        written = wall_history(l);
        x = gctest::gather(l, "x", 3);
        touching = tension = 0;
        for (int i = 0; i < NATOMS; ++i) {
          const double rp = (i % 3 == 0) ? RP2 : RP1;
          if (written[(size_t) i * 8] == 0.0) continue;
          ++touching;
          if (x[3 * i + 2] > rp) ++tension;
        }
        if (tension > 0) break;
      }
      l.cmd("write_restart " + file);
    }
    EXPECT_GT(touching, 5);
    EXPECT_GT(tension, 0);

    std::vector<double> after[2];
    int k = 0;
    for (const std::string reader : {"wall/gran", "wall/gran/opt"}) {
      SCOPED_TRACE("read by " + reader);
      Lmp l;
      l.cmds({"processors * * 1", "read_restart " + file, "pair_style granular",
              std::string("pair_coeff * * ") + MARSHALL_FULL, "comm_modify vel yes",
              "fix floor all " + reader + " granular " + MARSHALL_FULL + " zplane 0.0 NULL"});
      expect_identical(written, wall_history(l), 1, "history read back");
      l.cmds({"neighbor 2e-7 bin", "neigh_modify every 1 delay 0 check yes",
              "fix integrate all nve/sphere", "timestep 2e-9", "thermo 0"});
      after[k] = dump_run(l, 300, "restart");
      const auto h = wall_history(l);
      after[k].insert(after[k].end(), h.begin(), h.end());
      ++k;
    }
    expect_identical(after[0], after[1], 9, "run after the restart");
  }
  if (gctest::rank() == 0) std::remove(file.c_str());
}
