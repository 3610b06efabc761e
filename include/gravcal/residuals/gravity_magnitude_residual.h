// gravcal/residuals/gravity_magnitude_residual.h: the per-position Ceres residual.
//
// For a static position with mean raw accelerometer vector v_k,
//
//   m   = U (v_k - b)                                 m/s^2, sensor frame
//   a   = effect correction of m at (dT_k, dt_k)      model_effects.h
//   r_k = ( |a| - g ) / sigma_k
//
// b: bias, raw units (parameter block of 3).
// U: upper-triangular scale and non-orthogonality, m/s^2 per raw unit
//    (parameter block of 6: u00 u01 u02 u11 u12 u22, see accel_model.h).
// g: local gravity, m/s^2. sigma_k: standard deviation of |a_k| from the
// position's own noise, m/s^2, so r_k is dimensionless and unit-variance.
// The housing rotation R drops out of the magnitude, so it is not a
// parameter here. For a diagonal model hold u01, u02 and u12 constant with a
// ceres::SubsetManifold.
//
// Without effects (Create: blocks b, U) a = m, the usual calibration
// residual. With effects (CreateWithEffects: blocks b, U and the
// accelerometer effects' block, kAccelEffectParameters values in the
// registry's layout, core/effect_registry.h; dT_k = T_k - T_ref and dt_k =
// t_k - t_ref) a is m with the accelerometer effect terms removed; an effect
// that is off has its values held at zero, which leaves its term the
// identity. The model is ImuModel (core/imu_model.h) over these blocks.
//
// Another estimator can add this residual to its own problem, sharing the
// bias and upper blocks with its other residuals.
#ifndef GRAVCAL_RESIDUALS_GRAVITY_MAGNITUDE_RESIDUAL_H_
#define GRAVCAL_RESIDUALS_GRAVITY_MAGNITUDE_RESIDUAL_H_

#include <ceres/autodiff_cost_function.h>
#include <ceres/ceres.h>

#include <Eigen/Core>
#include <cmath>

#include "gravcal/core/imu_model.h"

namespace gravcal {

struct GravityMagnitudeResidual {
  GravityMagnitudeResidual(const Eigen::Vector3d& raw_mean, double gravity, double sigma,
                           double temperature_offset = 0.0, double time_offset = 0.0)
      : raw_mean_(raw_mean),
        gravity_(gravity),
        sigma_(sigma),
        temperature_offset_(temperature_offset),
        time_offset_(time_offset) {}

  // Without effects.
  template <typename T>
  bool operator()(const T* const bias, const T* const upper, T* residual) const {
    return Evaluate<T>(bias, upper, nullptr, residual);
  }
  // With the accelerometer effects.
  template <typename T>
  bool operator()(const T* const bias, const T* const upper, const T* const effects,
                  T* residual) const {
    return Evaluate<T>(bias, upper, effects, residual);
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& raw_mean, double gravity,
                                     double sigma) {
    return new ceres::AutoDiffCostFunction<GravityMagnitudeResidual, 1, 3, 6>(
        new GravityMagnitudeResidual(raw_mean, gravity, sigma));
  }

  // temperature_offset = T_k - T_ref (0 when unknown), time_offset = t_k -
  // t_ref.
  static ceres::CostFunction* CreateWithEffects(const Eigen::Vector3d& raw_mean,
                                                double temperature_offset, double time_offset,
                                                double gravity, double sigma) {
    return new ceres::AutoDiffCostFunction<GravityMagnitudeResidual, 1, 3, 6,
                                           kAccelEffectParameters>(
        new GravityMagnitudeResidual(raw_mean, gravity, sigma, temperature_offset, time_offset));
  }

 private:
  // A null effects block skips the terms.
  template <typename T>
  bool Evaluate(const T* bias, const T* upper, const T* effects, T* residual) const {
    const AccelBlocks<T> accel(bias, upper, effects);
    T m[3];
    if (!ImuModel<T>(accel).CorrectedSensorFrame(raw_mean_, temperature_offset_, time_offset_, m)) {
      return false;
    }
    using std::sqrt;
    residual[0] = (sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]) - T(gravity_)) / T(sigma_);
    return true;
  }

  const Eigen::Vector3d raw_mean_;
  const double gravity_;
  const double sigma_;
  const double temperature_offset_;
  const double time_offset_;
};

}  // namespace gravcal

#endif  // GRAVCAL_RESIDUALS_GRAVITY_MAGNITUDE_RESIDUAL_H_
