/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#ifdef PAIR_CLASS
// clang-format off
PairStyle(granular/opt,PairGranularOpt);
// clang-format on
#else

#ifndef LMP_PAIR_GRANULAR_OPT_H
#define LMP_PAIR_GRANULAR_OPT_H

#include "granular_history_handover.h"
#include "marshall_fused_set.h"
#include "marshall_kernels.h"
#include "pair_granular.h"

#include <memory>
#include <string>
#include <vector>

namespace LAMMPS_NS {

// pair_style granular with a fused kernel for the Marshall sub-model set (jkr/marshall,
// damping marshall[/printed], tangential marshall, optional rolling marshall[/particle] and
// twisting marshall/jkr): the touching pairs packed into SIMD lanes and evaluated several at a
// time by the inline equations of marshall_kernels.h (marshall_lanes.h), no virtual calls.
// Every other type pair runs PairGranular::compute on a list of those pairs only. Same
// pair_coeff syntax, history layout, restart and single() as granular
// (doc/pair_granular_jkr_marshall.rst, "pair_style granular/opt"). With fix sleep/gran ...
// pairs awake, the pairs of two sleepers are left out of the contact list (doc/fix_sleep_gran.rst).
class PairGranularOpt : public PairGranular {
 public:
  PairGranularOpt(class LAMMPS *);
  ~PairGranularOpt() override;
  void compute(int, int) override;
  void init_style() override;

  // for tests and the log: does model n run the fused kernel?
  bool model_is_fused(int n) const;

  // contacts (touching pairs) whose forces the last compute() evaluated in its own loop
  bigint contacts_computed() const { return ncontacts; }
  // times the persistent contact list was built (tests: it follows the neighbor list)
  bigint contact_list_rebuilds() const { return list_rebuilds; }

 protected:
  // coefficients of one model for the fused kernel, copied from its sub-models
  struct FusedMarshall : MarshallFusedSet::Coeffs {
    bool on = false;                  // the model is of the fused set
  };
  std::vector<FusedMarshall> fused;      // one per entry of models_list
  bool fused_ready;                      // false after init_style(): rebuild before compute()
  bool generic_only;                     // no model fused (or a heat model): PairGranular's path
  bool any_heat;                         // a model with heat conduction
  bigint ncontacts;
  bool history_update;                   // this compute() advances the contact histories
  // the ID of fix sleep/gran with pairs awake ("": none, or pairs all), found by init_style()
  // and looked up by ID each step (a fix deleted or replaced before a run without init)
  std::string sleep_fix_id;
  // fix sleep/gran's state of this step when it leaves out the pairs of two sleepers: its
  // flags (local and ghost atoms) and the generation of its sleeping set
  struct Sleepers {
    const void *fix = nullptr;
    const double *asleep = nullptr;
    bigint generation = -1;
  };
  int hist_tangential, hist_rolling, hist_twisting;    // offsets in the per-pair history

  // R_eff and the JKR scales of one pair (of a type pair whose atoms all have one radius each)
  struct PairScales {
    bool valid = false;
    double reff = 0.0;
    MarshallKernels::JKRScales scales;
  };
  std::vector<double> type_radius;       // radius of every atom of a type (-1: none)
  // per type pair (itype * (ntypes + 1) + jtype), then those of the candidates whose type pair
  // has none (atoms of one type with several radii)
  std::vector<PairScales> pair_scales;

  // The contact list, persistent between neighbor-list builds: every pair of the list that the
  // fused kernel computes (a candidate: touching or not), in list order, which is the order of
  // the lanes and of the sums over contacts. What a pair keeps between builds is fixed until the
  // next: atoms, model, R_eff and scales (from radius and type, checked each step), special
  // factor and where its contact flag and history are in fix neigh/history's pages (laid anew
  // by each build). Each step reads only positions, velocities, spins, masses, flags and
  // histories; rebuilt with the list, after init_style() and when radius or type changed.
  struct Candidate {
    int i, j, model, scales;
    double radsum, factor_lj;
    int *touch;
    double *history;
  };
  std::vector<Candidate> candidates;
  bool one_pair;                         // every candidate of one model and one valid type pair
  // what the contact list was built from: a change of any of these rebuilds it
  struct ListStamp {
    const void *list = nullptr, *ilist = nullptr, *firstneigh = nullptr, *firstflag = nullptr,
               *firstvalue = nullptr;
    bigint build = -1, build_step = -1;
    // fix sleep/gran and the generation of its sleeping set (null, -1: no pairs left out)
    const void *sleep_fix = nullptr;
    bigint sleepers = -1;
    int inum = -1, nall = -1;
    bool operator==(const ListStamp &o) const
    {
      return list == o.list && ilist == o.ilist && firstneigh == o.firstneigh &&
          firstflag == o.firstflag && firstvalue == o.firstvalue && build == o.build &&
          build_step == o.build_step && sleep_fix == o.sleep_fix && sleepers == o.sleepers &&
          inum == o.inum &&
          nall == o.nall;
    }
  };
  ListStamp list_stamp;
  bool list_stale;                       // set by init_style(): rebuild at the next compute()
  std::vector<double> list_radius;       // radius and type of every atom at the last rebuild
  std::vector<int> list_type;
  bigint list_rebuilds;                  // contact-list rebuilds so far (tests)
  // one chunk's touching contacts: candidate, lane (-1: the scalar kernel), x_i - x_j
  struct ChunkContact {
    int candidate, lane;
    double dx[3];
  };
  std::vector<ChunkContact> chunk;
  std::vector<double> jkr_overlap, jkr_root;    // a chunk's scaled overlaps and JKR roots
  // lanes blocks of one chunk of contacts (marshall_lanes.h)
  std::vector<double> lane_in, lane_out;
  std::vector<double> model_dt;          // time step of each model
  // the entry of pair_scales whose model inputs each lane of the chunk holds (-1: none): kept
  // from step to step, so a lane is written again only when its contact is of another model,
  // type pair or pair of radii (cleared when the contact list or a time step changes)
  std::vector<int> lane_scales;
  // the contact history across restarts and switches of style
  GranularHistoryHandover history_handover;
  // the pairs outside the fused set (atom, index in its list) and their list for
  // PairGranular::compute, with copies of their contact flags and histories
  std::vector<int> generic_i, generic_jj;
  std::unique_ptr<class NeighList> generic_list;
  std::vector<int> generic_atoms, generic_numneigh, generic_neigh, generic_touch;
  std::vector<int *> generic_firstneigh, generic_firsttouch;
  std::vector<double> generic_history;
  std::vector<double *> generic_firsthistory;

  void setup_fused();
  // the steps of compute()
  void begin_step(int eflag, int vflag);
  Sleepers sleepers_to_skip();
  bool contact_list_current(const Sleepers &sleepers);
  void build_contact_list(const double *asleep);
  void type_scales();
  bigint compute_generic_pairs(int eflag, int vflag);
  void build_generic_list();
  bigint compute_fused_contacts();
  int scales_of(int i, int j, const FusedMarshall &fm);
};

}    // namespace LAMMPS_NS

#endif
#endif
