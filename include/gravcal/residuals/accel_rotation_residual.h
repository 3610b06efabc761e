// gravcal/residuals/accel_rotation_residual.h: the per-rotation Ceres
// residual that lets the gyroscope's turn between two static poses constrain
// the accelerometer model with its effects (issue 21).
//
// Poses s and e of a session are joined by a turn whose gyroscope samples
// u_0 .. u_{n-1} at t_0 .. t_{n-1} start with the last sample of pose s and
// end with the first of pose e. The corrected accelerometer direction of a
// pose with mean raw vector v at offsets (dT, dt) is
//
//   m = U (v - b_a)                                m/s^2, orthogonalised frame
//   a = effect correction of m at (dT, dt)         model_effects.h
//   d = a / |a|
//
// The gyroscope rate in the same frame is w_i = M_g (u_i - b_g) (M_g: 9
// free entries, rad/s per raw unit, so it absorbs the rotation between the
// gyroscope's axes and the accelerometer's orthogonalised frame; b_g raw
// units; u_i may be given about a level of the caller's, then b_g is the
// correction to it), integrated as IntegrateGyroRotation (gyro_rotation_residual.h)
// into the attitude change dq of pose e relative to pose s. Gravity is fixed
// in the navigation frame, so a right model carries d_s into d_e:
//
//   r = W E (R(dq)^T d_s - d_e)                    2 values, dimensionless
//
// E (2x3) spans the plane perpendicular to d_e (fixed when the residual is
// made), so E (...) is the direction error in rad to first order; W (2x2) is
// the square-root information of that error (src/methods/
// between_pose_rotations.cc: the integrated white noise of the gyroscope
// over the turn, the wander of its bias when a noise model gives one, and
// the noise of the two poses' means).
//
// Unlike the magnitude |a| = g, the direction sees the shape of the
// accelerometer's error in every axis at once (non-orthogonality, scale
// ratios, the quadratic term's dependence on the axis' share of gravity);
// what it cannot see is a common scale of a (normalised away) and a common
// rotation (absorbed by M_g).
//
// Parameter blocks, in order: b_a (3), U (6: u00 u01 u02 u11 u12 u22) and
// the accelerometer effects' block (kAccelEffectParameters) as
// GravityMagnitudeResidual::CreateWithEffects, then b_g (3) and M_g (9,
// row-major). An effect that is off has its values held at zero, which
// leaves its term the identity.
#ifndef GRAVCAL_RESIDUALS_ACCEL_ROTATION_RESIDUAL_H_
#define GRAVCAL_RESIDUALS_ACCEL_ROTATION_RESIDUAL_H_

#include <ceres/autodiff_cost_function.h>
#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Core>
#include <cmath>
#include <memory>
#include <utility>

#include "gravcal/core/imu_model.h"
#include "gravcal/residuals/gyro_rotation_residual.h"

namespace gravcal {

// One turn and its two poses, in the units of the parameters.
struct AccelRotationData {
  // Sample times and raw gyroscope vectors of the turn (turn.force unused).
  GyroRotationData turn;
  // Mean raw accelerometer vectors of the poses and their offsets
  // dT = T - T_ref (0 when unknown) and dt = t - t_ref.
  Eigen::Vector3d start_raw = Eigen::Vector3d::Zero();
  Eigen::Vector3d end_raw = Eigen::Vector3d::Zero();
  double start_temperature_offset = 0.0;
  double start_time_offset = 0.0;
  double end_temperature_offset = 0.0;
  double end_time_offset = 0.0;
  // E: rows span the plane perpendicular to the end direction.
  Eigen::Matrix<double, 2, 3> tangent = Eigen::Matrix<double, 2, 3>::Zero();
  // W: square-root information of E (R(dq)^T d_s - d_e).
  Eigen::Matrix2d sqrt_information = Eigen::Matrix2d::Identity();
  // The turn's integration at the gyroscope parameters it was last
  // evaluated at (gyro_rotation_residual.h), shared by every residual made
  // from this data and its copies; null: each residual keeps its own. Set
  // it only while `turn` stays as it is.
  std::shared_ptr<GyroTurnCache> turn_cache;
};

struct AccelRotationResidual {
  explicit AccelRotationResidual(AccelRotationData data)
      : data_(std::move(data)),
        cache_(data_.turn_cache ? data_.turn_cache : std::make_shared<GyroTurnCache>()) {}

  template <typename T>
  bool operator()(const T* const bias, const T* const upper, const T* const effects,
                  const T* const gyro_bias, const T* const gyro_matrix, T* residual) const {
    const AccelBlocks<T> accel(bias, upper, effects);
    const ImuModel<T> model(accel);
    T start[3], end[3];
    if (!model.Direction(data_.start_raw, data_.start_temperature_offset, data_.start_time_offset,
                         start) ||
        !model.Direction(data_.end_raw, data_.end_temperature_offset, data_.end_time_offset, end)) {
      return false;
    }
    T dq[4];
    IntegrateGyroTurn(data_.turn, gyro_bias, gyro_matrix, static_cast<const T*>(nullptr), dq,
                      cache_.get());
    WhitenedTurnError<T>(dq, start, end, data_.tangent, data_.sqrt_information, residual);
    return true;
  }

  static ceres::CostFunction* Create(AccelRotationData data) {
    return new ceres::AutoDiffCostFunction<AccelRotationResidual, 2, 3, 6, kAccelEffectParameters,
                                           3, 9>(new AccelRotationResidual(std::move(data)));
  }

 private:
  const AccelRotationData data_;
  const std::shared_ptr<GyroTurnCache> cache_;
};

}  // namespace gravcal

#endif  // GRAVCAL_RESIDUALS_ACCEL_ROTATION_RESIDUAL_H_
