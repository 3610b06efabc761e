// Private: the Ceres residuals of the model with effects (model_effects.h),
// one block per static position. Used only by src/effect_fit.cc, so the
// autodiff code is compiled once.
#ifndef GRAVCAL_SRC_RESIDUALS_EFFECT_RESIDUAL_H_
#define GRAVCAL_SRC_RESIDUALS_EFFECT_RESIDUAL_H_

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Core>
#include <cmath>

#include "gravcal/core/model_effects.h"

namespace gravcal {

// The gravity magnitude of one position with the accelerometer effects:
//
//   m   = U (v_k - b)                                 m/s^2, sensor frame
//   a   = effect correction of m at (dT_k, dt_k)      model_effects.h
//   r_k = ( |a| - g ) / sigma_k
//
// Blocks: b (3, raw units), U (6, upper triangle row-major, m/s^2 per raw
// unit), k2 (3), beta (3), c (3), delta (3). An effect that is off has its
// block held constant at zero, which leaves its term the identity.
struct AccelEffectResidual {
  AccelEffectResidual(const Eigen::Vector3d& raw_mean, double temperature_offset,
                      double time_offset, double gravity, double sigma)
      : raw_mean_(raw_mean),
        temperature_offset_(temperature_offset),
        time_offset_(time_offset),
        gravity_(gravity),
        sigma_(sigma) {}

  template <typename T>
  bool operator()(const T* const bias, const T* const upper, const T* const quadratic,
                  const T* const temperature_bias, const T* const temperature_scale,
                  const T* const drift, T* residual) const {
    const T d0 = T(raw_mean_(0)) - bias[0];
    const T d1 = T(raw_mean_(1)) - bias[1];
    const T d2 = T(raw_mean_(2)) - bias[2];
    T m[3] = {upper[0] * d0 + upper[1] * d1 + upper[2] * d2, upper[3] * d1 + upper[4] * d2,
              upper[5] * d2};
    if (!CorrectAccelEffects(quadratic, temperature_bias, temperature_scale, drift,
                             temperature_offset_, time_offset_, m)) {
      return false;
    }
    using std::sqrt;
    residual[0] = (sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]) - T(gravity_)) / T(sigma_);
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& raw_mean, double temperature_offset,
                                     double time_offset, double gravity, double sigma) {
    return new ceres::AutoDiffCostFunction<AccelEffectResidual, 1, 3, 6, 3, 3, 3, 3>(
        new AccelEffectResidual(raw_mean, temperature_offset, time_offset, gravity, sigma));
  }

 private:
  const Eigen::Vector3d raw_mean_;
  const double temperature_offset_;
  const double time_offset_;
  const double gravity_;
  const double sigma_;
};

// The mean gyroscope reading of one static position (w = 0):
//
//   e   = u_k - b_g - (G f_k + gamma dT_k + eta dt_k)     raw units
//   r_k = L_k^-1 e,   L_k L_k^T = covariance of the mean u_k
//
// f_k the calibrated specific force of the position (m/s^2, held fixed).
// Blocks: b_g (3), G (9, row-major), gamma (3), eta (3); an effect that is
// off is held at zero.
struct GyroEffectResidual {
  GyroEffectResidual(const Eigen::Vector3d& gyro_mean, const Eigen::Matrix3d& whitening,
                     const Eigen::Vector3d& force, double temperature_offset, double time_offset)
      : gyro_mean_(gyro_mean),
        whitening_(whitening),
        force_(force),
        temperature_offset_(temperature_offset),
        time_offset_(time_offset) {}

  template <typename T>
  bool operator()(const T* const bias, const T* const g_sensitivity,
                  const T* const temperature_bias, const T* const drift, T* residual) const {
    T offset[3];
    GyroEffectOffset(g_sensitivity, temperature_bias, drift, force_.data(), temperature_offset_,
                     time_offset_, offset);
    T e[3];
    for (int i = 0; i < 3; ++i) e[i] = T(gyro_mean_(i)) - bias[i] - offset[i];
    for (int i = 0; i < 3; ++i) {
      residual[i] =
          T(whitening_(i, 0)) * e[0] + T(whitening_(i, 1)) * e[1] + T(whitening_(i, 2)) * e[2];
    }
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& gyro_mean,
                                     const Eigen::Matrix3d& whitening, const Eigen::Vector3d& force,
                                     double temperature_offset, double time_offset) {
    return new ceres::AutoDiffCostFunction<GyroEffectResidual, 3, 3, 9, 3, 3>(
        new GyroEffectResidual(gyro_mean, whitening, force, temperature_offset, time_offset));
  }

 private:
  const Eigen::Vector3d gyro_mean_;
  const Eigen::Matrix3d whitening_;
  const Eigen::Vector3d force_;
  const double temperature_offset_;
  const double time_offset_;
};

}  // namespace gravcal

#endif  // GRAVCAL_SRC_RESIDUALS_EFFECT_RESIDUAL_H_
