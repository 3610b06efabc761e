// gravcal/methods/effect_fit.h: the static-position fit of the model with optional
// effects (model_effects.h), by Ceres.
//
// Accelerometer: minimises sum_k r_k^2 over b, the free entries of U and the
// parameters of the accelerometer effects switched on, with r_k the
// GravityMagnitudeResidual (with effects) of each position:
//
//   r_k = ( |h^-1( U (v_k - b), dT_k, dt_k )| - g ) / sigma_k
//
// sigma_k from the position's own covariance of the mean (refinement.h),
// plus, with use_within_pose_trends and for every position whose
// observation carries a within-pose trend, the AccelTrendResidual
// (residuals/accel_trend_residual.h): three whitened values (or, with
// WithinPoseTrendOptions::along_gravity_only, the one along the pose's
// mean direction) comparing the
// slope of the raw mean against time within the pose with the slope the
// temperature and drift terms predict,
//
//   t_k = W_k ( ghat_k - U^-1 ((c q_k + beta) Tdot_k + delta) ).
//
// Its noise is from the pose's batch means about their line,
// pooled over the poses (src/methods/within_pose_trend.h). These are more
// residuals per pose that see beta, c and delta directly, so
// a twelve-position session can test and estimate them; the quadratic term
// and the model's bias, scale and non-orthogonality predict no trend.
// With use_between_pose_rotations, also the AccelRotationResidual
// (residuals/accel_rotation_residual.h) of every turn between consecutive
// poses: two whitened values saying how far the gyroscope's integrated turn
// misses carrying the corrected direction of one pose to that of the next,
// with the gyroscope's M_g and b_g estimated alongside (weights:
// src/methods/between_pose_rotations.h). The directions see what the
// magnitudes cannot: on the seed's twelve poses the quadratic term of z.
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
#include <utility>
#include <vector>

#include "gravcal/core/accel_model.h"
#include "gravcal/core/gyro_model.h"
#include "gravcal/core/imu_log.h"
#include "gravcal/core/model_effects.h"
#include "gravcal/core/position.h"
#include "gravcal/core/solver_result.h"
#include "gravcal/detection/static_detector.h"
#include "gravcal/estimation/fit_settings.h"
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
  // The within-pose trend (AccelTrendResidual): slope of the raw
  // accelerometer mean against time, raw units per second, its covariance,
  // and the slope of the temperature, degC per second (0 without a
  // temperature column). has_trend is false for a pose too short for it or
  // when the observations were made without the log's samples.
  bool has_trend = false;
  Eigen::Vector3d accel_slope = Eigen::Vector3d::Zero();
  Eigen::Matrix3d accel_slope_cov = Eigen::Matrix3d::Identity();
  double temperature_slope = 0.0;
  // The trend is used along the pose's mean direction only (one row, for
  // gravity; WithinPoseTrendOptions::along_gravity_only).
  bool trend_along_gravity = false;
  // The pose's place in its session (0, 1, ...; -1 unknown) and the turn
  // into it from the session's previous pose: the samples from the last one
  // of that pose to the first of this one (AddBetweenPoseTurns). A rotation
  // row joins two observations only when their session indices are
  // consecutive, so leaving a pose out drops both of its turns.
  int session_index = -1;
  bool has_turn = false;
  std::vector<double> turn_t;
  std::vector<Eigen::Vector3d> turn_gyro;
  std::vector<Eigen::Vector3d> turn_accel;

  // Middle of the interval, s.
  double time() const { return 0.5 * (accel.t_begin + accel.t_end); }
  double temperature() const { return accel.temperature; }
};

// One observation per interval (the accelerometer part as
// PositionsFromIntervals makes it), without within-pose trends.
std::vector<StaticObservation> ObservationsFromIntervals(
    const std::vector<StaticInterval>& intervals, bool has_gyro);

