// gravcal/methods/handheld_kalman.h: handheld field calibration of the accelerometer
// and gyroscope bias and scale factor with an error-state Kalman filter (Sun,
// Ding, Yan), for a user with no table and no fixture.
//
// Procedure the filter expects: a few seconds still (initial roll and pitch
// from the accelerometer, heading 0), then the unit turned by hand about
// each of its axes in turn while that axis is roughly horizontal, staying
// roughly in place. Rotation about the vertical excites nothing.
//
// Navigation: strapdown.h (local level frame, z up, gravity -g on z). The
// measurements are pseudo-measurements: the unit turns in place, so its true
// velocity is about zero and its position about the start point:
//   z_v = v_hat - 0            = dv + v_true,          R_v = sigma_v^2 I
//   z_p = p_hat - p_start      = dp + (p_true - p_0),  R_p = sigma_p^2 I
// sigma_v and sigma_p describe how much the hand moves the unit; they are
// the filter's measurement noise.
//
// Error state (error_state_layout.h), errors = estimate - truth, except the
// attitude error phi, defined by C_true = (I + [phi x]) C_hat:
//   x = [phi, dv, dp, db_a, dE_a, db_g, dE_g]   (21 states for diagonal E).
// Sensor model: f_m = (I + E_a) f + b_a + n_a and w_m = (I + E_g) w + b_g +
// n_g (SI units after the nominal scale); corrected values
// f_hat = (I + E_a_hat)^-1 (f_m - b_a_hat), same for w_hat, so to first order
//   df = f_hat - f = -(I + E_a)^-1 (db_a + dE_a f_hat) + (I + E_a)^-1 n_a
//   dw = w_hat - w = -(I + E_g)^-1 (db_g + dE_g w_hat) + (I + E_g)^-1 n_g.
// Standard INS error equations in a local level frame (w_ie the Earth rate,
// zero unless enabled):
//   phi' = -w_ie x phi - C dw
//        = -w_ie x phi + C (I+E_g)^-1 (db_g + dE_g w_hat) - C (I+E_g)^-1 n_g
//   dv'  = (C f_hat) x phi - 2 w_ie x dv + C df
//        = [(C f_hat) x] phi - 2 w_ie x dv - C (I+E_a)^-1 (db_a + dE_a f_hat)
//          + C (I+E_a)^-1 n_a
//   dp'  = dv
//   db', dE' = 0 (random constants; optional bias random walk)
// i.e. x' = F x + G w. Discretisation: per IMU sample, Phi_k = I + F dt with
// F at mid-step; the products of Phi_k are accumulated exactly using the
// block structure Phi = [[A, B], [0, I]] (A: navigation, B: navigation <-
// sensor), and the process noise Q = sum Phi G Q_c G^T Phi^T dt with Q_c =
// diag(sigma_g^2 I, sigma_a^2 I) (noise densities) and the bias random walks.
// The covariance P = Phi P Phi^T + Q is formed once per update epoch.
//
// Update: Kalman gain K = P H^T (H P H^T + R)^-1, Joseph form
//   P = (I - K H) P (I - K H)^T + K R K^T,
// closed loop: the estimated errors are fed back into the navigation state
// (C_hat <- exp([phi x]) C_hat, v -= dv, p -= dp) and the sensor estimates
// (b -= db, E -= dE), and the error state is reset to zero.
//
// Initial covariance: the coarse levelling reads the (uncalibrated)
// accelerometer, so its tilt error is not independent of the accelerometer
// errors: phi_x = -(C df)_y / g, phi_y = (C df)_x / g. P0 = T D T^T with D the
// independent priors and T carrying that dependence.
//
// Beyond the paper (both off by default): cross-axis terms (accel_terms,
// gyro_terms) and the lever arm r, the sensor's offset from the point the
// hand turns about; with r the pseudo-measurements hold that point still:
//   z_v = v_hat - C_hat (w_hat x r_hat),   z_p = p_hat - C_hat r_hat,
// linearised in Filter::Update.
//
// What it determines: bias and scale of both sensors (12 numbers), with
// standard deviations from the final covariance of the last pass (`passes`),
// and with the options above the cross-axis terms and r. It cannot determine
// anything the motion did not excite: those keep a standard deviation near
// their prior and a warning names the missing motion.
#ifndef GRAVCAL_METHODS_HANDHELD_KALMAN_H_
#define GRAVCAL_METHODS_HANDHELD_KALMAN_H_

#include <string>
#include <vector>

#include "gravcal/core/calibration.h"
#include "gravcal/core/gravity.h"
#include "gravcal/core/imu_log.h"
#include "gravcal/estimation/error_state_layout.h"
#include "gravcal/methods/session.h"

