// GRANULAR-CHARGED FMM core library (gcfmm).
// The exact far field of a 2D-periodic system: the field of all image cells beyond the near
// block, a precomputed Chebyshev operator applied to the smooth far kernel R of
// lattice_sum.hpp (doc/theory.md, eq. (4.6)). No LAMMPS headers; only std (Eigen is used
// inside the library only, so that callers built with other vectorisation flags share no
// Eigen objects with it).
// See doc/fmm-far-field.md for the error control and measured costs.
#ifndef GCFMM_FAR_FIELD_HPP
#define GCFMM_FAR_FIELD_HPP

#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include "gcfmm/types.hpp"
#include "gcsimd/simd.hpp"

namespace gcfmm {

/** @brief Thrown by PeriodicFarField::setup() / setup_explicit() BEFORE anything is allocated
 *  when the operator of the column would need more than PeriodicFarField::kMaxSetupBytes:
 *  the cost grows linearly with the column height H in units of the cell side L (boxes of
 *  height <= L). bytes() is the estimate, boxes() the number of boxes, height_over_side() H/L
 *  of the stored (padded) column. */
class FarFieldTooLarge : public std::runtime_error {
 public:
  FarFieldTooLarge(double bytes, int boxes, double height_over_side, const std::string &what)
      : std::runtime_error(what), bytes_(bytes), boxes_(boxes), hl_(height_over_side) {}
  double bytes() const { return bytes_; }                //!< estimated peak bytes of the set-up
  int boxes() const { return boxes_; }                   //!< boxes of the column
  double height_over_side() const { return hl_; }        //!< stored column height / min(lx, ly)

 private:
  double bytes_;
  int boxes_;
  double hl_;
};

/**
 * @brief Field of all image cells beyond `images` shells (max(|nx|,|ny|) > images), the
 * exact lattice sum to the requested accuracy.
 *
 * Method (black-box FMM of Fong & Darve, J. Comput. Phys. 228 (2009) 8712, applied to the
 * smooth far kernel R above): the column [zlo, zhi] (padded) is split into nb boxes of
 * full cell width and height hz <= min(lx, ly) (0.7 min(lx, ly) at 1e-8); each box
 * carries a tensor Chebyshev grid of p x p x pz nodes; charges are anterpolated to the nodes, the node potentials are
 * M_{t-s} W_s with the precomputed matrices M_o[a, b] = R(node_a - node_b + o hz e_z)
 * (translation invariant, so one matrix per box offset o, and M_{-o} = M_o^T since R is
 * even), and potential and field at the targets are the Chebyshev interpolant and its
 * derivative. R is even in dx and dy and the nodes are mirror-symmetric, so each M_o is
 * block diagonal in even/odd node combinations (4 blocks of size (p^2 pz / 4)^2; p even).
 * Cost: set-up evaluates R once per distinct |node difference| and fills nb x 4 blocks;
 * evaluate costs O(N p^2 pz + ns nt (p^2 pz)^2 / 4), ns and nt the spans of boxes holding
 * sources and targets (at most nb).
 * Parameters (p, pz, hz) per accuracy and measured errors/costs: doc/fmm-far-field.md.
 *
 * Conventions: pot_i = sum_j q_j R(r_i - r_j) (all j, including j = i: R is smooth at 0 and
 * R(0) is the self-energy of i with its far images), E_i = -grad pot_i. The monopole (sheet
 * field of a net-charged layer) is kept exactly, nothing is neutralised. Because R is even,
 * the exact far field exerts zero total force on the cell: sum_i q_i E_i = 0 (the
 * interpolated one does so to the interpolation accuracy).
 *
 * Requirements: images >= 1 (with images = 0 the kernel is singular inside the cell
 * difference domain); positions inside the primary cell and the stored z range (a margin
 * of 1% of the cell size is tolerated, beyond it evaluate throws std::invalid_argument).
 */
class PeriodicFarField {
 public:
  //! Largest cell aspect ratio max(lx, ly) / min(lx, ly) accepted by setup(); column heights
  //! are limited by their cost only (kMaxSetupBytes; H / L = 160 is tested).
  static constexpr double kMaxAspect = 2.0;

  //! setup() truncates each operator block's low-rank factorisation at this times the
  //! accuracy, relative to the scale of the blocks of its offset: a block's error then adds at
  //! most ~1e-6 x accuracy x (offset in boxes) of the sheet field (doc/theory.md, after eq. (4.6))
  static constexpr double kCompressionPerAccuracy = 1e-6;
  //! largest block (p^2 pz / 4 rows) that setup() factorises; larger ones stay dense
  static constexpr int kMaxCompressedBlock = 256;

  //! Largest peak memory of a set-up (dense operator blocks, kernel table and node
  //! differences, held at once before the blocks are compressed; setup_bytes() estimates it),
  //! per caller (each MPI rank of the LAMMPS fix holds a copy). The bound admits the columns
  //! of a deposition at the accuracies it uses and refuses, with a message, the columns whose
  //! set-up would exhaust a node's memory: the cost grows linearly with the column's height.
  //! Then setup() throws FarFieldTooLarge (doc/fmm-far-field.md, "Column height", which has
  //! the measured memory and time per height and accuracy).
  static constexpr double kMaxSetupBytes = 1024.0 * 1024 * 1024;

