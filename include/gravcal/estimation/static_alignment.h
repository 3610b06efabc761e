// gravcal/estimation/static_alignment.h: attitude of an IMU held still, from its own
// accelerometer (and gyroscope), with an honest uncertainty.
//
// Frames: navigation n = East-North-Up (z up); body b = the housing. The
// attitude is C = C_b^n = R_z(heading) R_y(pitch) R_x(roll) (the simulator's
// convention), so a unit at rest reads the specific force
//   f^b = C^T (0, 0, g) = g (-sin(pitch), sin(roll) cos(pitch), cos(roll) cos(pitch)).
//
// Coarse alignment: roll = atan2(f_y, f_z), pitch = atan2(-f_x, |f_yz|) from
// the mean specific force of the first coarse_seconds; heading by
// gyrocompassing (the levelled mean rate w^l = R_y R_x w^b reads Earth rate
// W cos(lat) (sin h, cos h, .), so h = atan2(w^l_x, w^l_y)) only when the
// gyroscope can resolve Earth rate: the heading standard deviation it would
// give,
//   sigma_h = sqrt(gyro_bias_std^2 + sigma_w^2 / N) / (W |cos(lat)|),
// sigma_w the gyroscope white noise per sample and N the samples, must be
// below max_heading_std_deg and the latitude must be given. Otherwise heading
// is 0 and reported as not observed (heading_observed = false, NaN std).
//
// Fine alignment: a closed-loop error-state Kalman filter over the rest of
// the interval. States (12; without a gyroscope the last three stay at zero
// covariance):
//   x = [phi (3, nav, rad), dv (3, nav, m/s), db_a (3, body, m/s^2), db_g (3, body, rad/s)],
// with C_true = Exp(phi) C_est. The attitude of a static base is constant, so
// the filter holds it (no gyroscope integration) and
//   phi' = 0,     dv' = [f^n x] phi + C db_a + n_a,   f^n = (0, 0, g),
// v_est integrating C_est (f - b_a) - f^n. Measurements at every sample: zero
// velocity, z = v_est = dv; with a gyroscope, zero angular rate,
//   z = u - b_g - C_est^T w = db_g + C^T [w x] phi + n_g,
// w the Earth rate the model accounts for (all of it when heading is
// observed, else its vertical part W sin(lat), or none without a latitude:
// the rest is inside b_g, whose prior grows by it). The white noises come
// from the interval itself (sample standard deviation per axis) unless
// given. The Jacobians are evaluated at the coarse attitude (first
// estimates), which keeps the unobservable directions unobservable.
//
// Honesty: on a static base a horizontal accelerometer bias and a tilt give
// the same measurements, so roll and pitch are never better than the bias
// prior allows. The filter starts with the coarse tilt error correlated with
// the bias exactly as the coarse solution makes it (phi_h = G (db_a + mean
// noise), G from f^n), so its final roll/pitch covariance is the bias prior
// (plus noise), not an optimistic split. The prior covers the constant error
// the static base sees: accel_bias_std^2 + accel_matrix_std^2 |f|^2 per axis
// (each entry of a scale/misalignment error matrix dM drawn N(0, s), seen
// as dM f).
#ifndef GRAVCAL_ESTIMATION_STATIC_ALIGNMENT_H_
#define GRAVCAL_ESTIMATION_STATIC_ALIGNMENT_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "gravcal/core/gravity.h"
#include "gravcal/core/types.h"