// How the within-pose trends are read from the samples (within_pose_trend.h).
struct WithinPoseTrendOptions {
  // Batches per pose (>= 4); the noise is pooled over the poses.
  int batches = 10;
  // A pose gets a trend when it has batches * min_batch_samples samples
  // (>= 1) and lasts min_seconds (> 0) or more.
  int min_batch_samples = 5;
  double min_seconds = 3.0;
  // Keep only the slope's component along the pose's mean direction
  // (gravity): one row per pose instead of three. The cross-gravity
  // components also carry slow tilts of the placement and tremor, which no
  // catalogue effect models; the along-gravity one sees a tilt only to
  // second order.
  bool along_gravity_only = false;

  bool IsValid(std::string* error) const;
};

// The trends `discover` and `calibrate --effects` read (issue 21): 5 batch
// means per pose (6 s batches on a 30 s hold count the noise correlated
// over seconds in each batch mean; pooling over the poses gives the
// degrees of freedom), the component along gravity only, poses of
// min_seconds or more.
WithinPoseTrendOptions GravityTrendOptions(double min_seconds = 10.0);

// The same observations with each pose's within-pose trend from the samples
// of `log` (the log the intervals were detected in). An empty result when
// the options are invalid.
std::vector<StaticObservation> ObservationsFromIntervals(
    const ImuLog& log, const std::vector<StaticInterval>& intervals,
    const WithinPoseTrendOptions& options = WithinPoseTrendOptions());

// Issue 21: sets (*observations)[k].session_index = k and, for every k >= 1,
// the turn's samples from intervals[k - 1] to intervals[k] (observations
// made from `intervals` of `log`, in order). The turn starts edge_seconds
// (at most a quarter of the interval) before the end of the one and ends as
// far into the other, as in the gyroscope calibration: static detection
// lets the slow start and end of a motion into an interval, and a turn the
// gyroscope does not integrate is an error no model absorbs. Turns longer
// than max_turn_seconds are left out. Nothing without a gyroscope or when
// the sizes differ. Returns the turns added.
int AddBetweenPoseTurns(const ImuLog& log, const std::vector<StaticInterval>& intervals,
                        std::vector<StaticObservation>* observations, double edge_seconds = 0.5,
                        double max_turn_seconds = 60.0);

// The shared settings (fit_settings.h) as the refinement reads them, so a
// calibration hands its refinement's settings to this fit whole:
// - parameterization, the baseline accelerometer model: kScale holds the
//   off-diagonal of U at zero (unless accel_misalignment is in `effects`);
//   kAffine fits like kScaleMisalignment and keeps R;
// - loss at loss_scale, on each residual block (a position's magnitude, its
//   within-pose trend, a turn between poses; a position's three gyroscope
//   mean rates), as in the refinement (refinement.h): the solve is graduated
//   from a scale holding every initial residual down to loss_scale, and the
//   covariance weights each block's rows by sqrt(rho'(|r|^2)), the weights of
//   iteratively reweighted least squares at the optimum. chi2 and the
//   residuals stay unweighted;
// - estimate_pose_variance: one extra variance s^2 common to the position
//   magnitudes by REML (src/estimation/variance_component.h), refit with
//   sigma_k^2 + s^2 and the covariance inflated by the Student factor of the
//   estimate: what the pose means share beyond their samples' noise (bias
//   instability and random walk wander from pose to pose, placement). For
//   estimates with honest standard deviations (calibrate --effects); off for
//   the likelihood-ratio tests, where every model must see the same noise.
//   Skipped when the magnitudes leave no residual degree of freedom beyond
//   what the trends determine and no prior (pose_disturbance_prior on
//   pose_disturbance_prior_dof) is given.
struct EffectFitOptions : AccelFitSettings {
  std::vector<Effect> effects;
  // Fit the gyroscope part (when the observations have it).
  bool fit_gyro = true;
  // Skip the accelerometer part (keep `initial` and its effects): for
  // refits of a gyroscope effect alone.
  bool fit_accel = true;
  // Add the AccelTrendResidual of every observation that has a trend; false
  // = the position magnitudes alone.
  bool use_within_pose_trends = true;
  // A fixed extra variance (m/s^2)^2 added to every magnitude's sigma_k^2
  // (>= 0; the REML above adds to it): for likelihood-ratio tests, where
  // every model must see the same noise, a value from outside the models
  // compared (a noise model, a prior). The REML of a model without the
  // candidate absorbs it: on twelve poses with the drift and both tempcos
  // fitted, a hidden k2 is then found in 3 of 20 seeds instead of 20.
  double magnitude_extra_variance = 0.0;