  /// @brief Estimated peak bytes of setup_explicit() for these parameters (what
  /// kMaxSetupBytes limits); `boxes` receives the number of boxes of the padded column.
  static double setup_bytes(double lx, double ly, double zlo, double zhi, int pxy, int pz,
                            double hz_max, int *boxes = nullptr);

  /**
   * @brief Precompute the operator.
   * @param x0,y0,lx,ly primary cell [x0,x0+lx) x [y0,y0+ly)
   * @param zlo,zhi     z range containing all particles (stored padded by
   *                    0.1 (zhi - zlo) + 0.1 min(lx, ly) on each side)
   * @param images      near-block shells handled by the caller (>= 1)
   * @param accuracy    requested relative RMS accuracy of the far field, in [1e-8, 1)
   * @throws std::invalid_argument on bad arguments, and for cells with
   *         max(lx, ly) / min(lx, ly) > kMaxAspect (the accuracy is not met there);
   *         FarFieldTooLarge (before allocating) if setup_bytes() exceeds kMaxSetupBytes
   */
  void setup(double x0, double y0, double lx, double ly, double zlo, double zhi, int images,
             double accuracy);

  /// @brief true when the stored operator does not cover this geometry (different cell, z
  /// range outside the stored one or much smaller than it, other images or accuracy).
  bool needs_setup(double x0, double y0, double lx, double ly, double zlo, double zhi, int images,
                   double accuracy) const;

  /**
   * @brief ADDS far-field potential and field at targets i in [begin, end).
   * Sources are all n particles (inside the primary cell). pot, ex, ey, ez are indexed by
   * particle (length >= end); pot may be null.
   * With a PartSum, work partition `part` of `nparts` anterpolates only its share of the node
   * charges (a contiguous block of the x nodes) and `sum` completes them; without one every
   * caller anterpolates them all. Either way the node charges are bit-identical.
   * @throws std::logic_error if setup was not called; std::invalid_argument if a particle
   *         lies outside the stored geometry.
   */
  void evaluate(std::size_t n, const double *x, const double *y, const double *z, const double *q,
                std::size_t begin, std::size_t end, double *pot, double *ex, double *ey,
                double *ez, int part = 0, int nparts = 1, const PartSum &sum = nullptr) const;

  /**
   * @brief evaluate() with point dipoles among the sources and, optionally, the field gradient
   * at the targets (doc/polarization.md, section 5.3): a dipole p at y is anterpolated as
   * p . grad_y of the interpolation weights (the limit of two opposite charges), and the
   * gradient G_ab = dE_a/dx_b is the interpolant's second derivative. q, px, py, pz may each
   * be null (none); g6 (6 per particle: xx, xy, xz, yy, yz, zz, indexed like ex) may be null.
   * Every caller anterpolates all sources (no PartSum).
   * @throws as evaluate().
   */
  void evaluate_dipoles(std::size_t n, const double *x, const double *y, const double *z, const double *q,
                        const double *px, const double *py, const double *pz, std::size_t begin, std::size_t end,
                        double *pot, double *ex, double *ey, double *ez, double *g6) const;

  /**
   * @brief The source half of evaluate(), for a source set that stays fixed while the targets
   * move (StaticSourceField): the node potentials Phi_t of every box t of the column
   * (doc/theory.md, eq. (4.6): anterpolation W_b, then Phi_t = sum_b K_{t-b} W_b), the same
   * code path as evaluate(). phi receives p^2 pz x boxes() doubles (all zero without charge).
   * Cost O(n p^2 pz) plus the operator from the source boxes to all boxes.
   * @throws std::logic_error if setup was not called; std::invalid_argument if a source lies
   *         outside the stored geometry.
   */
  void node_potentials(std::size_t n, const double *x, const double *y, const double *z, const double *q,
                       std::vector<double> &phi) const;

  /**
   * @brief The target half: ADDS the far-field potential and field interpolated from node
   * potentials of node_potentials() (this set-up) at the points (x, y, z)[0, n), which need
   * not be the sources; pot may be null. Cost O(n p^2 pz), independent of the sources.
   * @throws std::logic_error if setup was not called; std::invalid_argument if phi is not of
   *         this set-up's size or a point lies outside the stored geometry.
   */
  void interpolate_at(const std::vector<double> &phi, std::size_t n, const double *x, const double *y,
                      const double *z, double *pot, double *ex, double *ey, double *ez) const;

  /// @brief Estimated relative RMS error of the far field: the larger of the error measured
  /// for these parameters in the calibration (setup only) and 20 x the RMS error of the
  /// interpolated kernel gradient over random sample pairs divided by the sheet field
  /// 2 pi / A of a unit charge (the factor 20 covers the ratios seen in calibration).
  double estimated_error() const { return est_error_; }

