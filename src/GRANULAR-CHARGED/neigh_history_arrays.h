/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

// The per-atom partner arrays of fix NEIGH_HISTORY (its pre_exchange() fills them from the
// neighbor list, its post_neighbor() copies them into the new list), for the package's classes
// that read them (the history handover across restarts, fix bury/gran). LAMMPS 4Jul2026 gives
// them through public accessors; 4Feb2025 keeps them protected with no accessor, and there a
// class derived from it forms pointers to those members.

#ifndef LMP_NEIGH_HISTORY_ARRAYS_H
#define LMP_NEIGH_HISTORY_ARRAYS_H

#include "fix_neigh_history.h"
#include "my_page.h"

#include <type_traits>
#include <utility>

namespace LAMMPS_NS {

struct NeighHistoryArrays {
  int *npartner;
  tagint **partner;
  double **valuepartner;
  MyPage<tagint> *ipage;
  MyPage<double> *dpage;
  int dnum;
};

namespace neigh_history_detail {
template <class F, class = void> struct HasAccessors : std::false_type {};
template <class F>
struct HasAccessors<F, std::void_t<decltype(std::declval<F &>().get_dpage_atom())>>
    : std::true_type {};

struct Members : public FixNeighHistory {
  static NeighHistoryArrays of(FixNeighHistory *f)
  {
    return {f->*(&Members::npartner), f->*(&Members::partner), f->*(&Members::valuepartner),
            f->*(&Members::ipage_atom), f->*(&Members::dpage_atom), f->*(&Members::dnum)};
  }
};

template <class F> NeighHistoryArrays arrays(F *f)
{
  if constexpr (HasAccessors<F>::value)
    return {f->get_npartner(), f->get_partner(), f->get_valuepartner(), f->get_ipage_atom(),
            f->get_dpage_atom(), f->get_dnum()};
  else
    return Members::of(f);
}
}    // namespace neigh_history_detail

inline NeighHistoryArrays neigh_history_arrays(FixNeighHistory *f)
{
  return neigh_history_detail::arrays(f);
}

}    // namespace LAMMPS_NS

#endif
