// gravcal/methods/gyro_calibration.h: gyroscope calibration from the rotations
// between the static poses of a multi-position session, no turntable
// (Tedaldi et al. 2014; docs/methods.md section 4).
//
// The log is cut into rotations, each from the last sample of one static
// interval to the first sample of the next (after edge_seconds are trimmed
// from both ends of every interval). The calibrated gyroscope
//
//   w = M_g (u - b_g) - G f      (gyro_model.h, plus the g-sensitivity G)
//
// is integrated over each rotation and must turn the gravity direction the
// calibrated accelerometer sees in one pose into the direction it sees in
// the next (GyroRotationResidual, gyro_rotation_residual.h). At rest w = 0,
// which ties b_g (and G) to the mean gyroscope reading of every pose
// (GyroStaticResidual, gyro_static_residual.h). All residuals go into one
// Ceres problem, optionally together with the accelerometer's gravity
// magnitude residuals (joint = true), so the bias comes from the static
// intervals with its standard deviation and the rest jointly.
//
// What the data can determine: M_g is a full 3x3 matrix (scale factors and
// misalignment into the accelerometer's body frame, which fixes the gauge).
// Column j of M_g (gyro scale j and the misalignments m_xj, m_yj, m_zj) needs
// rotations with rate on raw axis j while that axis is away from the
// vertical: a rotation about the vertical leaves gravity where it is and
// tells nothing. G needs static poses whose gravity directions span three
// dimensions. Entries the data does not determine are held at their initial
// value, named in a warning and reported with NaN standard deviation.
//
// Units: b_g in raw gyroscope units, M_g in rad/s per raw unit, G in rad/s
// per m/s^2, residuals in degrees. The initial M_g comes from a linear fit of
// df/dt = f x w over the rotations, so no nominal scale is needed.
#ifndef GRAVCAL_METHODS_GYRO_CALIBRATION_H_
#define GRAVCAL_METHODS_GYRO_CALIBRATION_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "gravcal/core/accel_model.h"
#include "gravcal/core/gyro_model.h"
#include "gravcal/core/imu_log.h"
#include "gravcal/core/noise_model.h"
#include "gravcal/core/types.h"
#include "gravcal/detection/static_detector.h"
#include "gravcal/estimation/refinement.h"
#include "gravcal/estimation/solver_tolerances.h"
#include "gravcal/methods/twelve_position.h"

namespace gravcal {

struct GyroCalibrationOptions {
  // kNone makes CalibrateGyroscope fail: there is nothing to do.
  GyroParameterization parameterization = GyroParameterization::kNone;
  // Estimate the g-sensitivity G (9 more parameters).
  bool g_sensitivity = false;
  // Refine the accelerometer's bias and U in the same problem (its housing
  // rotation R is held: with it free the problem has a 3-parameter gauge).
  bool joint = false;
  // Robust loss on the whitened rotation and static residuals, and its scale
  // in units of sigma.
  LossType loss = LossType::kNone;
  double loss_scale = 3.0;
  bool compute_covariance = true;
  // A parameter whose standard deviation exceeds these is not determined:
  // entries of M_g relative to the mean scale factor, G in rad/s per m/s^2.
  double max_matrix_std = 0.05;
  double max_g_sensitivity_std = 1e-2;
  // Samples this close to either end of a static interval are integrated as
  // part of the rotations and left out of the pose's mean, s (at most a
  // quarter of the interval): static detection lets the slow start and end
  // of a motion into an interval, and an attitude change the gyroscope does
  // not integrate is an error no model can absorb.
  double edge_seconds = 0.5;
  // A gap between two static poses longer than this is not used, s.
  double max_rotation_seconds = 60.0;
  // (m/s^2)^2 per axis added to the covariance of every pose's mean
  // specific force: what the samples of a pose cannot show, which moves the
  // gravity direction each pose gives the rotations. AddGyroscopeCalibration
  // sets it to the accelerometer's absorbed per-pose variance
  // (pose_variance); 0 = white noise only.
  double pose_variance = 0.0;
  // Estimate the scatter of the static poses' mean rates beyond their white
  // noise (bias instability, random walk) by REML and add it to every static
  // pose's covariance (estimation/variance_component.h).
  // AddGyroscopeCalibration turns it on with the accelerometer's
  // pose_variance.
  bool estimate_static_variance = false;
  // The gyroscope's noise model (`calibrate --noise noise.json`), or null.
  // The bias wanders over the session (bias instability, rate random walk)
  // by an amount every static pose shares and no pose can show: with a
  // model, B^2 + K^2 T / 3 (T the session's span) is added to the bias's
  // covariance; without one, twice the static poses' REML scatter (when
  // estimate_static_variance finds one; src/methods/gyro_bias_wander.h).
  const ImuNoiseModel* noise_model = nullptr;

  // Stopping rules of the Ceres solve.
  SolverTolerances solver = {100, 1e-12, 1e-12, 1e-10};

