// methods/thermal_turns.h (private): the gyroscope's scale and misalignment
// against temperature from the turns between the static poses of a thermal session
// (issue 35, part 3), after the static fit (thermal_calibration.h) has given
// the accelerometer and the gyroscope's bias(T).
//
// A turn runs from the end of one static interval to the start of the
// next (edge_seconds of each interval's end included, as the static
// detector lets a slow start of a motion in). Its bias-free raw rates
// ubar_i = u_i - b_g - db_g(x) (x the turn's temperature offset, lag
// included as in the static fit) give the body rate
//
//   w_i = (I + D_g(x))^-1 M_g ubar_i
//
// (thermal_model.h: D_g = diag(scale polynomials) + the six misalignment
// polynomials off the diagonal), and the integrated turn R = prod_i
// Exp(A int_i ubar dt) (A = (I + D_g)^-1 M_g, the integral over each
// sample interval by a fourth-order formula) must carry the calibrated gravity
// direction d_s of the pose before into d_e after it:
//
//   e = E (R^T d_s' - d_e') / sigma,   E: 2 x 3 basis orthogonal to d_e
//   d' = N d / |N d|,   N = [1 n01 n02; 0 1 n12; 0 0 1]
//
// N: the accelerometer's non-orthogonality (U's off-diagonal; M_g is in the
// frame N U, U itself keeps the static fit's 0 there for now) where
// the static poses leave it open (six faces do: a pose along one axis does
// not see it, to first order); the turns' angles between the faces measure
// it (Tedaldi et al. 2014 calibrate the two sensors' frames jointly). An
// open entry the turns cannot tell from M_g (the same face order every
// time) would make the fit wander along that valley: it is held at 0 and
// considered instead, with a spread of 0.01 rad (an accelerometer's
// cross-axis sensitivity, about 1 %), in the covariance of the rest. Where
// the static fit determined an entry, it is held (n = 0).
//   sigma^2 = (t_s + t_e) + q^2 |M_g|^2 h T + (s_b T)^2
//
// t_s, t_e the tangent variance of the two poses' directions (each window's
// covariance of the mean through U, over g^2), q^2 the gyroscope's white
// noise variance per sample (pooled over the windows), h the sample period,
// T the turn's duration, s_b the bias's standard deviation (rad/s).
//
// Parameters: M_g (3 x 3, the base model at T_ref in the accelerometer's
// frame, raw to rad/s), the three scale and six misalignment polynomials
// and N's open entries. A turn about
// gravity leaves gravity in place and carries nothing; turns about the
// three axes determine M_g (Tedaldi et al. 2014, as gyro_calibration.h).
// The orders of the scale term, then of the misalignment term, are chosen
// by the same criterion as the static terms, up to what the turns' own
// temperature span supports (ThermalMaxOrderForSpan). The covariance is (J^T J)^-1 scaled by
// max(1, chi^2 / dof).
#ifndef GRAVCAL_METHODS_THERMAL_TURNS_H_
#define GRAVCAL_METHODS_THERMAL_TURNS_H_

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "gravcal/core/accel_model.h"
#include "gravcal/core/calibration.h"
#include "gravcal/core/imu_log.h"
#include "gravcal/core/thermal_model.h"
#include "gravcal/detection/static_detector.h"
#include "gravcal/methods/thermal_calibration.h"

namespace gravcal {
namespace internal {

// One turn between consecutive static intervals.
struct ThermalTurn {
  // Calibrated gravity directions before and after (unit, sensor frame).
  Eigen::Vector3d from = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d to = Eigen::Vector3d::UnitZ();
  // The direction noise beside the gyroscope's: t_s + t_e, rad^2.
  double direction_variance = 0.0;
  // Duration (s), temperature (degC) and its offset x from T_ref.
  double seconds = 0.0;
  double temperature = 0.0;
  double x = 0.0;
  // Bias-free raw rates ubar_i, the sample times and the integral of the
  // rates over each sample interval (fourth-order quadrature).
  std::vector<Eigen::Vector3d> rates;
  std::vector<double> t;
  std::vector<Eigen::Vector3d> increments;
};

// What the turns gave.
struct ThermalTurnFit {
  // The base matrix was estimated (else M_g stays at the nominal scale).
  bool matrix_estimated = false;
  Eigen::Matrix3d matrix = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d matrix_std = Eigen::Matrix3d::Constant(NAN);
  // The gyroscope's scale and misalignment terms (order 0 when off or
  // undetermined).
  ThermalPolynomial scale;
  ThermalPolynomial misalignment;
  // N's entries n01, n02, n12 (header) that the turns determine (std below
  // 0.01 rad): which, their values and standard deviations (rad).
  std::array<bool, 3> frame_fitted = {false, false, false};
  Eigen::Vector3d frame = Eigen::Vector3d::Zero();
  Eigen::Vector3d frame_std = Eigen::Vector3d::Constant(NAN);
  // The open entries the turns do not determine either: held at 0, their
  // spread (0.01 rad) considered in the covariance.
  std::array<bool, 3> frame_considered = {false, false, false};
  int turns = 0;
  // The turns' temperature span, degC.
  double span = 0.0;
  double chi2 = NAN;
  int dof = 0;
  // What the turns determined and what not, one sentence each.
  std::vector<std::string> notes;
};

// The turns of `log` between consecutive `intervals` (time order), with the
// accelerometer (`accel`, `model`'s accelerometer terms) and the
// gyroscope's bias (`gyro_bias`, `model`'s gyroscope bias term) of the
// static fit. `windows` give the poses' directions and noise.
std::vector<ThermalTurn> ThermalTurns(const ImuLog& log,
                                      const std::vector<StaticInterval>& intervals,
                                      const std::vector<ThermalWindow>& windows,
                                      const AccelModel& accel, const Eigen::Vector3d& gyro_bias,
                                      const ThermalModel& model, double gyro_bias_std);

// Fits M_g, the gyroscope's scale(T) and misalignment(T) and N's entries
// flagged in `frame` (n01, n02, n12) to `turns`. `gyro_noise_variance`:
// q^2 above (raw units^2); `nominal`: the starting scale (rad/s per raw
// unit). Fills `fit` (with notes when the turns are too few or do not
// cover the span).
void FitThermalTurns(const std::vector<ThermalTurn>& turns, double gyro_noise_variance,
                     double nominal, const ThermalCalibrationOptions& options,
                     const std::array<bool, 3>& frame, ThermalTurnFit* fit);

// The turns' step of CalibrateThermal: with the static fit in `out`
// (accelerometer, gyroscope bias and their thermal terms), fits the turns
// of `log` and, when they determine it, sets out->gyro's matrix and its
// standard deviations and the gyroscope's scale and misalignment terms;
// adds the notes (N among them).
void AddThermalTurns(const ImuLog& log, const std::vector<StaticInterval>& intervals,
                     const std::vector<ThermalWindow>& windows,
                     const ThermalCalibrationOptions& options, Calibration* out);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_METHODS_THERMAL_TURNS_H_
