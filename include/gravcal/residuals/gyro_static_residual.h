// gravcal/residuals/gyro_static_residual.h: the per-pose Ceres residual that ties the
// gyroscope bias (and g-sensitivity) to the static poses.
//
// At rest the body rate is zero, so for static pose k with mean raw gyroscope
// vector u_k and mean calibrated specific force f_k (m/s^2, body frame):
//
//   r_k = W_k ( M_g (u_k - b_g) - G f_k )                 3 values
//
// W_k (3x3) is the square-root information of M_g (u_k - b_g) from the
// covariance of the mean u_k, taken at the initial M_g, so r_k is
// dimensionless with unit variance. Without G every pose measures b_g
// directly; with G the poses measure b_g + M_g^-1 G f_k, which separates b_g
// from G when the f_k span three dimensions (four or more poses not in one
// plane). Parameter blocks: b_g (3), M_g (9, row-major) and optionally G (9).
#ifndef GRAVCAL_RESIDUALS_GYRO_STATIC_RESIDUAL_H_
#define GRAVCAL_RESIDUALS_GYRO_STATIC_RESIDUAL_H_

#include <ceres/autodiff_cost_function.h>
#include <ceres/ceres.h>

#include <Eigen/Core>

namespace gravcal {

struct GyroStaticResidual {
  GyroStaticResidual(const Eigen::Vector3d& raw_mean, const Eigen::Vector3d& force,
                     const Eigen::Matrix3d& sqrt_information)
      : raw_mean_(raw_mean), force_(force), sqrt_information_(sqrt_information) {}

  template <typename T>
  bool operator()(const T* const bias, const T* const matrix, T* residual) const {
    return Evaluate<T>(bias, matrix, nullptr, residual);
  }
  template <typename T>
  bool operator()(const T* const bias, const T* const matrix, const T* const g_sensitivity,
                  T* residual) const {
    return Evaluate<T>(bias, matrix, g_sensitivity, residual);
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& raw_mean, const Eigen::Vector3d& force,
                                     const Eigen::Matrix3d& sqrt_information, bool g_sensitivity) {
    auto* functor = new GyroStaticResidual(raw_mean, force, sqrt_information);
    if (g_sensitivity) {
      return new ceres::AutoDiffCostFunction<GyroStaticResidual, 3, 3, 9, 9>(functor);
    }
    return new ceres::AutoDiffCostFunction<GyroStaticResidual, 3, 3, 9>(functor);
  }

 private:
  template <typename T>
  bool Evaluate(const T* bias, const T* matrix, const T* g_sensitivity, T* residual) const {
    const T d[3] = {T(raw_mean_(0)) - bias[0], T(raw_mean_(1)) - bias[1],
                    T(raw_mean_(2)) - bias[2]};
    T w[3];
    for (int r = 0; r < 3; ++r) {
      w[r] = matrix[3 * r] * d[0] + matrix[3 * r + 1] * d[1] + matrix[3 * r + 2] * d[2];
      if (g_sensitivity != nullptr) {
        w[r] -= g_sensitivity[3 * r] * force_(0) + g_sensitivity[3 * r + 1] * force_(1) +
                g_sensitivity[3 * r + 2] * force_(2);
      }
    }
    for (int r = 0; r < 3; ++r) {
      residual[r] = sqrt_information_(r, 0) * w[0] + sqrt_information_(r, 1) * w[1] +
                    sqrt_information_(r, 2) * w[2];
    }
    return true;
  }

  const Eigen::Vector3d raw_mean_;
  const Eigen::Vector3d force_;
  const Eigen::Matrix3d sqrt_information_;
};

}  // namespace gravcal

#endif  // GRAVCAL_RESIDUALS_GYRO_STATIC_RESIDUAL_H_
