// GRANULAR-CHARGED FMM core library (gcfmm).
// User options of the solver, the rule that turns `accuracy` into (order, theta, leaf), and the
// accuracy's owner: the share each part of an evaluation gets and the finest request these
// options reach (reachable_accuracy()).
#ifndef GCFMM_OPTIONS_HPP
#define GCFMM_OPTIONS_HPP

#include <cmath>

namespace gcfmm {

//! Boundary conditions. Periodic2D: periodic in x and y, open in z.
enum class Boundary { Free, Periodic2D };
//! Treatment of the image cells beyond the `images` shells (Periodic2D only).
enum class FarField { None, Average, Exact };

//! Largest expansion order accepted by Options::validate().
inline constexpr int kMaxOrder = 30;
// lowest order the automatic choice takes (p = 1 leaves too few terms for the error model)
inline constexpr int kMinAutoOrder = 2;
//! Finest accuracy the exact periodic far field is calibrated for (its last parameter set,
//! doc/fmm-far-field.md); finer requests get this set.
inline constexpr double kFinestFarFieldAccuracy = 1e-8;

//! Solver options. Zero means "choose from accuracy" for order, theta and leaf.
struct Options {
  double accuracy = 1e-4;  //!< requested relative RMS force error
  int order = 0;           //!< expansion order p; 0 = choose from accuracy
  double theta = 0.0;      //!< opening angle of the MAC; 0 = choose from accuracy
  int leaf = 0;            //!< max particles per leaf; 0 = choose
  int images = 1;          //!< shells of periodic image cells in the near field (1 = 3x3 block)
  Boundary boundary = Boundary::Free;  //!< boundary conditions
  FarField farfield = FarField::Exact; //!< far field beyond the shells (Periodic2D only)
  double bed_zlo = NAN;  //!< bed bottom for FarField::Average; NaN = min z of charged particles
  double bed_zhi = NAN;  //!< bed top for FarField::Average; NaN = max z of charged particles
  //! A static part beside a Solver over the other charges (a split of one charge set,
  //! static_field.hpp): the fraction of `accuracy` it runs at (static_part_options()); the two
  //! parts' errors add, so each keeps a share of the request
  double static_share = 0.5;
  //! PolarizableSolver: residual of the induction solve (polarization.hpp); 0 = 0.1 x accuracy
  //! (induction_tolerance())
  double induction_tolerance = 0.0;

  /** @brief Check every field; throws std::invalid_argument naming the bad field and value. */
  void validate() const;
};

//! Parameters actually used, derived from Options by resolve().
struct Resolved {
  int order = 0;                 //!< expansion order p
  double theta = 0.0;            //!< MAC opening angle
  int leaf = 0;                  //!< max particles per leaf
  double estimated_error = 0.0;  //!< predicted relative RMS force error of the near field
};

/** @brief Apply the error-control rule (doc/theory.md, eq. (3.15)) to the options.
 *  @param opts validated options
 *  @return order, theta and leaf (explicit user values are kept) and the predicted error */
Resolved resolve(const Options &opts);

/** @brief Predicted relative RMS force error of the calibrated model for (order, theta). */
double predicted_error(int order, double theta);

/** @brief The accuracy the exact periodic far field is set up for: Options::accuracy, but not
 *  below kFinestFarFieldAccuracy (the finest calibrated set; its far field is smooth and small,
 *  so a finer request gets that set). Solver and StaticSourceField both take it from here. */
double far_field_accuracy(const Options &opts);

/** @brief The factor by which induced dipoles tighten the expansions' accuracy at a request
 *  (doc/benchmarks.md, "Induced dipoles"): their forces G p need the field gradient, whose
 *  error at a given order is larger than the field's; 8 down to 1e-5, 16 below, where the
 *  exact far field's gradient needs the tighter margin to deliver the request. */
double dipole_accuracy_margin(double accuracy);

/** @brief The options of the static part of a split (Solver over the moving charges +
 *  StaticSourceField over the fixed ones, at the moving ones): accuracy x static_share, so
 *  that the sum of the two parts meets opts.accuracy. */
Options static_part_options(const Options &opts);

/** @brief PolarizableSolver's induction residual: Options::induction_tolerance, or 0.1 x
 *  accuracy when it is 0 (doc/polarization.md, section 6). */
double induction_tolerance(const Options &opts);

//! The share of Options::accuracy that one pair's term of the P2P may carry (p2p_term_tolerance()).
constexpr double kP2PTermShare = 1e-2;

/** @brief The relative error one pair's field term of the P2P may carry (p2p_kernel_within(),
 *  kernels.hpp): kP2PTermShare x accuracy when the order is chosen from accuracy; 0 (full
 *  precision) with an explicit order, which accuracy does not govern. A target's P2P error is
 *  then at most that share of the sum of its terms' magnitudes, the unsigned scale the request
 *  is measured against where fields cancel; the terms all err the same way (the Newton steps
 *  approach 1/sqrt(r2) from below), so the errors do not average out and that bound is the one
 *  to count on (doc/fmm-accuracy.md, "P2P precision"). */
double p2p_term_tolerance(const Options &opts);

//! What sets the finest accuracy some options reach (reachable_accuracy()).
enum class AccuracyLimit {
  None,           //!< an explicit order: accuracy does not choose it, every request is taken
  MaxOrder,       //!< the error model at kMaxOrder and the resolved theta
  ExactFarField,  //!< the exact periodic far field's finest calibrated set, kFinestFarFieldAccuracy
};

//! The parts an evaluation at Options::accuracy runs besides the charges' field.
struct AccuracyParts {
  bool dipoles = false;         //!< induced dipoles (PolarizableSolver with polarizabilities)
  bool static_sources = false;  //!< a static part beside the Solver (static_part_options())
};

//! The finest request some options deliver, and why not finer.
struct ReachableAccuracy {
  double accuracy = 0.0;   //!< the finest request delivered (0: every request, AccuracyLimit::None)
  AccuracyLimit limit = AccuracyLimit::None;  //!< what sets the charges' finest expansions
  double charges = 0.0;    //!< the charges' finest: the model at (order, theta) or the far-field floor
  int order = 0;           //!< kMaxOrder (MaxOrder, ExactFarField)
  double theta = 0.0;      //!< the resolved theta
  double dipole_margin = 1.0;  //!< dipole_accuracy_margin() at the request (1: no dipoles)
  double static_share = 1.0;   //!< Options::static_share (1: no static part)
};

/** @brief The finest accuracy these options can reach with these parts, and why. With the
 *  order chosen from accuracy (order 0): the charges' finest (the model at kMaxOrder and the
 *  resolved theta; with Periodic2D and FarField::Exact not below kFinestFarFieldAccuracy),
 *  times the dipoles' margin (their expansions run that much finer) or over the static part's
 *  share (it runs at that fraction of the request), whichever is larger. With an explicit
 *  order: 0 (the user's choice). A finer request would be served with a larger error than
 *  asked: callers refuse it, naming this value. */
ReachableAccuracy reachable_accuracy(const Options &opts, const AccuracyParts &parts = {});

}  // namespace gcfmm

#endif
