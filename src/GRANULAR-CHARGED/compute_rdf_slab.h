/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

#ifdef COMPUTE_CLASS
// clang-format off
ComputeStyle(rdf/slab,ComputeRDFSlab);
// clang-format on
#else

#ifndef LMP_COMPUTE_RDF_SLAB_H
#define LMP_COMPUTE_RDF_SLAB_H

#include "compute.h"

namespace LAMMPS_NS {

// Radial distribution function g(r) of the atoms whose centres lie in a slab zlo <= z <= zhi of
// a box periodic in x and y; the ideal-gas normalisation uses the part of each shell that lies
// inside the slab.
class ComputeRDFSlab : public Compute {
 public:
  ComputeRDFSlab(class LAMMPS *, int, char **);
  ~ComputeRDFSlab() override;
  void init() override;
  void init_list(int, class NeighList *) override;
  void compute_array() override;
  double memory_usage() override;

 private:
  int nbin;                  // # of rdf bins
  double rmax_user;          // rmax as given (box units or diameters)
  int diameter_units;        // 1 if r and rmax are in units of the mean particle diameter
  double zlo, zhi;           // slab of atom centres
  int zlo_null, zhi_null;    // 1 if that bound is NULL (lowest / highest centre of the group)

  double dunit;         // length unit of r: 1 or the mean diameter at init()
  double rmax, delr;    // rmax and bin width in box units
  double *buf,
      *bufall;    // local and global tallies: hist[nbin], count[nbin], capsum[nbin+1], nref
  class NeighList *list;    // occasional half list with cutoff rmax + skin
  bool warned_outside;      // the slab outside a non-periodic z range has been reported

};

}    // namespace LAMMPS_NS

#endif
#endif
