// Private: the data of the rotations gyroscope calibration
// (gyro_calibration.h), prepared once. The log is cut into rotations, each
// from the last sample of one static pose to the first of the next (after
// edge_seconds are trimmed from every interval); the gyroscope is normalised
// as u' = (u - center) * scale, with scale the cube root of |det M_g| of the
// linear initial estimate.
#ifndef GRAVCAL_SRC_METHODS_GYRO_ROTATIONS_H_
#define GRAVCAL_SRC_METHODS_GYRO_ROTATIONS_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "gravcal/core/accel_model.h"
#include "gravcal/core/imu_log.h"
#include "gravcal/core/position.h"
#include "gravcal/detection/static_detector.h"
#include "gravcal/methods/gyro_calibration.h"
#include "gravcal/residuals/gyro_rotation_residual.h"

namespace gravcal {
namespace internal {

// One rotation: samples first..last, between static poses from and to.
struct GyroSegment {
  int from = 0;
  int to = 0;
  size_t first = 0;
  size_t last = 0;
};

// Everything the problem needs, prepared once.
struct GyroPrepared {
  std::vector<GyroSegment> segments;
  // Normalised raw gyroscope: u' = (u - center) * scale.
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double scale = 1.0;
  // Per-sample covariance of the raw gyroscope (pooled over the poses).
  Eigen::Matrix3d gyro_cov = Eigen::Matrix3d::Zero();
  // Static poses: normalised mean gyroscope, its covariance (normalised),
  // calibrated mean force.
  std::vector<Eigen::Vector3d> static_gyro;
  std::vector<Eigen::Matrix3d> static_gyro_cov;
  std::vector<Eigen::Vector3d> static_force;
  std::vector<Position> positions;
  // The positions in the accelerometer's normalised units (joint fit).
  std::vector<Position> normalized_positions;
  // Rotation data without weights (t, normalised gyro, force, raw means).
  std::vector<GyroRotationData> rotations;
  // Seconds from the first static pose's first sample to the last pose's
  // last sample: the span the bias wanders over (gyro_bias_wander.h).
  double session_seconds = 0.0;
  // The static poses' scatter s^2 beyond their white noise, normalised units
  // squared per axis (estimate_static_variance; 0 when not estimated or
  // at the boundary), and the residual dof it rests on.
  double static_variance = 0.0;
  int static_variance_dof = 0;
};

// Cuts the log into rotations and prepares the normalised data; *m0 gets the
// linear initial M_g (raw units). Rotations longer than max_rotation_seconds
// are dropped with a warning. On bad input returns false with *error set.
bool PrepareGyroRotations(const ImuLog& log, const std::vector<StaticInterval>& intervals,
                          const AccelModel& accel, const GyroCalibrationOptions& options,
                          GyroPrepared* prep, Eigen::Matrix3d* m0,
                          std::vector<std::string>* warnings, std::string* error);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_METHODS_GYRO_ROTATIONS_H_
