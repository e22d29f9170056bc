/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

// Which atoms touch the wall of a fix wall/gran (or wall/gran/opt): a wall whose contact model
// acts beyond contact (JKR) keeps, as the first value of each atom's wall history, 1 while the
// atom touches it and 0 otherwise (FixWallGran::post_force). The history is protected in both
// supported LAMMPS releases, without an accessor: a class derived from it forms pointers to
// those members.

#ifndef LMP_WALL_GRAN_TOUCH_H
#define LMP_WALL_GRAN_TOUCH_H

#include "fix_wall_gran.h"
#include "granular_model.h"

namespace LAMMPS_NS {

namespace wall_gran_touch_detail {
struct Members : public FixWallGran {
  static double **touch(FixWallGran *f)
  {
    if (!(f->*(&Members::use_history)) || !f->model || !f->model->beyond_contact) return nullptr;
    return f->*(&Members::history_one);
  }
};
}    // namespace wall_gran_touch_detail

// the wall's per-atom history, whose [i][0] is nonzero while local atom i touches the wall
// (updated in the wall's post_force for the atoms of its group), or nullptr if the wall's model
// does not keep that flag
inline double **wall_gran_touch_flags(FixWallGran *f)
{
  return wall_gran_touch_detail::Members::touch(f);
}

}    // namespace LAMMPS_NS

#endif
