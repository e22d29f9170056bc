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

#include "marshall_kernels.h"
#include "pair_granular.h"

#include <vector>

namespace LAMMPS_NS {

// pair_style granular with a fused kernel for the Marshall sub-model set (jkr/marshall,
// damping marshall[/printed], tangential marshall, optional rolling marshall[/particle] and
// twisting marshall/jkr): one pass per neighbor pair through the inline equations of
// marshall_kernels.h, no virtual calls. Every other type pair runs PairGranular's sub-model
// path. Same pair_coeff syntax, history layout, restart and single() as granular
// (doc/pair_granular_jkr_marshall.md, "pair_style granular/opt").
class PairGranularOpt : public PairGranular {
 public:
  PairGranularOpt(class LAMMPS *);
  void compute(int, int) override;
  void init_style() override;

  // for tests and the log: does model n run the fused kernel?
  bool model_is_fused(int n) const;

  // fix sleep/gran: set mark[j] = 1 for every sleeper j (flag 1) touching an atom flagged -1
  // (local and ghost atoms of this rank's list)
  void mark_touching_sleepers(const double *flag, double *mark) const;
  // contacts (touching pairs) whose forces the last compute() evaluated in its own loop
  bigint contacts_computed() const { return ncontacts; }

 protected:
  // coefficients of one model for the fused kernel, copied from its sub-models
  struct FusedMarshall {
    bool on = false;                  // the model is of the fused set
    double emix = 0.0;                // E*
    double gamma = 0.0;               // surface energy
    double alpha = 0.0;               // damping alpha(e)
    double mass_factor = 2.0;         // damping marshall 2, marshall/printed 1
    double k_t = 0.0;                 // 8 G*: tangential stiffness per unit contact radius
    double mu = 0.0;                  // sliding friction coefficient
    bool rolling = false;             // rolling marshall[/particle] defined
    double theta_crit = 0.0;          // critical rolling angle
    double roll_radius_factor = 1.0;  // rolling limit at theta_crit x this x R_eff
    bool twisting = false;            // twisting marshall/jkr defined
    MarshallKernels::JKRScales scales;    // delta_C, a_sep, F_C of the last R_eff
    // the last pair's radii and masses: a monodisperse packing divides and takes roots once
    double radi = -1.0, radj = -1.0, reff = 0.0;      // R_eff (and scales) of radii radi, radj
    double mi = -1.0, mj = -1.0, meff = 0.0;          // m* of masses mi, mj
    double sqrt_mass_of = -1.0, sqrt_mass = 0.0;      // sqrt(mass_factor m*) of m* = sqrt_mass_of
  };
  std::vector<FusedMarshall> fused;      // one per entry of models_list
  bool fused_ready;                      // false after init_style(): rebuild before compute()
  bool generic_only;                     // no model fused (or a heat model): PairGranular's path
  bool any_heat;                         // a model with heat conduction
  class FixSleepGran *sleep_fix;         // fix sleep/gran, if defined
  // with sleepers: the list entries ii whose atom is awake or has an awake neighbor, rebuilt
  // after each neighbor list build and each change of the sleeping set
  std::vector<int> active;
  bigint active_build, active_generation;
  bigint ncontacts;
  int hist_tangential, hist_rolling, hist_twisting;    // offsets in the per-pair history

  void setup_fused();
  // a sleeper is a fixed body, as an atom of fix freeze: the effective mass is the other's
  static void sleeper_mass(double sleep_i, double sleep_j, double mi, double mj, double &meff)
  {
    if (sleep_i != 0.0) meff = mj;
    if (sleep_j != 0.0) meff = mi;
  }
  void update_active(const double *asleep);

  // R_eff and the JKR scales of the pair's radii (recomputed only when they change)
  static void use_radii(FusedMarshall &fm, double radi, double radj)
  {
    if (radi == fm.radi && radj == fm.radj) return;
    fm.radi = radi;
    fm.radj = radj;
    fm.reff = radi * radj / (radi + radj);
    MarshallKernels::use_jkr_scales(fm.scales, fm.reff, fm.gamma, fm.emix);
  }

  // compute()'s two passes: the interacting pairs (atom, index in its neighbor list) and the
  // scaled overlaps and JKR roots of the adhesive fused ones, in pair order
  std::vector<int> contact_i, contact_jj;
  std::vector<double> jkr_overlap, jkr_root;
};

}    // namespace LAMMPS_NS

#endif
#endif