  int order_xy() const { return pxy_; }           //!< Chebyshev nodes per box in x and y
  int order_z() const { return pz_; }             //!< Chebyshev nodes per box in z
  int boxes() const { return nb_; }               //!< number of boxes in the column
  double box_height() const { return hz_; }       //!< height of one box
  double stored_zlo() const { return zlo_; }      //!< lower end of the stored (padded) z range
  double stored_zhi() const { return zhi_; }      //!< upper end of the stored (padded) z range
  double setup_seconds() const { return setup_s_; }  //!< wall time of the last setup
  std::size_t memory_bytes() const;               //!< bytes held by the operator
  bool ready() const { return nb_ > 0; }          //!< setup has been called

  /// @brief Choice of (p, pz, hz / min(lx, ly)) for a requested accuracy (used by setup).
  static void parameters_for(double accuracy, int *pxy, int *pz, double *hz_over_l);

  /// @brief Instruction-set path of the per-particle work (anterpolation, interpolation);
  /// every path gives the same result bit for bit. Default: gcsimd::default_simd_path().
  void set_simd_path(gcsimd::SimdPath path) { simd_path_ = path; }
  gcsimd::SimdPath simd_path() const { return simd_path_; }

  /// @brief Setup with explicit interpolation parameters (tests and tuning).
  void setup_explicit(double x0, double y0, double lx, double ly, double zlo, double zhi,
                      int images, int pxy, int pz, double hz_max);

 private:
  // Lagrange weights s, their derivatives ds and (if d2s is not null) second derivatives d2s
  static void interp_weights(double t, int p, const double *tab, double *s, double *ds, double *d2s = nullptr);
  // node charges -> node potentials, (p^2 pz) x nb, from the source boxes [src_lo, src_hi) at
  // the target boxes [tgt_lo, tgt_hi) only (the other columns of phi are zero)
  void apply(const double *w, double *phi, int src_lo, int src_hi, int tgt_lo, int tgt_hi) const;
  // node charges W (p^2 pz x nb, x nodes a in [a0, a1) only) of the charges, and the box
  // spans holding any particle (tgt) and any nonzero charge (src); [lo, hi) = [nb, 0) if none
  void anterpolate(std::size_t n, const double *x, const double *y, const double *z, const double *q, int a0,
                   int a1, std::vector<double> &w, int *src_lo, int *src_hi, int *tgt_lo, int *tgt_hi) const;
  // interpolate() with the field gradient g6 (6 per particle) too
  void interpolate_gradient(const double *phi, const double *x, const double *y, const double *z, std::size_t begin,
                            std::size_t end, double *pot, double *ex, double *ey, double *ez, double *g6) const;
  int locate(std::size_t i, double x, double y, double z, double *tx, double *ty, double *tz) const;
  // per-thread work arrays of anterpolate() and interpolate(), and the particles sorted by box
  struct FarFieldScratch;
  static FarFieldScratch &far_field_scratch();
  void sort_by_box(std::size_t begin, std::size_t end, const double *x, const double *y, const double *z,
                   const double *q, FarFieldScratch &scratch) const;
  void interpolate(const double *phi, const double *x, const double *y, const double *z,
                   std::size_t begin, std::size_t end, double *pot, double *ex, double *ey,
                   double *ez) const;
  double sample_error() const;
  // the sampled kernel error times this is the estimate (the ratio of the far-field error to
  // the sample in the calibration scan: doc/fmm-far-field.md)
  static constexpr double kSampleToError = 20.0;
  // the uncompressed operator of a column (setup and setup_explicit; no error estimate)
  void build_operator(double x0, double y0, double lx, double ly, double zlo, double zhi,
                      int images, int pxy, int pz, double hz_max);
  // replace each block by a truncated low-rank factorisation U W where that halves the work
  void compress(double rel_tol);

  double x0_ = 0, y0_ = 0, lx_ = 0, ly_ = 0;  //!< primary cell
  double zlo_ = 0, zhi_ = 0;                  //!< stored (padded) z range
  int images_ = -1;                           //!< near-block shells excluded
  double accuracy_ = 0;                       //!< requested accuracy
  int pxy_ = 0, pz_ = 0, nb_ = 0;             //!< nodes per box, boxes
  double hz_ = 0;                             //!< box height
  double est_error_ = 0;                      //!< sampled relative kernel error
  double setup_s_ = 0;                        //!< set-up wall time
  std::vector<std::vector<double>> ops_;      //!< blocks K_{o,s} (column-major) at 4 o + s, o = 0 .. nb-1,
                                              //!< or U (nh x r) then W (r x nh) where rank_ < nh
  std::vector<int> rank_;                     //!< rank of each stored block (nh: dense)
  std::vector<double> tab_xy_, tab_z_;        //!< T_k(t_i) at the Chebyshev nodes
  gcsimd::SimdPath simd_path_ = gcsimd::default_simd_path();  //!< path of the per-particle work
};

}  // namespace gcfmm

#endif
