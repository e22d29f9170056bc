/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#ifndef LMP_COUL_FMM_SLEEPERS_H
#define LMP_COUL_FMM_SLEEPERS_H

#include "coul_fmm_cell.h"
#include "coul_fmm_comm.h"
#include "pointers.h"

#include <memory>
#include <string>
#include <vector>

namespace gcfmm {
class StaticSourceField;
struct Options;
}    // namespace gcfmm

namespace LAMMPS_NS {

// fix coul/fmm with fix sleep/gran: the sleeping charges as a static source
// (doc/fix_coul_fmm.rst, "Sleeping particles"). Their field at the awake atoms comes from a
// gcfmm::StaticSourceField built once per change of the sleeping set or of the cell; the awake
// charges go through the fix's solver (CoulFMMEvaluator adds the two). Gathers the sleepers of
// all ranks sorted by atom ID (the same set and order on every rank); the caller gives each rank
// its share of the awake targets.
class CoulFMMSleepers : protected Pointers {
 public:
  CoulFMMSleepers(class LAMMPS *, const gcfmm::Options &, int groupbit);
  ~CoulFMMSleepers() override;

  // the sleeper flags (local atoms) of fix sleep/gran and the generation of its set
  void use(const double *asleep, bigint generation);
  bool asleep(int i) const { return flags && flags[i] != 0.0; }

  // rebuild the static source if the sleeping set or the cell (the box, its z range) changed;
  // throws what gcfmm throws
  void prepare(const CoulFMMCell &cell);
  // ADD the sleepers' potential and field (bare 1/r kernel) at the targets [first, last) of
  // the gathered awake atoms; returns sum_t q_t pot_t over those targets
  double add_field(const double *x, const double *y, const double *z, const double *q,
                   size_t first, size_t last, double *pot, double *ex, double *ey, double *ez);
  // energy of the sleepers among themselves (bare kernel), computed when first asked after a
  // change of the set
  double source_energy();

  double memory_usage() const;
  // ID of the sleeping atom at position k of the gathered set (error messages)
  tagint source_tag(size_t k) const { return k < sources.size() ? sources.tag[k] : -1; }

 private:
  std::unique_ptr<gcfmm::StaticSourceField> field;
  int groupbit;
  const double *flags;
  bigint generation, built_generation;
  CoulFMMCell built_cell;
  GatheredCharges sources;
  void gather();
};

}    // namespace LAMMPS_NS

#endif
