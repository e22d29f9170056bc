/* -*- c++ -*- ----------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

// The LAMMPS side of fix coul/fmm's one Coulomb solver (LAMMPS's ScaFaCoS adapter is the
// model): it holds a gcfmm::CoulombBackend (replicated, distributed or polarizable), sets its
// cell from the LAMMPS box, scales its bare-kernel results by qqrd2e, and turns the library's
// failures into one LAMMPS error naming atom IDs.

#ifndef LMP_COUL_FMM_BACKEND_H
#define LMP_COUL_FMM_BACKEND_H

#include "coul_fmm_cell.h"
#include "coul_fmm_comm.h"
#include "pointers.h"

#include <functional>
#include <memory>
#include <stdexcept>
#include <string>

namespace gcfmm {
class CoulombBackend;
class PolarizableBackend;
struct Options;
}    // namespace gcfmm

namespace LAMMPS_NS {

class CoulFMMBackend : protected Pointers {
 public:
  enum class Kind { REPLICATED, DISTRIBUTED, POLARIZABLE };
  // a failure already in LAMMPS terms (thrown inside run())
  struct Failure : std::runtime_error {
    using std::runtime_error::runtime_error;
  };

  explicit CoulFMMBackend(class LAMMPS *);
  ~CoulFMMBackend() override;

  // opts.boundary from the box (free space or periodic in x and y only), and errors for the
  // solver options this box rules out
  void set_geometry(gcfmm::Options &opts, bool bed_given);
  // warnings or errors for other styles that compute the same Coulomb interactions: a kspace
  // style, a pair style with a coul part, another fix coul/fmm sharing charged atoms
  void check_counted_once(class Fix *self);

  // a solver of this kind for these options; the one of the last run is kept if the kind and
  // the boundary are the same (its tree memory and far-field operator). True if new.
  bool create(Kind kind, const gcfmm::Options &opts, bool dipoles = false);
  gcfmm::CoulombBackend &solver() { return *backend; }
  gcfmm::PolarizableBackend &polarizable();
  bool distributed() const { return kind == Kind::DISTRIBUTED; }
  CoulFMMComm &communication() { return mpi; }

  // the primary cell and its z range from the LAMMPS box (boundary p p f; nothing in free
  // space): to the solver; cell() for any other gcfmm object (CoulFMMCell::apply_to)
  void set_cell();
  CoulFMMCell cell() const;
  // bare 1/r kernel -> LAMMPS units (qqrd2e includes the dielectric constant)
  double scale() const;

  // runs the library call (evaluation); a failure (on this rank, or on any rank unless
  // same_on_all_ranks) stops every rank with one LAMMPS error. tag_of: the solver's particle
  // index in a CoincidentParticles -> atom ID; explain: a better message for a failure, if any
  void run(const std::function<void()> &evaluation, const std::function<tagint(size_t)> &tag_of,
           bool same_on_all_ranks, const std::function<std::string()> &explain = nullptr);

 private:
  std::unique_ptr<gcfmm::CoulombBackend> backend;
  Kind kind;
  int boundary;
  CoulFMMComm mpi;
  std::string failure_of(const std::function<void()> &evaluation,
                         const std::function<tagint(size_t)> &tag_of) const;
};

}    // namespace LAMMPS_NS

#endif
