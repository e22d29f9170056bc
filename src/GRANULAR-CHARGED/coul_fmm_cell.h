/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

// The box of fix coul/fmm as the gcfmm objects take it (CoulFMMBackend::cell() reads it from
// LAMMPS): the primary cell in x and y and the z range. No LAMMPS headers, so the parts that
// need a cell (the solver, the static sleepers) take this value, not the backend.

#ifndef LMP_COUL_FMM_CELL_H
#define LMP_COUL_FMM_CELL_H

namespace LAMMPS_NS {

struct CoulFMMCell {
  bool periodic = false;    // periodic in x and y (boundary p p f); free space: no cell
  double xlo = 0.0, ylo = 0.0, lx = 0.0, ly = 0.0, zlo = 0.0, zhi = 0.0;

  bool operator==(const CoulFMMCell &o) const
  {
    return periodic == o.periodic && xlo == o.xlo && ylo == o.ylo && lx == o.lx && ly == o.ly &&
        zlo == o.zlo && zhi == o.zhi;
  }
  bool operator!=(const CoulFMMCell &o) const { return !(*this == o); }

  // to any gcfmm object with set_box and set_z_range (nothing in free space)
  template <class T> void apply_to(T &target) const
  {
    if (!periodic) return;
    target.set_box(xlo, ylo, lx, ly);
    // boundary f in z keeps every atom in the box: one far-field set-up for the run instead of
    // one each time the charges' z range grows (e.g. during a deposition)
    target.set_z_range(zlo, zhi);
  }
};

}    // namespace LAMMPS_NS

#endif
