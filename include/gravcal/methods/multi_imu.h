// gravcal/methods/multi_imu.h: several IMUs held by one rigid plate,
// calibrated together from one session of static poses and the turns
// between them (issue 38).
//
// Frames. The plate frame is the reference IMU's (index 0) orthogonalised
// accelerometer frame (accel_model.h: m = U (v - b)). IMU i's own
// orthogonalised frame is turned into it by C_i (C_0 = I):
//
//   static pose k, IMU i:   U_i (v_ik - b_i) = g C_i^T d_k           (3 rows)
//   turn k -> k+1, IMU i:   R(dq_ik)^T C_i^T d_k = C_i^T d_{k+1}     (2 rows)
//   static pose k, IMU i:   u_ik - b_gi = 0                          (3 rows)
//
// with d_k the unit direction of gravity (up) in the plate frame during pose
// k, ONE attitude shared by every IMU, and dq_ik the turn integrated from
// IMU i's gyroscope w = M_gi (u - b_gi) (gyro_rotation_residual.h). Each IMU
// keeps its full intrinsics: b_i (3), U_i (6), b_gi (3), M_gi (9, into its
// orthogonalised accelerometer frame); C_i = C_i0 Exp(delta_i) with delta_i
// the estimated rotation vector (3; its covariance is the rotation's sigma).
// The separate calibration of one IMU is the same problem with the poses
// d_k its own and its own variance factors: what a calibration of that IMU
// alone reports. The gain of the joint fit is the shared poses.
//
// Weights: each group of rows (accelerometer poses, gyroscope poses, turns)
// of each IMU starts from the white noise the still samples show and is
// rescaled by its own chi2/dof after a first solve (a variance factor per
// IMU and group), so the sigmas stay honest where the poses scatter beyond
// their samples, and one unit's misfit does not inflate the others'.
//
// Time. The turns give the relative timing of the gyroscopes: IMU i's
// calibrated rate turned into the plate frame, C_i M_gi (u_i - b_gi), is
// matched to the reference's, w_0(t) = w_i(t + tau_i), turn by turn; a line
// tau_i(t) = tau_i + drift_i (t - t_0) through the turns' estimates gives
// the offset at the session's start and the drift. A positive tau_i: IMU
// i's stamps are late. Static poses alone give no time offset, and the
// lever arm between the IMUs is not observable from gravity and slow turns:
// neither is reported as determined.
//
// Checks: a rotation close to a 90 or 180 degree turn from the stated
// mounting (a permuted or flipped axis), a unit whose poses disagree with
// the others' (it moved on the plate: split tests of its relative rotation,
// pair by pair), and clocks that drift.
#ifndef GRAVCAL_METHODS_MULTI_IMU_H_
#define GRAVCAL_METHODS_MULTI_IMU_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "gravcal/core/calibration.h"
#include "gravcal/core/imu_log.h"
#include "gravcal/detection/static_detector.h"

namespace gravcal {

// One IMU of the plate: its log (raw units, every log on one clock), its
// nominal units and its stated mounting.
struct PlateImu {
  std::string name;
  ImuLog log;
  // SI per raw unit (m/s^2, rad/s): the starting scale of the fit.
  double accel_scale = 1.0;
  double gyro_scale = 1.0;
  // Stated rotation plate-from-housing (the checks compare with it); the
  // reference's stated mounting defines the plate's.
  Eigen::Matrix3d stated_mounting = Eigen::Matrix3d::Identity();
};

struct MultiImuOptions {
  StaticDetectorOptions detector;
  // Local gravity, m/s^2.
  double gravity = 9.80665;
  // Index of the reference IMU.
  int reference = 0;
  // A turn is matched for timing over its samples plus this margin, s.
  double timing_margin = 0.2;
  // Largest |tau| searched, s.
  double max_time_offset = 0.2;
  // A rotation this close to a 90 or 180 degree turn of the stated mounting
  // is named as permuted, degrees.
  double permutation_tolerance_deg = 10.0;
  // A mounting this far from the stated one (and not a permutation) is
  // named, degrees.
  double mounting_warning_deg = 5.0;
  // A unit is named as moved when its rotation before and after some pose
  // differ by more than slip_min_deg and by more than slip_factor sigma.
  double slip_min_deg = 0.2;
  double slip_factor = 6.0;
  // A clock is named as drifting beyond drift_factor sigma and drift_min
  // (s per s).
  double drift_factor = 4.0;
  double drift_min = 2e-5;
  // Also run each IMU's separate calibration (the gain of the joint fit).
  bool separate = true;
  int max_iterations = 100;

