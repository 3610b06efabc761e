// gravcal/residuals/gravity_magnitude_residual.h: the per-position Ceres residual.
//
// For a static position with mean raw accelerometer vector v_k,
//
//   r_k = ( |U (v_k - b)| - g ) / sigma_k
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
// Another estimator can add this residual to its own problem, sharing the
// bias and upper blocks with its other residuals.
#ifndef GRAVCAL_RESIDUALS_GRAVITY_MAGNITUDE_RESIDUAL_H_
#define GRAVCAL_RESIDUALS_GRAVITY_MAGNITUDE_RESIDUAL_H_

#include <ceres/autodiff_cost_function.h>
#include <ceres/ceres.h>

#include <Eigen/Core>

namespace gravcal {

struct GravityMagnitudeResidual {
  GravityMagnitudeResidual(const Eigen::Vector3d& raw_mean, double gravity, double sigma)
      : raw_mean_(raw_mean), gravity_(gravity), sigma_(sigma) {}

  template <typename T>
  bool operator()(const T* const bias, const T* const upper, T* residual) const {
    const T d0 = T(raw_mean_(0)) - bias[0];
    const T d1 = T(raw_mean_(1)) - bias[1];
    const T d2 = T(raw_mean_(2)) - bias[2];
    const T a0 = upper[0] * d0 + upper[1] * d1 + upper[2] * d2;
    const T a1 = upper[3] * d1 + upper[4] * d2;
    const T a2 = upper[5] * d2;
    using std::sqrt;
    residual[0] = (sqrt(a0 * a0 + a1 * a1 + a2 * a2) - T(gravity_)) / T(sigma_);
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& raw_mean, double gravity,
                                     double sigma) {
    return new ceres::AutoDiffCostFunction<GravityMagnitudeResidual, 1, 3, 6>(
        new GravityMagnitudeResidual(raw_mean, gravity, sigma));
  }

 private:
  const Eigen::Vector3d raw_mean_;
  const double gravity_;
  const double sigma_;
};

}  // namespace gravcal

#endif  // GRAVCAL_RESIDUALS_GRAVITY_MAGNITUDE_RESIDUAL_H_