  bool IsValid(std::string* error) const;
};

// One rotation between consecutive static poses.
struct GyroRotationReport {
  // Index of the static interval it leaves and reaches.
  int from_pose = 0;
  int to_pose = 0;
  // Samples first..last of the log (the last sample of one pose, the first
  // of the next) and their times.
  size_t first_sample = 0;
  size_t last_sample = 0;
  double t_begin = 0.0;
  double t_end = 0.0;
  // Angle between the gravity directions of the two poses, degrees.
  double gravity_angle_deg = 0.0;
  // Angle between the predicted and the seen end direction after
  // calibration, degrees, and its expected size from the noise
  // (sqrt of the trace of the 2x2 covariance), degrees.
  double residual_deg = 0.0;
  double sigma_deg = 0.0;
  // Squared norm of the whitened 2-vector: chi-square with 2 dof.
  double chi2 = 0.0;
};

// chi2 and dof cover the static, rotation and (joint) magnitude residuals;
// parameter_names: bias_x..z; scale for kBias, m_xx, m_yy, m_zz for kScale,
// m_xx, m_xy, ..., m_zz for kFull; g_xx, ..., g_zz with G (SI / raw units as
// above).
struct GyroCalibrationResult : LeastSquaresSummary {
  GyroModel model;
  // Zero unless estimated.
  Eigen::Matrix3d g_sensitivity = Eigen::Matrix3d::Zero();
  // Standard deviations; NaN where not estimated or not determined.
  Eigen::Vector3d bias_std = Eigen::Vector3d::Constant(NAN);
  Eigen::Matrix3d matrix_std = Eigen::Matrix3d::Constant(NAN);
  Eigen::Matrix3d g_sensitivity_std = Eigen::Matrix3d::Constant(NAN);
  // Parameters the data does not determine (held at their initial value).
  std::vector<std::string> undetermined;
  std::vector<GyroRotationReport> rotations;
  // Per-sample gyroscope noise seen in the static intervals, raw units
  // (sqrt of the diagonal of the pooled covariance).
  Eigen::Vector3d gyro_noise = Eigen::Vector3d::Zero();
  // The bias's wander over the session that every pose shares, per axis,
  // raw units (included in bias_std and covariance; zero when none was
  // accounted for), and a note saying from what it was sized.
  Eigen::Vector3d bias_wander_std = Eigen::Vector3d::Zero();
  std::string bias_wander_note;
  // The linear initial estimate of M_g.
  Eigen::Matrix3d initial_matrix = Eigen::Matrix3d::Identity();
  // joint: the refined accelerometer (model, covariance of its bias and free
  // U entries in parameter_names order, residuals, sigmas); otherwise empty.
  bool accel_refined = false;
  RefinementResult accel;
  std::vector<std::string> warnings;
  // The code of each warning (same index).
  std::vector<WarningCode> warning_codes;
  std::string message = "CalibrateGyroscope was not called";
};

// Calibrates the gyroscope from `log` (which must have gyroscope columns),
// its static intervals in time order (DetectStaticIntervals) and the
// calibrated accelerometer `accel` (its body frame is the result's frame).
// accel_covariance is the covariance of the accelerometer's bias and free U
// entries (RefinementResult::covariance, MagnitudeParameterNames order) or
// empty: the held accelerometer's errors move the gyroscope estimate, and
// without it the gyroscope's standard deviations leave that out (measured:
// 15-35 % too small with the default simulator; joint = true needs none, the
// joint fit estimates both). `gravity` (m/s^2) is used by the joint fit only. Returns false with a
// one-line message on invalid options, a log without gyroscope, too few
// static intervals or rotations, an initial estimate that fails, or a
// solve that does not converge (then the result holds the last estimate and
// converged = false).
bool CalibrateGyroscope(const ImuLog& log, const std::vector<StaticInterval>& intervals,
                        const AccelModel& accel, const Eigen::MatrixXd& accel_covariance,
                        double gravity, const GyroCalibrationOptions& options,
                        GyroCalibrationResult* result);

// The gyroscope step of a multi-position calibration: after the
// accelerometer (calibration->success) and its static `intervals` of `log`,
// runs CalibrateGyroscope with calibration->accel and
// fills calibration->gyro (estimated = true, the residual per rotation, the
// g-sensitivity as extra values g_sensitivity_xx .. g_sensitivity_zz in
// rad/s per m/s^2) and its warnings; with options.joint it also replaces the
// accelerometer's bias, U and their uncertainties by the joint fit's.
// Returns false with calibration->message (and success = false) when the
// gyroscope cannot be calibrated; nothing of the gyroscope is filled then.
bool AddGyroscopeCalibration(const ImuLog& log, const std::vector<StaticInterval>& intervals,
                             const GyroCalibrationOptions& options, Calibration* calibration);

}  // namespace gravcal

#endif  // GRAVCAL_METHODS_GYRO_CALIBRATION_H_
