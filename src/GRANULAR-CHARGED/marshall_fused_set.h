/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

// Which GranularModel a fused kernel may replace by the inline equations of
// marshall_kernels.h, and the coefficients it then needs: the Marshall set jkr/marshall +
// damping marshall or marshall/printed + tangential marshall, rolling none | marshall |
// marshall/particle, twisting none | marshall/jkr, heat none, no limit_damping (a cohesive
// model cannot use it anyway) and no synchronized_verlet (LAMMPS 4Jul2026; tangential marshall
// then runs mindlin's code). pair_style granular/opt and fix wall/gran/opt both decide here.

#ifndef LMP_GC_MARSHALL_FUSED_SET_H
#define LMP_GC_MARSHALL_FUSED_SET_H

#include "gran_sub_mod_damping_marshall.h"
#include "gran_sub_mod_normal_jkr_marshall.h"
#include "gran_sub_mod_rolling_marshall.h"
#include "gran_sub_mod_tangential_marshall.h"
#include "gran_sub_mod_twisting_marshall_jkr.h"

#include "granular_model.h"

namespace LAMMPS_NS {
namespace MarshallFusedSet {

  // the coefficients of one model of the set, as its sub-models hold them
  struct Coeffs {
    double emix = 0.0;                // E* (pair or wall mixing, as the model's contact type)
    double gamma = 0.0;               // surface energy
    double alpha = 0.0;               // damping alpha(e)
    double mass_factor = 2.0;         // damping marshall 2, marshall/printed 1
    double k_t = 0.0;                 // 8 G*: tangential stiffness per unit contact radius
    double mu = 0.0;                  // sliding friction coefficient
    bool rolling = false;             // rolling marshall[/particle] defined
    double theta_crit = 0.0;          // critical rolling angle
    double roll_radius_factor = 1.0;  // pair rolling limit at theta_crit x this x R_eff
    bool twisting = false;            // twisting marshall/jkr defined
    // offsets of the sub-models' values in the contact history (valid once the owner of the
    // model has set each sub-model's history_index)
    int hist_tangential = 0, hist_rolling = 0, hist_twisting = 0;
  };

  // is `model` of the fused set? If so, its coefficients into `c`
  inline bool of_model(Granular_NS::GranularModel *model, Coeffs &c)
  {
    using namespace Granular_NS;
    auto *normal = dynamic_cast<GranSubModNormalJKRMarshall *>(model->normal_model);
    auto *damping = dynamic_cast<GranSubModDampingMarshall *>(model->damping_model);
    auto *tangential = dynamic_cast<GranSubModTangentialMarshall *>(model->tangential_model);
    auto *rolling = dynamic_cast<GranSubModRollingMarshall *>(model->rolling_model);
    auto *twisting = dynamic_cast<GranSubModTwistingMarshallJKR *>(model->twisting_model);
    const bool rolling_ok = rolling || model->rolling_model->name == "none";
    const bool twisting_ok = twisting || model->twisting_model->name == "none";
    bool ok = normal && damping && tangential && rolling_ok && twisting_ok &&
        model->sub_models[HEAT]->name == "none" && !model->limit_damping;
#if GC_LAMMPS_VERSION >= 20260704
    ok = ok && !model->synchronized_verlet;
#endif
    if (!ok) return false;

    c = Coeffs();
    c.emix = normal->get_emix();
    c.gamma = normal->get_surface_energy();
    c.alpha = damping->get_alpha();
    c.mass_factor = damping->get_mass_factor();
    c.k_t = tangential->get_k();
    c.mu = tangential->get_mu();
    c.rolling = rolling != nullptr;
    if (rolling) {
      c.theta_crit = rolling->get_theta_crit();
      c.roll_radius_factor = rolling->get_pair_radius_factor();
    }
    c.twisting = twisting != nullptr;
    c.hist_tangential = model->tangential_model->history_index;
    c.hist_rolling = model->rolling_model->history_index;
    c.hist_twisting = model->twisting_model->history_index;
    return true;
  }

}    // namespace MarshallFusedSet
}    // namespace LAMMPS_NS

#endif
