/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#ifdef GRAN_SUB_MOD_CLASS
// clang-format off
GranSubModStyle(jkr/marshall,GranSubModNormalJKRMarshall,NORMAL);
// clang-format on
#else

#ifndef GRAN_SUB_MOD_NORMAL_JKR_MARSHALL_H
#define GRAN_SUB_MOD_NORMAL_JKR_MARSHALL_H

#include "gran_sub_mod_normal.h"

namespace LAMMPS_NS {
namespace Granular_NS {

  // JKR contact as in Marshall, J. Comput. Phys. 228, 1541 (2009): the same elastic-adhesive
  // force as the built-in jkr, but a contact breaks at the separation point delta = -delta_C
  // instead of the force-controlled pull-off point, and the second coefficient is the
  // restitution coefficient used by damping marshall.
  class GranSubModNormalJKRMarshall : public GranSubModNormalJKR {
   public:
    GranSubModNormalJKRMarshall(class GranularModel *, class LAMMPS *);
    void coeffs_to_local() override;
    void mix_coeffs(double *, double *) override;
    void init() override;
    bool touch() override;
    double pulloff_distance(double, double) override;
    double calculate_contact_radius() override;
    double calculate_forces() override;

    double get_emix() const { return Emix; }                    //!< effective modulus E*
    double get_gmix() const { return Gmix; }                    //!< effective shear modulus G*
    double get_restitution() const { return restitution; }      //!< e, for damping marshall
    double get_pulloff_force() const { return F_pulloff; }      //!< F_C = 3 pi gamma R
    double get_adhesive_force() const { return F_adhesive; }    //!< 4 F_C (a/a_0)^(3/2)
    double critical_overlap(double reff) const;                 //!< delta_C for this R

   protected:
    double restitution;    // e, coefficient of restitution
    double Gmix;           // effective shear modulus
    double F_adhesive;     // adhesive part of the JKR force of the current contact
    double s_contact;      // scaled root s of the current contact (jkr_scaled.h)

    // scales of the last R seen (a monodisperse packing has one R per model, so this cache
    // spares a cbrt per touching pair and step)
    double scales_reff = -1.0;
    double scale_deltac = 0.0;        // delta_C
    double scale_inv_deltac = 0.0;    // 1 / delta_C (0 without adhesion)
    double scale_asep = 0.0;          // contact radius at separation, a_0 / 6^(2/3)
    double scale_fc = 0.0;            // F_C = 3 pi gamma R
    void use_scales(double reff)
    {
      if (reff != scales_reff) set_scales(reff);
    }
    void set_scales(double reff);
  };

}    // namespace Granular_NS
}    // namespace LAMMPS_NS

#endif
#endif
