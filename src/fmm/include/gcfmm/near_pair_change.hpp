// GRANULAR-CHARGED FMM core library (gcfmm).
// The multiple time stepping of polarizable particles (doc/polarization.md, section 8): between
// two FMM evaluations the force on each particle is the evaluation's plus the change of its near
// pairs since then, with the charges and dipoles held at the evaluation's values:
//   F_i(t) = F_i(t_e) + sum_{k near i} [f_ik(t) - f_ik(t_e)],   f_ik = q_i E_k(r_i) + G_k(r_i) p_i
// over the other particles and their periodic copies, and (with a grounded electrode) every
// particle's mirror image; a pair is near when it is closer than the cutoff now or at the
// evaluation (so a pair entering or leaving the cutoff adds no jump), and a particle's own image
// is always near (its pull changes fastest as the particle falls onto the electrode). The far part
// (everything else) is held. The pair terms are those of dipole_kernels.hpp (one home).
#ifndef GCFMM_NEAR_PAIR_CHANGE_HPP
#define GCFMM_NEAR_PAIR_CHANGE_HPP

#include <cstddef>
#include <vector>

namespace gcfmm {

//! Where the particles are: free space or periodic in x and y, with or without a grounded plane.
struct NearGeometry {
  bool periodic = false;    //!< periodic in x and y with the periods lx, ly
  double lx = 0.0, ly = 0.0;
  bool electrode = false;   //!< a grounded plane z = electrode_z below every particle (images)
  double electrode_z = 0.0;
};

//! The change since the evaluation at each target (bare units; 3 per target for vectors).
struct NearChange {
  std::vector<double> field;  //!< change of the field E
  std::vector<double> pot;    //!< change of the potential of the charges and dipoles
  std::vector<double> force;  //!< change of q E + G p (p held)
};

class NearPairChange {
 public:
  /** @throws std::invalid_argument unless cutoff > 0 and, periodic, both periods > 0 */
  NearPairChange(double cutoff, const NearGeometry &geometry);

  /** @brief Whether compute() can follow displacements up to max_displacement: in a periodic
   *  box the cutoff plus twice that must stay below half of each period (one copy of a pair
   *  within reach). */
  bool fits(double max_displacement) const;

  /** @brief The change of field, potential and force at the targets from the positions `then`
   *  (of the evaluation) to `now`, both 3 n interleaved and unwrapped alike (then = now minus
   *  the displacement), q (n) and p (3 n, or null: no dipoles) held.
   *  @param targets indices of the particles whose change is wanted (nt of them)
   *  @return false (out untouched) if the displacements are too large for the box (fits())
   *  @throws std::invalid_argument if a particle is at or below the electrode now */
  bool compute(std::size_t n, const double *now, const double *then, const double *q, const double *p,
               const std::size_t *targets, std::size_t nt, NearChange &out);

  double cutoff() const { return cutoff_; }
  //! pairs whose change the last compute() summed (images included)
  std::size_t pairs() const { return pairs_; }

 private:
  double cutoff_;
  NearGeometry geo_;
  std::size_t pairs_ = 0;
  // the sources of the last compute(): particles, then the images within reach of the plane
  struct Source {
    double now[3], then[3], q, p[3];
    std::size_t particle;
    bool image;
  };
  std::vector<Source> sources_;
  std::vector<std::size_t> cell_start_, cell_items_;
};

}  // namespace gcfmm

#endif
