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
#include "marshall_kernels.h"

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
    void set_fncrit() override;

    double get_emix() const { return Emix; }                    //!< effective modulus E*
    double get_gmix() const { return Gmix; }                    //!< effective shear modulus G*
    double get_surface_energy() const { return cohesion; }      //!< gamma
    double get_restitution() const { return restitution; }      //!< e, for damping marshall
    double get_adhesive_force() const { return contact.adhesive; }    //!< 4 F_C (a/a_0)^(3/2)
    const MarshallKernels::NormalForce &get_contact() const { return contact; }    //!< current contact

   protected:
    double restitution;    // e, coefficient of restitution
    double Gmix;           // effective shear modulus
    // the current contact: computed with its contact radius, read by calculate_forces() and by
    // rolling marshall (LAMMPS asks for the radius first, then for the force)
    MarshallKernels::NormalForce contact;
    // delta_C, a_sep, F_C of radius scales_reff: LAMMPS hands the sub-model one contact at a
    // time, and most contacts of a packing share their R, so the scales are kept until R changes
    MarshallKernels::JKRScales scales;
    double scales_reff;
    void use_scales(double reff);
  };

}    // namespace Granular_NS
}    // namespace LAMMPS_NS

#endif
#endif
