/* GRANULAR-CHARGED: granular/opt's contact list, kept between neighbor-list builds, against
   pair_style granular step by step (forces and torques of every atom at every step):
   - a colliding cluster rebuilt every 10 steps only (neigh_modify every 10 check no), whose
     contacts form and break between builds (checked from the contact count at steps without a
     build), and whose list follows the builds (one rebuild per build, none in between);
   - radii changed between builds (fix adapt of the diameter every step);
   - radii and types changed by set between runs without a new set-up (run pre no);
   - the time step changed at every step (fix dt/reset).
   Tolerance as in test_granular_opt.cpp (1e-12 of each quantity's scale; bit for bit in
   practice). Checked by breaking the list's rebuild: a list kept from the set-up on fails
   ContactsMadeAndBrokenBetweenBuilds on the forces (from step 70) besides the rebuild count;
   radii not compared fail RadiiChangedBetweenBuilds and SetBetweenRunsWithoutSetup, types not
   compared SetBetweenRunsWithoutSetup, lanes kept across a change of time step
   TimeStepChangedBetweenBuilds. */
#include "gc_testing.h"

#include "force.h"
#include "neighbor.h"
#include "pair_granular_opt.h"

#include "gtest/gtest.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

using gctest::Lmp;
using LAMMPS_NS::bigint;