namespace gravcal {

struct StaticAlignmentOptions {
  // Local gravity, m/s^2.
  double gravity = 9.80665;
  // Geodetic latitude, degrees; NaN = unknown (no gyrocompassing).
  double latitude_deg = NAN;
  // Prior (1 sigma) of the accelerometer's constant errors: bias per axis,
  // m/s^2, and each entry of the scale / misalignment error matrix
  // (dimensionless). The defaults describe an uncalibrated MEMS part.
  double accel_bias_std = 0.3;
  double accel_matrix_std = 0.0;
  // Prior of the gyroscope bias per axis, rad/s (MEMS: about 0.02).
  double gyro_bias_std = 0.02;
  // White noise per sample, m/s^2 and rad/s; <= 0 = from the data.
  double accel_noise = 0.0;
  double gyro_noise = 0.0;
  // Gyrocompassing is used when it would give heading to better than this.
  double max_heading_std_deg = 5.0;
  // Length of the coarse alignment at the start of the interval, seconds
  // (at most half of the interval is used).
  double coarse_seconds = 1.0;
  // Standard deviation of the zero-velocity measurement, m/s.
  double zero_velocity_std = 1e-4;
  // Use the gyroscope when the data has one (false: attitude held constant).
  bool use_gyro = true;

  bool IsValid(std::string* error) const;
};

struct StaticAlignmentResult {
  bool success = false;
  // Body-to-navigation attitude after fine alignment.
  Eigen::Quaterniond attitude = Eigen::Quaterniond::Identity();
  // Radians. heading is 0 when not observed.
  double roll = 0.0;
  double pitch = 0.0;
  double heading = 0.0;
  bool heading_observed = false;
  // Standard deviations, rad; heading_std NaN when not observed.
  double roll_std = NAN;
  double pitch_std = NAN;
  double heading_std = NAN;
  // The coarse solution, rad.
  double coarse_roll = 0.0;
  double coarse_pitch = 0.0;
  double coarse_heading = 0.0;
  // Would-be gyrocompassing heading standard deviation, rad (inf without
  // gyroscope or latitude).
  double gyrocompass_heading_std = INFINITY;
  // Covariance of the attitude error phi (navigation frame), rad^2.
  Eigen::Matrix3d attitude_covariance = Eigen::Matrix3d::Zero();
  // Covariance of (roll, pitch), rad^2.
  Eigen::Matrix2d roll_pitch_covariance = Eigen::Matrix2d::Zero();
  // Gravity projected into the body frame, g_a = C^T (0, 0, g), m/s^2, and
  // its covariance (tilt only: its magnitude is g exactly).
  Eigen::Vector3d gravity_body = Eigen::Vector3d::Zero();
  Eigen::Matrix3d gravity_body_covariance = Eigen::Matrix3d::Zero();
  // The filter's bias estimates (body frame) and standard deviations.
  Eigen::Vector3d accel_bias = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_bias_std = Eigen::Vector3d::Constant(NAN);
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_bias_std = Eigen::Vector3d::Constant(NAN);
  // Noise levels used, per sample.
  double accel_noise = 0.0;
  double gyro_noise = 0.0;
  int filter_updates = 0;
  std::vector<std::string> warnings;
  // The code of each warning (same index).
  std::vector<WarningCode> warning_codes;
  std::string message = "AlignStatic was not called";
};

// Aligns on the samples of one static interval: specific force in m/s^2
// (body frame; already scaled to SI, not otherwise corrected), body rate in
// rad/s (empty when there is no gyroscope), sample period dt in seconds.
// Returns false with a message on invalid options, fewer than 10 samples, a
// rate vector of the wrong size or a specific force far from g (not static).
bool AlignStatic(const std::vector<Eigen::Vector3d>& specific_force,
                 const std::vector<Eigen::Vector3d>& rate, double dt,
                 const StaticAlignmentOptions& options, StaticAlignmentResult* result);

// Roll, pitch, heading (rad) of a body-to-navigation attitude, ZYX.
Eigen::Vector3d RollPitchHeading(const Eigen::Quaterniond& attitude);
// The attitude of roll, pitch, heading (rad).
Eigen::Quaterniond AttitudeFromRollPitchHeading(double roll, double pitch, double heading);

}  // namespace gravcal

#endif  // GRAVCAL_ESTIMATION_STATIC_ALIGNMENT_H_
