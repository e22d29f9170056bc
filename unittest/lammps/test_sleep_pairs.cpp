/* GRANULAR-CHARGED: fix sleep/gran ... pairs awake, the pairs of two sleepers left out of
   pair_style granular/opt (doc/fix_sleep_gran.rst, keyword pairs).

   The deck (that of test_sleep_styles.cpp): a touching bed of 108 spheres on a JKR floor falls
   asleep at the first commit; 40 spheres rain on it at ~1 m/s, come to rest on it and fall
   asleep at later commits (the sleeping set changes during the run). Two instances run side by
   side, step by step: A with pairs all, B with pairs awake; on 1 and 2 ranks, newton off and on.

   - AwakeAtomsAsWithAllPairs (wake threshold 1 N: no sleeper wakes): at every step every atom's
     position, velocity, spin, force, torque and sleeping flag are the same in A and B, bit for
     bit: a pair of two sleepers only acts on atoms whose force and torque are zeroed after the
     forces, and the forces of an awake atom are summed over the same contacts in the same
     order. At every step B's pair computed exactly the contacts not between two sleepers
     (contacts_computed() against the count of this test, per rank, from the flags of the step's
     start and the contacts, whose flags are checked against the overlaps) and A's every contact;
     the history and contact flag of each pair B left out are those it had before the step, byte
     for byte.
   - GenericPathAsWithAllPairs: the same with a model outside the fused set (tangential
     mindlin), whose pairs granular/opt hands to PairGranular::compute on a list of its own.
   - WokenPairGoesOnFromItsHistory (wake threshold 1e-7 N: the rain wakes sleepers): the same
     comparison, with B's history of each pair it left out copied into A after the step, and
     A's atoms woken on the step held (velocity, spin, force, torque zeroed) as pairs awake
     holds them on their wake step, whose contacts with sleepers it did not compute. Then A and
     B must stay the same, bit for bit, also after wakes: B differs from pairs all only through
     the histories of the pairs it left out and the step a woken atom is held, and a woken pair
     goes on from the history it had when it was last computed (one reset or recomputed fails
     the comparison). The run wakes sleepers, and pairs all changes the histories of many
     sleepers' pairs (so the copy is needed; counted).
   - ErrorsNameKeywordAndStyle: pairs awake with pair_style granular, and a bad value.

   Checked against broken code (each on 1 rank): with the pairs of one sleeper left out too
   (asleep[i] || asleep[j] in build_contact_list) both side-by-side tests fail at step 101, the
   first after the bed's commit (84 contacts computed against the 120 counted; atom 73 vx
   1.01e-15 against 2.34e-15 m/s); with the contact list not built again when the sleeping set
   changes (the generation left out of its stamp: stale flags) both fail at step 101 (324
   computed against 120, the histories of pairs of two sleepers changed); with the histories of
   the pairs left out zeroed, both fail at step 101 (histories changed); with a woken atom not
   held on its wake step, WokenPairGoesOnFromItsHistory fails at step 265 (atom 68 vz = -g dt / 2:
   gravity alone, its contacts with sleepers not computed on that step); with a model outside
   the fused set run by PairGranular::compute on the whole list (the sleepers' pairs included),
   GenericPathAsWithAllPairs fails at step 1 (0 contacts counted by the pair against 324). */
#include "gc_testing.h"

#include "atom.h"
#include "fix.h"
#include "fix_neigh_history.h"
#include "force.h"
#include "modify.h"
#include "neigh_list.h"
#include "pair_granular_opt.h"

#include "gtest/gtest.h"
#include "library.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <string>
#include <utility>
#include <vector>

using gctest::Lmp;
using gctest::nprocs;
using gctest::rank;
using LAMMPS_NS::bigint;
using LAMMPS_NS::tagint;

