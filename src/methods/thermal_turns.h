// methods/thermal_turns.h (private): the gyroscope's scale against
// temperature from the turns between the static poses of a thermal session
// (issue 35, part 3), after the static fit (thermal_calibration.h) has given
// the accelerometer and the gyroscope's bias(T).
//
// A turn runs from the end of one static interval to the start of the
// next (edge_seconds of each interval's end included, as the static
// detector lets a slow start of a motion in). Its bias-free raw rates
// ubar_i = u_i - b_g - db_g(x) (x the turn's temperature offset, lag
// included as in the static fit) give the body rate
//
//   w_i = (I + D_g(x))^-1 M_g ubar_i,   D_g(x) = diag(p_x(x), p_y(x), p_z(x))
//
// (thermal_model.h; D_g's off-diagonal, the misalignment's change with
// temperature, is not fitted), and the integrated turn R = prod_i
// Exp(A int_i ubar dt) (A = (I + D_g)^-1 M_g, the integral over each
// sample interval by a fourth-order formula) must carry the calibrated gravity
// direction d_s of the pose before into d_e after it:
//
//   e = E (R^T d_s - d_e) / sigma,   E: 2 x 3 basis orthogonal to d_e
//   sigma^2 = (t_s + t_e) + q^2 |M_g|^2 h T + (s_b T)^2
//
// t_s, t_e the tangent variance of the two poses' directions (each window's
// covariance of the mean through U, over g^2), q^2 the gyroscope's white
// noise variance per sample (pooled over the windows), h the sample period,
// T the turn's duration, s_b the bias's standard deviation (rad/s).
//
// Parameters: M_g (3 x 3, the base model at T_ref in the accelerometer's
// frame, raw to rad/s) and the three scale polynomials. A turn about
// gravity leaves gravity in place and carries nothing; turns about the
// three axes determine M_g (Tedaldi et al. 2014, as gyro_calibration.h).
// The order of the scale term is chosen by the same criterion as the
// static terms, up to what the turns' own temperature span supports
// (ThermalMaxOrderForSpan). The covariance is (J^T J)^-1 scaled by
// max(1, chi^2 / dof).
#ifndef GRAVCAL_METHODS_THERMAL_TURNS_H_
#define GRAVCAL_METHODS_THERMAL_TURNS_H_

#include <Eigen/Core>
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
  // The gyroscope's scale term (order 0 when off or undetermined).
  ThermalPolynomial scale;
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

// Fits M_g and the gyroscope's scale(T) to `turns`. `gyro_noise_variance`:
// q^2 above (raw units^2); `nominal`: the starting scale (rad/s per raw
// unit). Fills `fit` (with notes when the turns are too few or do not
// cover the span).
void FitThermalTurns(const std::vector<ThermalTurn>& turns, double gyro_noise_variance,
                     double nominal, const ThermalCalibrationOptions& options, ThermalTurnFit* fit);

// The turns' step of CalibrateThermal: with the static fit in `out`
// (accelerometer, gyroscope bias and their thermal terms), fits the turns
// of `log` and, when they determine it, sets out->gyro's matrix and its
// standard deviations and the gyroscope's scale term; adds the notes.
void AddThermalTurns(const ImuLog& log, const std::vector<StaticInterval>& intervals,
                     const std::vector<ThermalWindow>& windows,
                     const ThermalCalibrationOptions& options, Calibration* out);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_METHODS_THERMAL_TURNS_H_