  // Stopping rules of the Ceres solve.
  SolverTolerances solver = {50, 1e-12, 1e-12, 1e-10};

  // Issue 21: add the AccelRotationResidual
  // (residuals/accel_rotation_residual.h) of every turn between consecutive
  // poses that the observations carry (AddBetweenPoseTurns): the
  // gyroscope's integrated turn must carry the corrected accelerometer
  // direction of one pose to that of the next. Two rows per turn, counted in
  // the accelerometer's num_residuals and chi2 (and apart in
  // rotation_residuals, rotation_chi2); the gyroscope's M_g (9) and b_g (3)
  // are estimated with the accelerometer as nuisance parameters (named
  // rotation_gyro_*). Needs at least 7 turns; with fewer the rows are left
  // out with a warning.
  bool use_between_pose_rotations = false;
  // The variance of the gyroscope's bias about its session value,
  // (rad/s)^2 per axis (>= 0): bias instability and rate random walk, B^2 +
  // K^2 T / 6 over a session of T s from a noise model; it adds to each
  // turn's integrated white noise. 0 = white noise only.
  double rotation_gyro_bias_variance = 0.0;

  bool IsValid(std::string* error) const;
};

// The statistics of one sensor's part of the fit.
struct SensorFitSummary {
  bool fitted = false;
  bool converged = false;
  // Scalar residuals (one per position for the accelerometer plus three per
  // within-pose trend, three per position for the gyroscope) and free
  // parameters.
  int num_residuals = 0;
  int num_parameters = 0;
  // Sum of squared whitened residuals.
  double chi2 = 0.0;
  // The part of num_residuals and chi2 from the within-pose trends (0 when
  // none was used); the rest is from the position magnitudes.
  int trend_residuals = 0;
  double trend_chi2 = 0.0;
  // The same for the rotations between poses (use_between_pose_rotations).
  int rotation_residuals = 0;
  double rotation_chi2 = 0.0;
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
  // Leverage of each position, diag of J (J^T J)^+ J^T (of its magnitude
  // row for the accelerometer, the largest of its three rows for the
  // gyroscope): near 1, the other positions do not
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
  // The extra magnitude variance (estimate_pose_variance), (m/s^2)^2,
  // and the factor the accelerometer covariance was multiplied by.
  VarianceComponent magnitude_variance;
  double magnitude_variance_inflation = 1.0;
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
  // Per position, the whitened within-pose trend residual t_k (zero where
  // the position has none or trends were not used).
  std::vector<Eigen::Vector3d> accel_trend_residuals;
  // With the rotations between poses: the gyroscope estimated with them,
  // w = M_g (u - b_g) in the accelerometer's orthogonalised frame (raw
  // units; NaN when not used; b_g is the poses' mean rest level plus the
  // common correction, each turn using its own level, between_pose_
  // rotations.h), and each turn's whitened residual (2 values) with the
  // observation indices it joins.
  Eigen::Matrix3d rotation_gyro_matrix = Eigen::Matrix3d::Constant(NAN);
  Eigen::Vector3d rotation_gyro_bias = Eigen::Vector3d::Constant(NAN);
  std::vector<Eigen::Vector2d> rotation_residuals;
  std::vector<std::pair<int, int>> rotation_poses;
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