namespace {
const char *MODEL = "jkr/marshall 2e8 0.7 0.33 0.01 damping marshall tangential marshall 0.3 "
                    "rolling marshall 0.01 twisting marshall/jkr";
// outside the fused set (tangential mindlin): granular/opt runs PairGranular::compute on its
// generic list
const char *GENERIC = "jkr/marshall 2e8 0.7 0.33 0.01 damping marshall tangential mindlin NULL 1.0 0.3";
constexpr double A = 1.995e-6;    // lattice spacing, below the diameter: neighbours touch
constexpr int NBED = 6 * 6 * 3, NRAIN = 40;
constexpr int NSTEPS = 2400;      // the rain lands from step ~400 to ~2000
constexpr double RADSUM = 2.0e-6;
// the JKR separation distance delta_C of two of these spheres (gctest::JKR: E* = E / (2 (1 -
// nu^2)), R = 0.5 um): a contact flag may be set up to this far apart, not farther
const double DELTA_C = gctest::JKR{0.5e-6, 2e8 / (2.0 * (1.0 - 0.33 * 0.33)), 0.01}.deltaC();

// the deck with `pairs` all or awake and wake threshold `wake` (N)
std::vector<std::string> deck(const std::string &newton, const std::string &pairs, double wake,
                              const std::string &model)
{
  return {"units si", "atom_style sphere", "atom_modify map array sort 0 0", "boundary p p f",
          "newton " + newton, fmt::format("lattice sc {}", A), "region box block 0 6 0 6 -1 20",
          "create_box 1 box", "region cells block 0 5.5 0 5.5 0 2", "create_atoms 1 region cells",
          "group bed region cells", "region above block EDGE EDGE EDGE EDGE 7.0e-6 16e-6 units box",
          fmt::format("create_atoms 1 random {} 4711 above overlap 2.2e-6 maxtry 1000 units box",
                      NRAIN),
          "set group all diameter 2.0e-6", "set group all density 2500",
          "group rain subtract all bed", "velocity rain create 1e7 77 loop geom",
          "velocity rain set NULL NULL -1.0 sum yes units box", "pair_style granular/opt",
          "pair_coeff * * " + model,
          "fix floor all wall/gran/opt granular " + model + " zplane -0.999e-6 NULL",
          "comm_modify vel yes", "neighbor 2e-7 bin", "neigh_modify every 1 delay 0 check yes",
          "fix integrate all nve/sphere", "fix grav all gravity 9.81 vector 0 0 -1",
          "timestep 5e-9", "thermo 0",
          fmt::format("fix sleep all sleep/gran speed 0.05 force 1e-7 wake {} time 0 every 100 "
                      "pairs {}",
                      wake, pairs)};
}

// x v omega f torque and the sleeping flag of every atom, by ID
std::vector<double> state(Lmp &l)
{
  const int n = static_cast<int>(l.lmp->atom->natoms);
  std::vector<double> s;
  for (const char *name : {"x", "v", "omega", "f", "torque"}) {
    std::vector<double> q(3 * n);
    lammps_gather_atoms(l.lmp, (char *) name, 1, 3, q.data());
    s.insert(s.end(), q.begin(), q.end());
  }
  std::vector<double> asleep(n);
  lammps_gather(l.lmp, "f_sleep", 1, 1, asleep.data());
  s.insert(s.end(), asleep.begin(), asleep.end());
  return s;
}

std::string first_difference(const std::vector<double> &a, const std::vector<double> &b, int n)
{
  static const char *QUANTITY[] = {"x", "v", "omega", "f", "torque"};
  if (a.size() != b.size()) return fmt::format("{} values against {}", a.size(), b.size());
  for (size_t k = 0; k < a.size(); k++) {
    if (a[k] == b[k]) continue;
    if (k >= static_cast<size_t>(15 * n))
      return fmt::format("atom {} sleeping flag {} against {}", k - 15 * n + 1, a[k], b[k]);
    return fmt::format("atom {} {}[{}]: {:.17g} against {:.17g}", (k % (3 * n)) / 3 + 1,
                       QUANTITY[k / (3 * n)], k % 3, a[k], b[k]);
  }
  return "";
}

// the sleeping flag of every atom, by ID (index ID - 1)
std::vector<double> flags_by_id(Lmp &l)
{
  std::vector<double> asleep(static_cast<size_t>(l.lmp->atom->natoms));
  lammps_gather(l.lmp, "f_sleep", 1, 1, asleep.data());
  return asleep;
}

LAMMPS_NS::FixNeighHistory *history_of(Lmp &l)
{
  auto fixes = l.lmp->modify->get_fix_by_style("^NEIGH_HISTORY");
  return fixes.size() == 1 ? dynamic_cast<LAMMPS_NS::FixNeighHistory *>(fixes.front()) : nullptr;
}

// one pair of this rank's list: its IDs as listed, its contact flag and history values
using PairKey = std::pair<tagint, tagint>;
struct PairRecord {
  int touch;
  std::vector<double> history;
};

// calls visit(i, j, touch, history) for each pair of the pair style's list on this rank
template <typename Visit> void each_pair(Lmp &l, Visit visit)
{
  auto *hist = history_of(l);
  ASSERT_NE(hist, nullptr);
  const auto *list = l.lmp->force->pair->list;
  const int dnum = hist->get_dnum();
  for (int ii = 0; ii < list->inum; ii++) {
    const int i = list->ilist[ii];
    for (int jj = 0; jj < list->numneigh[i]; jj++) {
      const int j = list->firstneigh[i][jj] & NEIGHMASK;
      visit(i, j, &hist->firstflag[i][jj], &hist->firstvalue[i][dnum * jj], dnum);
    }
  }
}

// the pairs of two sleepers (by the flags `asleep` by ID) on this rank, with their flags and
// histories: those pairs awake leaves out
std::map<PairKey, PairRecord> sleeper_pairs(Lmp &l, const std::vector<double> &asleep)
{
  std::map<PairKey, PairRecord> pairs;
  const tagint *tag = l.lmp->atom->tag;
  each_pair(l, [&](int i, int j, int *touch, double *history, int dnum) {
    if (asleep[tag[i] - 1] == 0.0 || asleep[tag[j] - 1] == 0.0) return;
    pairs[{tag[i], tag[j]}] = {*touch, std::vector<double>(history, history + dnum)};
  });
  return pairs;
}

// after a step: the contacts this rank computed (flag set, at least one atom awake by the flags
// `asleep` of the step's start) and those of two sleepers; every flag checked against the
// overlap (set when the spheres overlap, never farther apart than delta_C)
struct Contacts {
  bigint computed = 0, of_sleepers = 0;
};
Contacts count_contacts(Lmp &l, const std::vector<double> &asleep, int step)
{
  Contacts c;
  const tagint *tag = l.lmp->atom->tag;
  double **x = l.lmp->atom->x;
  int bad = 0;
  each_pair(l, [&](int i, int j, int *touch, double *, int) {
    const double dx = x[i][0] - x[j][0], dy = x[i][1] - x[j][1], dz = x[i][2] - x[j][2];
    const double d = std::sqrt(dx * dx + dy * dy + dz * dz);
    const bool overlap = d < RADSUM;
    // delta_C (~9e-10 m) with a margin of 1e-3 of it for the rounding of d (~1e-21 m)
    const bool flag_possible = d < RADSUM + 1.001 * DELTA_C;
    if ((overlap && !*touch) || (*touch && !flag_possible)) {
      if (bad++ < 5)
        ADD_FAILURE() << "step " << step << ": pair " << tag[i] << "-" << tag[j] << " flag "
                      << *touch << " at distance " << d << " (sum of radii " << RADSUM << ")";
    }
    if (!*touch) return;
    if (asleep[tag[i] - 1] != 0.0 && asleep[tag[j] - 1] != 0.0)
      c.of_sleepers++;
    else
      c.computed++;
  });
  return c;
}

bigint contacts_computed(Lmp &l)
{
  auto *pair = dynamic_cast<LAMMPS_NS::PairGranularOpt *>(l.lmp->force->pair);
  return pair ? pair->contacts_computed() : -1;
}

// what a side-by-side run found (summed over the steps, this rank's pairs)
struct Findings {
  bigint sleeper_contacts = 0;     // contacts of two sleepers left out by B
  bigint frozen_compared = 0;      // histories of pairs left out compared before and after
  bigint changed_by_all = 0;       // pairs left out by B whose history A changed
  double fallen = 0.0, woken = 0.0;
};

// A (pairs all) and B (pairs awake) side by side, step by step; with copy_history, B's flag and
// history of each pair it left out are copied into A after the step
Findings side_by_side(const std::string &newton, double wake, bool copy_history,
                      const std::string &model = MODEL)
{
  Lmp a, b;
  a.cmds(deck(newton, "all", wake, model));
  b.cmds(deck(newton, "awake", wake, model));
  Findings found;
  const int n = static_cast<int>(a.lmp->atom->natoms);
  for (int step = 1; step <= NSTEPS; step++) {
    const std::vector<double> asleep = flags_by_id(b);    // the flags B's pair reads this step
    // (no list before the first run)
    const auto before = step > 1 ? sleeper_pairs(b, asleep) : std::map<PairKey, PairRecord>();
    const char *run = step == 1 ? "run 1" : "run 1 pre no post no";
    a.cmd(run);
    b.cmd(run);

    // B's pair left out exactly the contacts of two sleepers; A's computed all
    const Contacts cb = count_contacts(b, asleep, step);
    EXPECT_EQ(contacts_computed(b), cb.computed) << "step " << step << ": pairs awake";
    // (with no model fused, pairs all runs PairGranular::compute alone, which counts nothing)
    if (model == MODEL)
      EXPECT_EQ(contacts_computed(a), cb.computed + cb.of_sleepers) << "step " << step
                                                                    << ": pairs all";
    found.sleeper_contacts += cb.of_sleepers;

    // the pairs B left out: flag and history as before the step, byte for byte
    const auto after = sleeper_pairs(b, asleep);
    int changed = 0;
    for (const auto &[key, rec] : before) {
      auto it = after.find(key);
      if (it == after.end()) continue;    // listed the other way round after a build
      found.frozen_compared++;
      const bool same = it->second.touch == rec.touch &&
          std::memcmp(it->second.history.data(), rec.history.data(),
                      rec.history.size() * sizeof(double)) == 0;
      if (!same && changed++ < 5)
        ADD_FAILURE() << "step " << step << ": pair " << key.first << "-" << key.second
                      << " left out, its history changed";
    }
    // every rank stops together (the runs are collective)
    int any_changed = 0;
    MPI_Allreduce(&changed, &any_changed, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    if (any_changed) return found;

    // A's pairs B left out: history changed by pairs all; copied from B when asked
    if (copy_history) {
      const tagint *tag = a.lmp->atom->tag;
      std::vector<std::pair<int *, double *>> of_a;
      each_pair(a, [&](int i, int j, int *touch, double *history, int) {
        if (asleep[tag[i] - 1] != 0.0 && asleep[tag[j] - 1] != 0.0)
          of_a.emplace_back(touch, history);
      });
      size_t k = 0;
      const int dnum = history_of(b)->get_dnum();
      const tagint *tagb = b.lmp->atom->tag;
      each_pair(b, [&](int i, int j, int *touch, double *history, int) {
        if (asleep[tagb[i] - 1] == 0.0 || asleep[tagb[j] - 1] == 0.0) return;
        ASSERT_LT(k, of_a.size()) << "the lists of A and B differ";
        auto [touch_a, history_a] = of_a[k++];
        if (std::memcmp(history_a, history, dnum * sizeof(double)) != 0) found.changed_by_all++;
        *touch_a = *touch;
        std::memcpy(history_a, history, dnum * sizeof(double));
      });
      EXPECT_EQ(k, of_a.size()) << "the lists of A and B differ";
      // the atoms woken on this step: held on it with pairs awake, so held in A too
      const std::vector<double> now = flags_by_id(a);
      auto *atom = a.lmp->atom;
      for (int i = 0; i < atom->nlocal; i++) {
        if (asleep[atom->tag[i] - 1] == 0.0 || now[atom->tag[i] - 1] != 0.0) continue;
        for (double **q : {atom->v, atom->omega, atom->f, atom->torque})
          q[i][0] = q[i][1] = q[i][2] = 0.0;
      }
    }

    // the gathered states are the same on every rank: every rank stops together
    const std::string diff = first_difference(state(b), state(a), n);
    EXPECT_EQ(diff, "") << "step " << step << ", newton " << newton
                        << ": pairs awake against pairs all";
    if (!diff.empty()) return found;
  }
  found.fallen = b.var("f_sleep[3]");
  found.woken = b.var("f_sleep[4]");
  // sums over the ranks
  for (bigint *v : {&found.sleeper_contacts, &found.frozen_compared, &found.changed_by_all}) {
    bigint all = 0;
    MPI_Allreduce(v, &all, 1, MPI_LMP_BIGINT, MPI_SUM, MPI_COMM_WORLD);
    *v = all;
  }
  if (rank() == 0)
    std::printf("[ newton %s, wake %g ] %g fell asleep, %g woken; %lld sleeper contacts left "
                "out, %lld histories compared, %lld changed by pairs all\n",
                newton.c_str(), wake, found.fallen, found.woken,
                static_cast<long long>(found.sleeper_contacts),
                static_cast<long long>(found.frozen_compared),
                static_cast<long long>(found.changed_by_all));
  return found;
}
}    // namespace

TEST(SleepPairs, AwakeAtomsAsWithAllPairs)
{
  for (const std::string newton : {"off", "on"}) {
    const Findings f = side_by_side(newton, 1.0, false);
    EXPECT_EQ(f.woken, 0.0) << "newton " << newton << ": nothing wakes";
    EXPECT_GE(f.fallen, NBED + 20.0) << "newton " << newton << ": the rain falls asleep too";
    EXPECT_GT(f.sleeper_contacts, 0) << "newton " << newton << ": contacts left out";
    EXPECT_GT(f.frozen_compared, 0) << "newton " << newton;
  }
}

// the same with a model outside the fused set: the pairs of two sleepers left out of the list
// PairGranular::compute runs on
TEST(SleepPairs, GenericPathAsWithAllPairs)
{
  for (const std::string newton : {"off", "on"}) {
    const Findings f = side_by_side(newton, 1.0, false, GENERIC);
    EXPECT_EQ(f.woken, 0.0) << "newton " << newton << ": nothing wakes";
    EXPECT_GE(f.fallen, NBED + 5.0) << "newton " << newton << ": some of the rain falls asleep";
    EXPECT_GT(f.sleeper_contacts, 0) << "newton " << newton << ": contacts left out";
  }
}

TEST(SleepPairs, WokenPairGoesOnFromItsHistory)
{
  for (const std::string newton : {"off", "on"}) {
    const Findings f = side_by_side(newton, 1e-7, true);
    EXPECT_GE(f.woken, 5.0) << "newton " << newton << ": the rain wakes sleepers";
    EXPECT_GE(f.fallen, NBED + 20.0) << "newton " << newton;
    EXPECT_GT(f.sleeper_contacts, 0) << "newton " << newton;
  }
}

TEST(SleepPairs, ErrorsNameKeywordAndStyle)
{
  std::vector<std::string> base = {"units si", "atom_style sphere", "boundary p p f",
                                   "region box block 0 12e-6 0 12e-6 0 12e-6", "create_box 1 box",
                                   "create_atoms 1 single 6e-6 6e-6 6e-6 units box",
                                   "neighbor 2e-7 bin",
                                   "set group all diameter 2e-6", "set group all density 2500",
                                   "comm_modify vel yes", "pair_style granular",
                                   std::string("pair_coeff * * ") + MODEL,
                                   "fix integrate all nve/sphere", "timestep 5e-9"};
  auto with = [&](const std::string &fix) {
    auto c = base;
    c.push_back(fix);
    c.push_back("run 0");
    return c;
  };
  const std::string granular =
      gctest::error_of(with("fix sleep all sleep/gran speed 0.05 force 1e-7 wake 1e-7 time 0 "
                            "pairs awake"));
  EXPECT_NE(granular.find("pairs awake"), std::string::npos) << granular;
  EXPECT_NE(granular.find("requires pair_style granular/opt"), std::string::npos) << granular;
  EXPECT_NE(granular.find("not granular"), std::string::npos) << granular;
  const std::string bad =
      gctest::error_of(with("fix sleep all sleep/gran speed 0.05 force 1e-7 wake 1e-7 time 0 "
                            "pairs some"));
  EXPECT_NE(bad.find("pairs must be all or awake, got some"), std::string::npos) << bad;
  const std::string missing = gctest::error_of(
      with("fix sleep all sleep/gran speed 0.05 force 1e-7 wake 1e-7 time 0 pairs"));
  EXPECT_NE(missing.find("pairs"), std::string::npos) << missing;
  // pairs all keeps working with pair_style granular
  EXPECT_EQ(gctest::error_of(with("fix sleep all sleep/gran speed 0.05 force 1e-7 wake 1e-7 "
                                  "time 0 pairs all")),
            "no error");
}
