// gravcal/methods/effect_fit.h: the static-position fit of the model with optional
// effects (model_effects.h), by Ceres.
//
// Accelerometer: minimises sum_k r_k^2 over b, the free entries of U and the
// parameters of the accelerometer effects switched on, with r_k the
// GravityMagnitudeResidual (with effects) of each position:
//
//   r_k = ( |h^-1( U (v_k - b), dT_k, dt_k )| - g ) / sigma_k
//
// sigma_k from the position's own covariance of the mean (refinement.h).
// Gyroscope (when the positions have it): minimises sum_k |L_k^-1 e_k|^2,
//
//   e_k = u_k - b_g - (G f_k + gamma dT_k + eta dt_k),
//
// u_k the mean raw gyroscope reading of position k, L_k L_k^T its covariance
// of the mean, f_k the fitted specific force of the position. The rotation R
// of the accelerometer model is kept (the magnitude cannot see it); the
// gyroscope's scale matrix is not estimated (static data cannot see it).
// Standard deviations are from (J^T J)^-1 of the whitened Jacobian; chi2 /
// dof says whether the sigmas and the model fit the data.
#ifndef GRAVCAL_METHODS_EFFECT_FIT_H_
#define GRAVCAL_METHODS_EFFECT_FIT_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "gravcal/core/accel_model.h"
#include "gravcal/core/gyro_model.h"
#include "gravcal/core/model_effects.h"
#include "gravcal/core/position.h"
#include "gravcal/detection/static_detector.h"
#include "gravcal/estimation/solver_tolerances.h"
#include "gravcal/methods/twelve_position.h"

namespace gravcal {

// One static position with what the effect fit needs.
struct StaticObservation {
  // Mean raw accelerometer vector, its covariance, times, temperature (NaN
  // when the log has none).
  Position accel;
  bool has_gyro = false;
  // Mean raw gyroscope vector and the covariance of that mean.
  Eigen::Vector3d gyro_mean = Eigen::Vector3d::Zero();
  Eigen::Matrix3d gyro_mean_cov = Eigen::Matrix3d::Identity();

  // Middle of the interval, s.
  double time() const { return 0.5 * (accel.t_begin + accel.t_end); }
  double temperature() const { return accel.temperature; }
};

// One observation per interval (the accelerometer part as
// PositionsFromIntervals makes it).
std::vector<StaticObservation> ObservationsFromIntervals(
    const std::vector<StaticInterval>& intervals, bool has_gyro);

struct EffectFitOptions {
  // The baseline accelerometer model: kScale holds the off-diagonal of U at
  // zero (unless accel_misalignment is in `effects`); kAffine fits like
  // kScaleMisalignment and keeps R.
  AccelParameterization parameterization = AccelParameterization::kScaleMisalignment;
  std::vector<Effect> effects;
  // Fit the gyroscope part (when the observations have it).
  bool fit_gyro = true;
  // Skip the accelerometer part (keep `initial` and its effects): for
  // refits of a gyroscope effect alone.
  bool fit_accel = true;
  bool compute_covariance = true;

  // Stopping rules of the Ceres solve.
  SolverTolerances solver = {50, 1e-12, 1e-12, 1e-10};

  bool IsValid(std::string* error) const;
};

// The statistics of one sensor's part of the fit.
struct SensorFitSummary {
  bool fitted = false;
  bool converged = false;
  // Scalar residuals (one per position for the accelerometer, three for the
  // gyroscope) and free parameters.
  int num_residuals = 0;
  int num_parameters = 0;
  // Sum of squared whitened residuals.
  double chi2 = 0.0;
  int dof() const { return num_residuals - num_parameters; }
  // Standard deviation of the named parameter from the covariance; NaN
  // when it was not estimated or no covariance was computed.
  double Std(const std::string& name) const;
  std::vector<std::string> parameter_names;
  // (J^T J)^-1 of the free parameters, parameter_names order.
  Eigen::MatrixXd covariance;
  // Parameters the positions do not determine (null space of J), and the
  // rank of J (num_parameters when all are determined; only computed with
  // the covariance).
  std::vector<std::string> undetermined;
  int rank = 0;
  // Leverage of each position, diag of J (J^T J)^+ J^T (the largest of its
  // three rows for the gyroscope): near 1, the other positions do not
  // determine the model without it, so it cannot be predicted by them.
  // Only computed with the covariance.
  std::vector<double> leverage;
  int iterations = 0;
  // Which information the fit used, in plain words for the reports (for
  // example "position magnitudes" or "position magnitudes + within-pose
  // trends"); empty when the sensor was not fitted.
  std::string information;
};

struct EffectFitResult {
  AccelModel accel;
  // Bias only (the matrix stays identity: not seen at rest).
  GyroModel gyro;
  // Values of the effects switched on; the rest zero. Reference temperature
  // and time as given.
  EffectParameters parameters;
  std::vector<Effect> effects;
  SensorFitSummary accel_fit;
  SensorFitSummary gyro_fit;
  // Standard deviations of b (raw units), b_g (raw units) and each effect.
  Eigen::Vector3d accel_bias_std = Eigen::Vector3d::Constant(NAN);
  Eigen::Vector3d gyro_bias_std = Eigen::Vector3d::Constant(NAN);
  std::vector<EffectEstimate> estimates;
  // Per position: |a_k| - g (m/s^2) and sigma_k; the calibrated force a_k;
  // the gyroscope residual e_k and sqrt of the diagonal of its covariance
  // (raw units).
  std::vector<double> accel_residuals;
  std::vector<double> accel_sigmas;
  std::vector<Eigen::Vector3d> forces;
  std::vector<Eigen::Vector3d> gyro_residuals;
  std::vector<Eigen::Vector3d> gyro_sigmas;
  std::vector<std::string> warnings;
  std::string message = "FitEffects was not called";
};

// Fits from `initial` (accelerometer model, gyroscope bias and effect values;
// `initial_parameters` also carries T_ref and t_ref). Returns false on
// invalid options or input (message says which); a fit that does not
// converge returns true with accel_fit.converged = false.
bool FitEffects(const std::vector<StaticObservation>& observations, const AccelModel& initial,
                const GyroModel& initial_gyro, const EffectParameters& initial_parameters,
                double gravity, const EffectFitOptions& options, EffectFitResult* result);

// |a| - g of one position under a fitted model (m/s^2), and the sigma of
// that residual; for cross-validation on a position left out of the fit.
double AccelResidual(const EffectFitResult& fit, const StaticObservation& observation,
                     double gravity, Eigen::Vector3d* force);
double AccelSigma(const EffectFitResult& fit, const StaticObservation& observation);

// The gyroscope residual e of one position (raw units) and its whitened
// squared norm.
Eigen::Vector3d GyroResidual(const EffectFitResult& fit, const StaticObservation& observation,
                             const Eigen::Vector3d& force, double* whitened_squared);

// Adds `effects` to a finished calibration of `log` (CalibrateAccelerometer
// with `options`, which detected `intervals`): fits the model with them from the calibration's
// model and replaces the accelerometer bias, U, their standard deviations and covariance, the
// residuals, and (for gyroscope effects) the gyroscope bias; fills calibration->effects. The
// rotation R is kept. Returns false with calibration->message when the effects cannot be fitted
// (not identified by the positions, no temperature, no gyroscope, too few positions).
bool FitCalibrationEffects(const ImuLog& log, const std::vector<StaticInterval>& intervals,
                           const CalibrationOptions& options, const std::vector<Effect>& effects,
                           Calibration* calibration);

}  // namespace gravcal

#endif  // GRAVCAL_METHODS_EFFECT_FIT_H_
