/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

// The condenser model of contact charging as stateless inline functions: the one home of each
// formula, called by fix tribo/charge (the plumbing: contacts, records, communication) and by
// the tests. Equation numbers: doc/fix_tribo_charge.rst, "Model".
//
// A contact between bodies a and b is a capacitor of gap z0 and area A: while A grows by dA,
// the charge
//     dq_a = -(eps dA / z0) (V_a - V_b + E_n z0)                              (T.1)
// flows onto a (and -dq_a onto b), with V the contact potential of each material (work
// function / e), eps the permittivity of the gap and E_n = E(c) . n the normal component of
// the electric field at the contact point c, n the unit normal from a to b. The material of
// higher V becomes negative; the flow stops when E_n z0 = -(V_a - V_b) (saturation).
// Units: V enters as energy per charge (V in volts times force->qe2f), E as force per charge,
// eps = 1 / (4 pi qqrd2e).

#ifndef LMP_GC_TRIBO_CHARGE_KERNELS_H
#define LMP_GC_TRIBO_CHARGE_KERNELS_H

#include <cmath>

namespace LAMMPS_NS {
namespace TriboChargeKernels {

  // (T.1): the charge onto a for an area growth dA, with the driving voltage
  // drive = V_a - V_b + E_n z0 (energy per charge) and the gap's permittivity eps
  inline double condenser_charge(double eps, double z0, double darea, double drive)
  {
    return -eps * darea / z0 * drive;
  }

  // the driving voltage of (T.1): the contact potential difference less the field's drop over
  // the gap (field_on false: the field-free law, E_n = 0)
  inline double contact_drive(double dv, double en, double z0, bool field_on)
  {
    return field_on ? dv + en * z0 : dv;
  }

  // distance from the centre of sphere a to the plane of the contact circle of two spheres of
  // radii ra, rb whose centres are r apart (the plane through the circle where the two
  // surfaces meet; (r^2 + ra^2 - rb^2) / (2 r), ra - delta/2 for equal radii)    (T.2)
  inline double contact_plane_distance(double r, double ra, double rb)
  {
    return (r * r + ra * ra - rb * rb) / (2.0 * r);
  }

  // E_n of (T.1) at the contact point c of a pair, c at da from a and db = r - da from b on
  // the line from a to b (unit normal n):
  //   E_n = C q_a / da^2 - C q_b / db^2 + (1 - w) (E_a . n + C q_b / r^2)
  //         + w (E_b . n - C q_a / r^2)                                          (T.3)
  // the pair's own charges as point charges at the centres, and the field of every other
  // charge interpolated linearly along the line (w = da / r) from its values at the centres:
  // E_a . n is the solver's field at a, which holds b's own C q_b K(x_a - x_b), . n = -C q_b /
  // r^2 (taken out), and likewise at b. has_a, has_b: whether the solver gives a field at that
  // centre (a charged atom); with one, it stands for the whole line, with none there is no
  // field of other charges.
  inline double pair_normal_field(double coulomb, double qa, double qb, double r, double da,
                                  double ena, double enb, bool has_a, bool has_b)
  {
    const double db = r - da;
    const double own = coulomb * (qa / (da * da) - qb / (db * db));
    const double rest_a = ena + coulomb * qb / (r * r);
    const double rest_b = enb - coulomb * qa / (r * r);
    double rest = 0.0;
    if (has_a && has_b) {
      const double w = da / r;
      rest = (1.0 - w) * rest_a + w * rest_b;
    } else if (has_a) {
      rest = rest_a;
    } else if (has_b) {
      rest = rest_b;
    }
    return own + rest;
  }

  // E_n at the contact of a sphere with a plane wall at distance d from its centre, n from the
  // centre to the wall: the particle's own charge at the contact point and the solver's field
  // at the centre for every other charge (and the images the solver has)             (T.4)
  inline double wall_normal_field(double coulomb, double q, double d, double en)
  {
    return coulomb * q / (d * d) + en;
  }

  // the saturation charge of two spheres a, b of opposite charges q_a = -q_b alone in free
  // space, touching with their contact plane at da, db from the centres: (T.1) with
  // E_n = C q_a (1/da^2 + 1/db^2) (T.3 without other charges) vanishes at
  //   q_a = -(V_a - V_b) / (C z0 (1/da^2 + 1/db^2))                                (T.5)
  inline double pair_saturation_charge(double coulomb, double dv, double z0, double da, double db)
  {
    return -dv / (coulomb * z0 * (1.0 / (da * da) + 1.0 / (db * db)));
  }

}    // namespace TriboChargeKernels
}    // namespace LAMMPS_NS

#endif
