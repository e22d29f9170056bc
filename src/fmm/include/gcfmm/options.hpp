// GRANULAR-CHARGED FMM core library (gcfmm).
// User options of the solver and the rule that turns `accuracy` into (order, theta, leaf).
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

/** @brief The finest accuracy these options deliver: with the order chosen from accuracy
 *  (order 0), the model's error at kMaxOrder and the resolved theta, and with Periodic2D and
 *  FarField::Exact at least kFinestFarFieldAccuracy; with an explicit order 0 (accuracy does
 *  not choose the order then). A finer request would be served with a larger error. */
double finest_accuracy(const Options &opts);

/** @brief Predicted relative RMS force error of the calibrated model for (order, theta). */
double predicted_error(int order, double theta);

}  // namespace gcfmm

#endif
