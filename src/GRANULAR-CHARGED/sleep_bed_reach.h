/* -*- c++ -*- ----------------------------------------------------------
   GRANULAR-CHARGED package for LAMMPS.

   Where the bed of a column ends, for the depth rule of fix sleep/gran: free of LAMMPS, so that
   it is tested alone.

   The bed's atoms (sleepers, and atoms in contact that are slow) are binned on a grid of
   nbx x nby columns and nbz layers, one particle wide and tall. A column's bed reaches from
   its lowest occupied layer up to the last layer before a run of more than max_gap empty
   layers, occupancy taken over the column and its eight neighbours (so that the pores of a
   loose bed do not end it). What lies above such a gap is not the bed: a cluster of charged
   particles that met in flight and hovers, slow, above a charged bed is in contact and slow
   too, and taken for the bed's top it would put every atom below it to sleep.
------------------------------------------------------------------------- */

#ifndef LMP_GC_SLEEP_BED_REACH_H
#define LMP_GC_SLEEP_BED_REACH_H

#include <vector>

namespace GranularCharged {

// occupied[(by * nbx + bx) * nbz + bz] != 0: a bed atom in column (bx, by), layer bz. Returns,
// per column by * nbx + bx, the first layer that is not the bed's (nbz: the bed reaches the top
// of the grid; 0: the column has no bed). periodic_x, periodic_y: neighbours wrap around the box.
inline std::vector<int> bed_reach(const std::vector<unsigned char> &occupied, int nbx, int nby,
                                  int nbz, bool periodic_x, bool periodic_y, int max_gap)
{
  std::vector<int> reach(static_cast<size_t>(nbx) * nby, 0);
  auto cell = [&](int bx, int by, int bz) -> bool {
    if (bx < 0 || bx >= nbx) {
      if (!periodic_x) return false;
      bx = (bx + nbx) % nbx;
    }
    if (by < 0 || by >= nby) {
      if (!periodic_y) return false;
      by = (by + nby) % nby;
    }
    return occupied[(static_cast<size_t>(by) * nbx + bx) * nbz + bz] != 0;
  };
  for (int by = 0; by < nby; ++by)
    for (int bx = 0; bx < nbx; ++bx) {
      int end = 0, empty = 0;
      bool started = false;
      for (int bz = 0; bz < nbz; ++bz) {
        bool any = false;
        for (int dy = -1; dy <= 1 && !any; ++dy)
          for (int dx = -1; dx <= 1 && !any; ++dx) any = cell(bx + dx, by + dy, bz);
        if (any) {
          started = true;
          empty = 0;
          end = bz + 1;
        } else if (started && ++empty > max_gap) {
          break;
        }
      }
      reach[static_cast<size_t>(by) * nbx + bx] = end;
    }
  return reach;
}

}    // namespace GranularCharged

#endif