namespace gravcal {

// Defaults are for a consumer MEMS IMU (for example an MPU-6050 class part)
// held by hand. From an Allan deviation plot of a still recording: the
// noise densities are the Allan deviations at tau = 1 s on the -1/2 slopes
// (the velocity random walk in m/s^2/sqrt(Hz) = m/s/sqrt(s), and the angle
// random walk in rad/s/sqrt(Hz) = rad/sqrt(s)); the bias random walks are the
// values at tau = 3 s on the +1/2 slopes (rate random walk), or leave them 0
// for a one-minute calibration, where the bias is constant to well within
// its bias instability.
struct HandheldKalmanOptions {
  // Raw units -> SI before the filter: m/s^2 per raw accelerometer unit and
  // rad/s per raw gyroscope unit (1 for data in SI units). The pipeline takes
  // the accelerometer one from the key nominal_scale.
  double accel_nominal_scale = 1.0;
  double gyro_nominal_scale = 1.0;
  // Local gravity (the pipeline takes it from the keys gravity, latitude,
  // height).
  GravityOptions gravity;
  // Earth rate in the mechanisation (needs gravity.latitude). Off: a MEMS
  // gyroscope cannot see it in a minute.
  bool earth_rate = false;

  // Initial still period used for the coarse levelling, seconds.
  double still_seconds = 3.0;
  // Time between pseudo-measurement updates, seconds. Set it to about the
  // correlation time of the hand's movement: updating faster than that
  // counts the same movement as independent information many times.
  double update_interval = 0.5;
  // How far the hand moves the unit: velocity about zero (m/s) and position
  // about the start point (m), one standard deviation.
  double velocity_noise = 0.03;
  double position_noise = 0.03;

  // Sensor noise densities: m/s^2/sqrt(Hz) and rad/s/sqrt(Hz).
  double accel_noise_density = 2e-3;
  double gyro_noise_density = 2e-4;
  // Bias random walks: m/s^2/sqrt(s) and rad/s/sqrt(s). 0 = constant biases
  // (the paper's model).
  double accel_bias_walk = 0.0;
  double gyro_bias_walk = 0.0;

  // Prior standard deviations of the sensor errors (the filter starts at
  // zero error): m/s^2, fraction, rad/s, fraction; cross_axis_std (rad) only
  // when the layout estimates cross-axis terms.
  double accel_bias_std = 0.2;
  double accel_scale_std = 0.02;
  double gyro_bias_std = 0.02;
  double gyro_scale_std = 0.02;
  double cross_axis_std = 0.01;
  // Attitude error of the coarse levelling beyond what the accelerometer
  // errors explain (the hand moving during the still period), rad.
  double initial_attitude_std = 0.01;

  // Passes over the log. The first is the causal filter of the paper (its
  // history and convergence times are reported); each later pass starts from
  // the previous pass's sensor estimates, which removes the second-order
  // errors of starting far from the truth (see handheld_kalman.cc).
  int passes = 2;
  // Also estimate the lever arm r: the sensor's position relative to the
  // point the hand turns about (body frame, m). The pseudo-measurements then
  // hold that point still instead of the sensor: position p - C r and
  // velocity v - C (w x r). Off in the paper's model; prior lever_arm_std.
  bool estimate_lever_arm = false;
  double lever_arm_std = 0.05;
  // Which sensor error terms are estimated (the paper: scale factors only).
  SensorErrorTerms accel_terms;
  SensorErrorTerms gyro_terms;

  // Convergence criterion (reported per state, on the first pass, the
  // causal filter): converged at the first epoch from which on both
  // |estimate - final estimate| and the standard deviation stay below
  // convergence_fraction times the prior standard deviation (a settling
  // time with a tolerance fixed in advance, so a longer recording does not
  // move it). A state whose final standard deviation is above that
  // tolerance is not determined: the motion did not excite it, and a
  // warning names the motion that was missing.
  double convergence_fraction = 0.1;

  bool IsValid(std::string* error) const;
};

// Runs the filter over the whole log and fills `calibration`: accel (model
// `scale`: bias and diagonal), gyro (bias and diagonal, off-diagonals not
// estimated: NaN std), standard deviations from the final covariance, the
// time history (calibration->history: t and every sensor estimate with its
// standard deviation, in filter units: m/s^2, fraction, rad/s, fraction per
// epoch), the convergence report, and warnings for unexcited errors.
// Returns false with a one-line message on invalid options, a log without
// gyroscope, too short a log or a diverging filter. A recording that does
// not excite some errors is not a failure: they are reported with their
// (large) standard deviation and a warning.
bool CalibrateHandheld(const ImuLog& log, const HandheldKalmanOptions& options,
                       Calibration* calibration);

// The sections the method reads.
struct HandheldKalmanMethodOptions {
  // The filter, its gravity and nominal scales included.
  HandheldKalmanOptions filter;
  // The config keys the user set; of the filter's process-noise keys
  // (hk_accel_noise_density, hk_gyro_noise_density, hk_accel_bias_walk,
  // hk_gyro_bias_walk) those named here keep their values when the session
  // has a noise model, and the others come from the model.
  std::vector<std::string> noise_keys_set;

  bool IsValid(std::string* error) const { return filter.IsValid(error); }
};

// The same on a session. With a noise model (session.noise), each process
// noise density not in noise_keys_set is the largest of the model's three
// axes (as `gravcal noise --handheld` writes them: no axis is trusted more
// than its noise allows), and a warning says where Q came from.
bool CalibrateHandheld(const Session& session, const HandheldKalmanMethodOptions& options,
                       Calibration* calibration);

}  // namespace gravcal

#endif  // GRAVCAL_METHODS_HANDHELD_KALMAN_H_
