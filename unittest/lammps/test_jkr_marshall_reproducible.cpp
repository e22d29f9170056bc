/* GRANULAR-CHARGED: the JKR/Marshall sub-models keep their contact history through neighbor
   rebuilds, newton on/off, restarts in the middle of loaded contacts, and MPI migration.
   A loaded adhesive cluster (27 spheres on a compressed cubic lattice, 162 live JKR contacts,
   random velocities, neighbor lists rebuilt every 50 steps so the history is transferred
   again and again) is run several ways; the state must agree to round-off. (Aggregation from
   free flight is not used: the JKR snap-in is a force jump, so after a few hundred steps a
   round-off difference flips the step at which some contact forms and trajectories diverge
   physically, as they do between any two orderings of the sums.) Run with 1 rank (newton, restart) and under mpirun -np 2
   (2 ranks vs 1 rank on MPI_COMM_SELF). */
#include "gc_testing.h"

#include "gtest/gtest.h"

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

using gctest::Lmp;
using gctest::nprocs;

namespace {
constexpr int NATOMS = 27;

std::vector<std::string> cluster_commands(const std::string &newton)
{
  return {"units si", "atom_style sphere", "atom_modify map array", "boundary p p p",
          "newton " + newton, "comm_modify vel yes", "lattice sc 1.99e-6",
          "region box block 0 3 0 3 0 3", "create_box 1 box", "create_atoms 1 box",
          "set type 1 diameter 2e-6", "set type 1 density 2500", "pair_style granular",
          "pair_coeff * * jkr/marshall 2e8 0.7 0.33 0.01 damping marshall tangential marshall "
          "0.3 rolling marshall 0.01 twisting marshall/jkr",
          "neighbor 1e-8 bin", "neigh_modify every 50 delay 0 check no",
          "velocity all create 1e7 87287 loop geom", "fix integrate all nve/sphere",
          "timestep 2e-10", "compute om all property/atom omegax", "compute contacts all contact/atom", "compute nc all reduce sum c_contacts",
          "thermo 0"};
}

void cluster(Lmp &l, const std::string &newton)
{
  l.cmds(cluster_commands(newton));
}

std::vector<double> state(Lmp &l)
{
  std::vector<double> s;
  for (int i = 1; i <= NATOMS; ++i)
    for (const char *q : {"x", "y", "z", "vx", "C_om"}) s.push_back(l.var(fmt::format("{}[{}]", q, i)));
  return s;
}

// positions ~1e-5 m, velocities ~0.1 m/s, spins ~1e5 rad/s: compare each relative to its scale
void expect_same(const std::vector<double> &a, const std::vector<double> &b, double rel)
{
  ASSERT_EQ(a.size(), b.size());
  const double scale[5] = {1e-5, 1e-5, 1e-5, 0.1, 1e5};
  for (size_t k = 0; k < a.size(); ++k)
    EXPECT_NEAR(a[k], b[k], rel * scale[k % 5]) << "component " << k;
}

}    // namespace

// 1e-9 of each quantity's scale is far above double round-off after 4000 steps and far below
// any physical change (a lost or wrongly transferred history term changes the state by ~1e-3
// of its scale).
constexpr double TOL = 1e-9;

TEST(JKRMarshallReproducible, NewtonOnOff)
{
  if (nprocs() > 1) GTEST_SKIP() << "single-rank test";
  std::vector<double> s_off, s_on;
  {
    Lmp l;
    cluster(l, "off");
    l.cmd("run 4000");
    EXPECT_EQ(l.var("c_nc"), 162.0) << "every lattice contact stays alive";
    s_off = state(l);
  }
  {
    Lmp l;
    cluster(l, "on");
    l.cmd("run 4000");
    s_on = state(l);
  }
  expect_same(s_off, s_on, TOL);
}

// Both runs are separate lmp processes, as a user's are: LAMMPS 4Jul2026 names pair granular's
// history fix after a per-process instance counter, and read_restart restores the history only
// into a fix of the same name, i.e. only if the reading process has created as many pair
// granular instances before as the writing one (a test process running several LAMMPS
// instances has not).
namespace {
std::vector<double> lmp_process(const std::vector<std::string> &lines, const std::string &tag)
{
  bool ok;
  auto s = gctest::lmp_process(GC_LMP_EXECUTABLE, lines, "jkr_marshall_" + tag, &ok);
  if (!ok) ADD_FAILURE() << "lmp run " << tag << " failed";
  return s;
}
}    // namespace

TEST(JKRMarshallReproducible, RestartInLoadedContacts)
{
  if (nprocs() > 1) GTEST_SKIP() << "single-rank test";
  const std::string file = "jkr_marshall_cluster.restart";
  auto writer = cluster_commands("off");
  writer.insert(writer.end(), {"run 2000", "if \"$(c_nc) != 162\" then \"quit 3\"",
                               "write_restart " + file, "run 2000"});
  const auto straight = lmp_process(writer, "straight");
  // LAMMPS (4Feb2025 and 4Jul2026) does not store pair granular's global cutoff flag in the
  // restart (PairGranular::cutoff_global stays uninitialised after read_restart and the pair
  // cutoff becomes 0: no ghosts, contacts lost). Re-issuing "pair_style granular" keeps the
  // restored coefficients and contact history and sets the flag again.
  const auto restarted = lmp_process({"read_restart " + file, "pair_style granular",
                                      "comm_modify vel yes", "neighbor 1e-8 bin",
                                      "neigh_modify every 50 delay 0 check no",
                                      "fix integrate all nve/sphere", "run 2000"},
                                     "restarted");
  std::remove(file.c_str());
  ASSERT_EQ(straight.size(), 5u * NATOMS);
  expect_same(straight, restarted, TOL);
}

TEST(JKRMarshallReproducible, OneVersusTwoRanks)
{
  if (nprocs() != 2) GTEST_SKIP() << "needs mpirun -np 2";
  std::vector<double> two;
  {
    Lmp l(MPI_COMM_WORLD);
    cluster(l, "off");
    l.cmd("run 4000");
    two = state(l);
  }
  int me;
  MPI_Comm_rank(MPI_COMM_WORLD, &me);
  std::vector<double> one(two.size());
  if (me == 0) {
    Lmp l(MPI_COMM_SELF);
    cluster(l, "off");
    l.cmd("run 4000");
    one = state(l);
  }
  MPI_Bcast(one.data(), (int) one.size(), MPI_DOUBLE, 0, MPI_COMM_WORLD);
  expect_same(one, two, TOL);
}