namespace {
constexpr int NATOMS = 27;
constexpr double TOL = 1e-12;
constexpr int EVERY = 10;    // neighbor-list builds every EVERY steps

const char *MARSHALL = "jkr/marshall 2e8 0.7 0.33 0.01 damping marshall tangential marshall "
                       "0.3 rolling marshall 0.01 twisting marshall/jkr";

// 27 spheres on a lattice whose gaps exceed the neighbor skin (the first list holds no pair),
// with random velocities of ~20 m/s and spins: pairs enter and leave the neighbor list from one
// build to the next, contacts form on impact, load, slip and break, many between two builds
std::vector<std::string> colliding(const std::string &pair_style, const std::string &newton,
                                   const std::string &atom_style = "sphere")
{
  return {"units si", "atom_style " + atom_style, "atom_modify map array", "boundary p p p",
          "newton " + newton, "comm_modify vel yes", "lattice sc 2.3e-6",
          "region box block 0 3 0 3 0 3", "create_box 2 box",
          "create_atoms 1 box", "set group all type/fraction 2 0.3 1234",
          "set group all diameter 1.999e-6", "set group all density 2500",
          "pair_style " + pair_style, std::string("pair_coeff * * ") + MARSHALL,
          "neighbor 2e-7 bin", "neigh_modify every " + std::to_string(EVERY) +
          " delay 0 check no", "velocity all create 3e11 4928 loop geom",
          "set group all omega 1e5 -2e5 3e5", "fix integrate all nve/sphere", "timestep 2e-10",
          "compute contacts all contact/atom", "compute nc all reduce sum c_contacts",
          "thermo 0"};
}

// every component of f and torque of every atom at every step, and the contact count of every
// step (from c_nc), from record() on
struct Recording {
  std::vector<double> forces, contacts;
};

std::string dump_file(const std::string &tag) { return "granular_opt_list_" + tag + ".dump"; }
std::string counts_file(const std::string &tag) { return "granular_opt_list_" + tag + ".nc"; }

void record(Lmp &l, const std::string &tag)
{
  l.cmd("dump f all custom 1 " + dump_file(tag) + " id fx fy fz tqx tqy tqz");
  l.cmd("dump_modify f sort id format float %.17g");
  l.cmd("variable nc equal c_nc");
  l.cmd("fix nc all print 1 \"${nc}\" file " + counts_file(tag) + " screen no");
}

Recording recorded(Lmp &l, const std::string &tag)
{
  const std::string dump = dump_file(tag), counts = counts_file(tag);
  l.cmd("undump f");
  l.cmd("unfix nc");
  Recording r;
  if (gctest::rank() == 0) {
    r.forces = gctest::dump_rows(dump, 6);
    FILE *fp = fopen(counts.c_str(), "r");
    char line[512];
    while (fp && fgets(line, sizeof line, fp)) {
      double c;
      if (line[0] != '#' && sscanf(line, "%lg", &c) == 1) r.contacts.push_back(c);
    }
    if (fp) fclose(fp);
    std::remove(dump.c_str());
    std::remove(counts.c_str());
  }
  for (std::vector<double> *s : {&r.forces, &r.contacts}) {
    int n = (int) s->size();
    MPI_Bcast(&n, 1, MPI_INT, 0, MPI_COMM_WORLD);
    s->resize(n);
    MPI_Bcast(s->data(), n, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  }
  return r;
}

void expect_same_forces(const std::vector<double> &a, const std::vector<double> &b)
{
  gctest::expect_same_forces(a, b, TOL, NATOMS);
}

LAMMPS_NS::PairGranularOpt *opt_pair(Lmp &l)
{
  return dynamic_cast<LAMMPS_NS::PairGranularOpt *>(l.lmp->force->pair);
}
}    // namespace

TEST(GranularOptContactList, ContactsMadeAndBrokenBetweenBuilds)
{
  constexpr int STEPS = 400;
  for (const std::string newton : {"on", "off"}) {
    SCOPED_TRACE("newton " + newton);
    Recording runs[2];
    bigint builds = 0, rebuilds = 0;
    int k = 0;
    for (const std::string style : {"granular", "granular/opt"}) {
      Lmp l;
      l.cmds(colliding(style, newton));
      const std::string tag = (style == "granular" ? "ref" : "opt") + newton;
      record(l, tag);
      l.cmd("run " + std::to_string(STEPS));
      runs[k] = recorded(l, tag);
      if (k == 1) {
        builds = l.lmp->neighbor->ncalls;    // the run's builds after its set-up
        rebuilds = opt_pair(l)->contact_list_rebuilds();
      }
      k++;
    }
    // the contacts change between builds, so a list of the last build's contacts would miss
    // some: count the steps, not after a build, whose count differs from the step before
    const std::vector<double> &nc = runs[0].contacts;
    ASSERT_EQ(nc.size(), static_cast<size_t>(STEPS + 1));
    int changes = 0;
    for (size_t s = 1; s < nc.size(); ++s)
      if (s % EVERY != 0 && nc[s] != nc[s - 1]) ++changes;
    EXPECT_GE(changes, 5) << "contacts made or broken between builds";
    EXPECT_GT(*std::max_element(nc.begin(), nc.end()), 10.0);
    expect_same_forces(runs[0].forces, runs[1].forces);
    // the list follows the neighbor list: built with it (and at the set-up), kept between builds
    EXPECT_EQ(builds, STEPS / EVERY);
    EXPECT_EQ(rebuilds, builds + 1);
  }
}

// fix adapt grows every atom each step: R_eff, the scales and the contact distance of the list
// change between builds
TEST(GranularOptContactList, RadiiChangedBetweenBuilds)
{
  Recording runs[2];
  int k = 0;
  for (const std::string style : {"granular", "granular/opt"}) {
    Lmp l;
    l.cmds(colliding(style, "off", "sphere 1"));    // radii that may change
    l.cmds({"variable dia equal 1.999e-6*(1.0+2.0e-4*step)",
            "fix grow all adapt 1 atom diameter v_dia reset no"});
    const std::string tag = "adapt" + std::to_string(k);
    record(l, tag);
    l.cmd("run 200");
    runs[k] = recorded(l, tag);
    k++;
  }
  expect_same_forces(runs[0].forces, runs[1].forces);
}

// radii, then types changed by set between runs, the later ones without a set-up (run pre no:
// no neighbor-list build and no init before their first step)
TEST(GranularOptContactList, SetBetweenRunsWithoutSetup)
{
  Recording runs[2];
  int k = 0;
  for (const std::string style : {"granular", "granular/opt"}) {
    Lmp l;
    l.cmds(colliding(style, "on"));
    l.cmds({"pair_coeff 2 2 jkr/marshall 3e8 0.5 0.3 0.015 damping marshall/printed "
            "tangential marshall 0.4 rolling marshall/particle 0.02"});
    // recorded from the start: a dump or fix added before a run without set-up is not set up
    const std::string tag = "set" + std::to_string(k);
    record(l, tag);
    l.cmds({"run 105", "set atom 1*10 diameter 2.004e-6", "run 2 pre no",
            "set atom 11*13 type 2", "run 2 pre no"});
    runs[k] = recorded(l, tag);
    k++;
  }
  expect_same_forces(runs[0].forces, runs[1].forces);
}

// fix dt/reset changes the time step at every step, with no neighbor-list build: the lanes'
// model inputs kept from the step before must follow it
TEST(GranularOptContactList, TimeStepChangedBetweenBuilds)
{
  Recording runs[2];
  int k = 0;
  for (const std::string style : {"granular", "granular/opt"}) {
    Lmp l;
    l.cmds(colliding(style, "on"));
    l.cmd("fix dtr all dt/reset 1 5e-11 4e-10 1e-8 units box");
    const std::string tag = "dt" + std::to_string(k);
    record(l, tag);
    l.cmd("run 300");
    runs[k] = recorded(l, tag);
    k++;
  }
  expect_same_forces(runs[0].forces, runs[1].forces);
}
