// gravcal/estimation/housing_rotation.h: the rotation R of a = R U (v - b), from the
// positions whose nominal up axis is known.
//
// The magnitude fit gives U and b; the direction of every calibrated vector
// u_k = U (v_k - b) / |U (v_k - b)| in the orthogonalised sensor frame is
// known, and so is the housing axis n_k that was meant to point up. R is the
// rotation that best maps the u_k onto the n_k (Kabsch / orthogonal
// Procrustes through the SVD of sum_k n_k u_k^T). Each position was placed
// with some tilt error, which the residual angles e_k = u_k x ... show; with
// sigma_t^2 their variance per axis,
//
//   Cov(theta) = nu / (nu - 2) sigma_t^2 (sum_k (I - n_k n_k^T))^-1,
//
// with nu = 2 K - 3 the degrees of freedom of sigma_t^2 (K axis-aligned
// positions): the factor is the variance of Student's t, because sigma_t is
// estimated from the same residuals.
// theta the small rotation vector of R (R_true = exp([theta]x) R). A rotation
// about a single axis seen is not determined: at least two different axes
// must have been up.
#ifndef GRAVCAL_ESTIMATION_HOUSING_ROTATION_H_
#define GRAVCAL_ESTIMATION_HOUSING_ROTATION_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "gravcal/core/accel_model.h"
#include "gravcal/core/position.h"

namespace gravcal {

struct HousingRotation {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  // Covariance of the small rotation vector, rad^2.
  Eigen::Matrix3d angle_covariance = Eigen::Matrix3d::Zero();
  // RMS placement (tilt) error seen in the positions, rad per axis.
  double tilt_rms = 0.0;
  int positions_used = 0;
};

// Uses the positions with nominal_up[k] >= 0. Returns false (saying why)
// when fewer than two different axes were up or there are fewer than 3 such
// positions (no way to estimate the tilt spread).
bool EstimateHousingRotation(const std::vector<Position>& positions,
                             const std::vector<int>& nominal_up, const AccelModel& model,
                             HousingRotation* result, std::string* error);

}  // namespace gravcal

#endif  // GRAVCAL_ESTIMATION_HOUSING_ROTATION_H_
