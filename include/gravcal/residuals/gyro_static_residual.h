// gravcal/residuals/gyro_static_residual.h: the per-pose Ceres residual that ties the
// gyroscope bias (and g-sensitivity) to the static poses.
//
// At rest the body rate is zero, so for static pose k with mean raw gyroscope
// vector u_k and mean calibrated specific force f_k (m/s^2, body frame):
//
//   o_k = G' f_k + gamma dT_k + eta dt_k                  raw units (effects)
//   r_k = W_k ( M_g (u_k - b_g - o_k) - G f_k )           3 values
//
// W_k (3x3) is the square-root information of what it multiplies, from the
// covariance of the mean u_k (taken at the initial M_g), so r_k is
// dimensionless with unit variance.
//
// Without effects (Create) o_k = 0 and the blocks are b_g (3), M_g (9,
// row-major) and optionally G (9). Without G every pose measures b_g
// directly; with G the poses measure b_g + M_g^-1 G f_k, which separates b_g
// from G when the f_k span three dimensions (four or more poses not in one
// plane).
//
// With effects (CreateWithEffects, the effects fit of effect_fit.h, which
// works in raw units) M_g = I and G = 0 are not blocks; the blocks are b_g
// (3) and the gyroscope effects' block (kGyroEffectParameters values in the
// registry's layout, core/effect_registry.h: G' raw units per m/s^2, gamma,
// eta), with dT_k = T_k - T_ref and dt_k = t_k - t_ref. An effect that is
// off has its values held at zero.
#ifndef GRAVCAL_RESIDUALS_GYRO_STATIC_RESIDUAL_H_
#define GRAVCAL_RESIDUALS_GYRO_STATIC_RESIDUAL_H_

#include <ceres/autodiff_cost_function.h>
#include <ceres/ceres.h>

#include <Eigen/Core>

#include "gravcal/core/imu_model.h"

namespace gravcal {

struct GyroStaticResidual {
  GyroStaticResidual(const Eigen::Vector3d& raw_mean, const Eigen::Vector3d& force,
                     const Eigen::Matrix3d& sqrt_information, double temperature_offset = 0.0,
                     double time_offset = 0.0)
      : raw_mean_(raw_mean),
        force_(force),
        sqrt_information_(sqrt_information),
        temperature_offset_(temperature_offset),
        time_offset_(time_offset) {}

  // Without effects: b_g, M_g.
  template <typename T>
  bool operator()(const T* const bias, const T* const matrix, T* residual) const {
    return Evaluate<false, T>(bias, matrix, nullptr, nullptr, residual);
  }
  // Without effects: b_g, M_g, G.
  template <typename T>
  bool operator()(const T* const bias, const T* const matrix, const T* const g_sensitivity,
                  T* residual) const {
    return Evaluate<false, T>(bias, matrix, g_sensitivity, nullptr, residual);
  }
  // With effects: b_g and the effects' block (a functor of its own: the
  // form without effects also takes two blocks).
  struct WithEffects;

  static ceres::CostFunction* Create(const Eigen::Vector3d& raw_mean, const Eigen::Vector3d& force,
                                     const Eigen::Matrix3d& sqrt_information, bool g_sensitivity) {
    auto* functor = new GyroStaticResidual(raw_mean, force, sqrt_information);
    if (g_sensitivity) {
      return new ceres::AutoDiffCostFunction<GyroStaticResidual, 3, 3, 9, 9>(functor);
    }
    return new ceres::AutoDiffCostFunction<GyroStaticResidual, 3, 3, 9>(functor);
  }

  // temperature_offset = T_k - T_ref (0 when unknown), time_offset = t_k -
  // t_ref.
  static ceres::CostFunction* CreateWithEffects(const Eigen::Vector3d& raw_mean,
                                                const Eigen::Matrix3d& sqrt_information,
                                                const Eigen::Vector3d& force,
                                                double temperature_offset, double time_offset);

 private:
  // kEffects: matrix is unused (M_g = I) and the effects make o_k;
  // otherwise o_k = 0 and g_sensitivity is G (may be null). Each form keeps
  // its own order of operations.
  template <bool kEffects, typename T>
  bool Evaluate(const T* bias, const T* matrix, const T* g_sensitivity, const T* effects,
                T* residual) const {
    GyroBlocks<T> gyro;
    gyro.bias = bias;
    T e[3];
    if constexpr (kEffects) {
      PointIntoBlocks<T>(nullptr, effects, gyro.effect);
      ImuModel<T>(gyro).GyroRestError(raw_mean_, force_.data(), temperature_offset_, time_offset_,
                                      e);
      for (int r = 0; r < 3; ++r) {
        residual[r] = T(sqrt_information_(r, 0)) * e[0] + T(sqrt_information_(r, 1)) * e[1] +
                      T(sqrt_information_(r, 2)) * e[2];
      }
    } else {
      gyro.matrix = matrix;
      gyro.g_sensitivity = g_sensitivity;
      ImuModel<T>(gyro).GyroRate(raw_mean_, force_.data(), e);
      for (int r = 0; r < 3; ++r) {
        residual[r] = sqrt_information_(r, 0) * e[0] + sqrt_information_(r, 1) * e[1] +
                      sqrt_information_(r, 2) * e[2];
      }
    }
    return true;
  }

  const Eigen::Vector3d raw_mean_;
  const Eigen::Vector3d force_;
  const Eigen::Matrix3d sqrt_information_;
  const double temperature_offset_;
  const double time_offset_;
};

struct GyroStaticResidual::WithEffects {
  template <typename T>
  bool operator()(const T* const bias, const T* const effects, T* residual) const {
    return residual_.template Evaluate<true, T>(bias, nullptr, nullptr, effects, residual);
  }
  const GyroStaticResidual residual_;
};

inline ceres::CostFunction* GyroStaticResidual::CreateWithEffects(
    const Eigen::Vector3d& raw_mean, const Eigen::Matrix3d& sqrt_information,
    const Eigen::Vector3d& force, double temperature_offset, double time_offset) {
  return new ceres::AutoDiffCostFunction<WithEffects, 3, 3, kGyroEffectParameters>(new WithEffects{
      GyroStaticResidual(raw_mean, force, sqrt_information, temperature_offset, time_offset)});
}

}  // namespace gravcal

#endif  // GRAVCAL_RESIDUALS_GYRO_STATIC_RESIDUAL_H_
