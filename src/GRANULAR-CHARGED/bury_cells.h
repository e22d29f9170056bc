/* -*- c++ -*- ----------------------------------------------------------
   GRANULAR-CHARGED package for LAMMPS.

   The cell grid of fix bury/gran's rule, free of LAMMPS so that it is tested alone: which cells
   lie within a given number of cells of a cell holding an awake atom, along each axis of a grid
   that is periodic or clamped per axis.
------------------------------------------------------------------------- */

#ifndef LMP_GC_BURY_CELLS_H
#define LMP_GC_BURY_CELLS_H

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace GranularCharged {

// index of the column (n columns of width w from lo) holding coordinate c, periodic or clamped
inline int column_index(double c, double lo, double w, int n, bool periodic)
{
  int b = static_cast<int>(std::floor((c - lo) / w));
  if (periodic) {
    b %= n;
    if (b < 0) b += n;
  } else {
    b = std::min(std::max(b, 0), n - 1);
  }
  return b;
}

// Each flag of a grid of n[0] x n[1] x n[2] flags (x fastest) becomes 1 if any flag of the
// window [e - k, e + k] along `axis` (0, 1, 2) is set: wrapped around a periodic axis, cut at the
// ends of a clamped one. Running counts along each line: linear in the grid size whatever k,
// with no division in the inner loop.
inline void window_any(std::vector<unsigned char> &v, const int n[3], int axis, int k, bool periodic)
{
  const int len = n[axis];
  if (len <= 0 || k <= 0) return;
  const size_t stride = axis == 0 ? 1 : (axis == 1 ? n[0] : static_cast<size_t>(n[0]) * n[1]);
  const int o1 = axis == 0 ? n[1] : n[0], o2 = axis == 2 ? n[1] : n[2];
  const size_t s1 = axis == 0 ? n[0] : 1;
  const size_t s2 = axis == 2 ? n[0] : static_cast<size_t>(n[0]) * n[1];
  // a periodic window as wide as the ring or wider holds the whole line
  const bool whole = periodic && 2 * static_cast<long>(k) + 1 >= len;
  std::vector<int> count(len + 1);
  for (int b = 0; b < o2; b++)
    for (int a = 0; a < o1; a++) {
      unsigned char *line = v.data() + a * s1 + b * s2;
      count[0] = 0;
      for (int e = 0; e < len; e++) count[e + 1] = count[e] + (line[e * stride] ? 1 : 0);
      const int total = count[len];
      for (int e = 0; e < len; e++) {
        const int from = e - k, to = e + k;    // to - from + 1 < len when periodic and !whole
        int sum;
        if (whole) sum = total;
        else if (!periodic) sum = count[std::min(to, len - 1) + 1] - count[std::max(from, 0)];
        else if (from < 0) sum = count[to + 1] + total - count[len + from];
        else if (to >= len) sum = total - count[from] + count[to - len + 1];
        else sum = count[to + 1] - count[from];
        line[e * stride] = sum > 0 ? 1 : 0;
      }
    }
}

}    // namespace GranularCharged

#endif