  bool IsValid(std::string* error) const;
};

struct PlateImuResult {
  std::string name;
  // The intrinsics in the existing schema (accel b, U with R = I: its own
  // orthogonalised frame; gyro b_g, M_g into that frame), with sigmas and
  // covariance.
  Calibration calibration;
  // C_i: IMU i's orthogonalised accelerometer frame to the reference's, its
  // sigma as a rotation vector (rad, body frame: C = C_hat Exp(e)) and the
  // covariance of e.
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d rotation_std = Eigen::Vector3d::Constant(NAN);
  Eigen::Matrix3d rotation_covariance = Eigen::Matrix3d::Constant(NAN);
  // The separate calibration's sigmas (NaN when not run): accel b, U (6),
  // gyro b_g, M_g (9), in that order (21 values), and the joint's in the
  // same order.
  std::vector<double> separate_std;
  std::vector<double> joint_std;
  // Time offset of the gyroscope to the reference at the session's first
  // stamp (s), its drift (s per s), their sigmas; NaN when undetermined.
  double time_offset = NAN;
  double time_offset_std = NAN;
  double clock_drift = NAN;
  double clock_drift_std = NAN;
  int timed_turns = 0;
  // Its variance factors (accel poses, gyro poses, turns): chi2 / dof of
  // its rows in the joint fit, at least 1; its sigmas are scaled by them.
  double accel_factor = 1.0;
  double gyro_factor = 1.0;
  double turn_factor = 1.0;
  // rms of its pose rows (m/s^2) and turn rows (deg).
  double accel_residual_rms = NAN;
  double turn_residual_deg = NAN;
  // Along-gravity offset per pose: with a single pose only this is
  // determined (bias plus scale error along the up axis), m/s^2.
  double up_offset = NAN;
  double up_offset_std = NAN;
};

struct MultiImuResult {
  bool success = false;
  std::string message = "CalibrateMultiImu was not called";
  std::vector<PlateImuResult> imus;
  int reference = 0;
  int poses = 0;
  int turns = 0;
  // Covariance of the time offsets of the IMUs (reference row and column
  // zero), s^2; empty when no turns.
  Eigen::MatrixXd time_offset_covariance;
  // What the session determines and what not, as sentences.
  std::vector<std::string> undetermined;
  // Named mistakes (permuted axes, moved units, drifting clocks) and other
  // warnings.
  std::vector<std::string> warnings;
  // The largest variance factor of each row group (accel poses, gyro
  // poses, turns) over the IMUs (PlateImuResult has each IMU's).
  double accel_factor = 1.0;
  double gyro_factor = 1.0;
  double turn_factor = 1.0;
};

// Calibrates the plate. Returns false with result->message (naming the
// IMU and file) when the logs cannot be used.
bool CalibrateMultiImu(const std::vector<PlateImu>& imus, const MultiImuOptions& options,
                       MultiImuResult* result);

// The nearest rotation by a multiple of 90 degrees about the axes (the 24
// signed permutations with det +1) to `rotation`, and the angle between
// them (deg). Used by the permutation check and by the PX4 export.
Eigen::Matrix3d NearestAxisRotation(const Eigen::Matrix3d& rotation, double* angle_deg);

// "rotated 90 degrees about z", "rotated 180 degrees about x", "not
// rotated" for a signed permutation.
std::string DescribeAxisRotation(const Eigen::Matrix3d& rotation);

}  // namespace gravcal

#endif  // GRAVCAL_METHODS_MULTI_IMU_H_
