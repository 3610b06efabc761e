// Private: the rotations between poses as rows of the accelerometer effect
// fit (effect_fit.h, use_between_pose_rotations; issue 21): which
// observations a turn joins, the gyroscope's normalisation and starting
// values, and the weight of every AccelRotationResidual.
//
// The gyroscope of a turn from pose s to pose e enters about its local
// level at rest and normalised, u' = (u - l) * scale, l = (ubar_s +
// ubar_e) / 2 the mean of the two poses' static means, scale the cube root
// of |det M_0| of the linear initial matrix (gyro_initial_matrix.h), so
// that M_g' is near a rotation and b_g' (common to all turns) near 0:
// M_g = scale M_g'. The local level takes out what moves the bias over the
// session (drift, temperature, the wander of bias instability and random
// walk): a hidden gyroscope drift or temperature bias is then not taken for
// an accelerometer effect. A g-sensitivity G f changes during the turn and
// is not modelled; the fit warns when the rows exceed their noise.
// result->rotation_gyro_bias reports center + b_g' / scale, center the
// mean of all static means.
//
// Weights. The direction error e = E (R(dq)^T d_s - d_e) of a turn has the
// covariance
//
//   C = E ( C_e + R^T C_s R + [p]x (A_w + A_b) [p]x^T ) E^T,   p = R^T d_s,
//
// with R = R(dq) the integrated turn, C_s and C_e the covariances of the two
// poses' directions (from each pose's covariance of the mean plus the extra
// magnitude variance s^2 of the fit, isotropic in m/s^2:
// P (U' Sigma_v U'^T + s^2 I) P^T, P = (I - d d^T) / |a|), A_w the
// integrated white noise of the gyroscope over the turn (per sample the
// pooled still covariance of the poses, weighted by its share c_i of the
// trapezoid and turned into the end frame: sum c_i^2 R^T R_i Sigma_w R_i^T
// R) and A_b = B (M_g' (Sigma_s + Sigma_e) M_g'^T / 4 + V) B^T, B = sum c_i
// R^T R_i, from the noise of the local level (the two static means'
// covariances Sigma) and the wander V of the bias about it
// (rotation_gyro_bias_variance), both constant over the turn.
// W = chol(C)^-1. The
// weights are fixed per solve, computed at the start of the fit after a
// first fit of the gyroscope alone with the accelerometer held.
#ifndef GRAVCAL_SRC_METHODS_BETWEEN_POSE_ROTATIONS_H_
#define GRAVCAL_SRC_METHODS_BETWEEN_POSE_ROTATIONS_H_

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "estimation/normalization.h"
#include "gravcal/core/accel_model.h"
#include "gravcal/core/model_effects.h"
#include "gravcal/estimation/solver_tolerances.h"
#include "gravcal/methods/effect_fit.h"
#include "gravcal/residuals/accel_rotation_residual.h"

namespace gravcal {
namespace internal {

// Turns needed at least: 2 rows each must exceed the gyroscope's 12
// parameters.
constexpr int kMinRotations = 7;

// (from, to) observation indices of every turn: observation `to` carries a
// turn and observation `from` has the previous session index; both have a
// gyroscope.
std::vector<std::pair<int, int>> TurnPairs(const std::vector<StaticObservation>& observations);

// The accelerometer's parameter blocks in the fit's normalised units
// (normalization.h): b', U' and the effects' block (kAccelEffectParameters,
// in SI units).
struct AccelBlocks {
  const double* blocks[3];
};

struct RotationRows {
  std::vector<std::pair<int, int>> poses;
  // u' = (u - center) * scale.
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double scale = 1.0;
  // Parameter blocks of the gyroscope (normalised), b_g' and M_g' row-major.
  double gyro_bias[3] = {0.0, 0.0, 0.0};
  double gyro_matrix[9] = {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};
  // One per turn, with its tangent basis and weight.
  std::vector<AccelRotationData> data;
};

// Builds the rows of every turn of `observations` (normalised accelerometer
// units `norm`, offsets from `parameters`' references), fits the gyroscope
// alone with the accelerometer held at `accel`, and weighs every row there.
// `extra_variance` is the fit's extra magnitude variance (m/s^2)^2. False
// with *error when there are fewer than kMinRotations turns or the gyroscope
// cannot be started or weighed.
bool PrepareRotationRows(const std::vector<StaticObservation>& observations,
                         const Normalization& norm, const EffectParameters& parameters,
                         const AccelBlocks& accel, double extra_variance, double gyro_bias_variance,
                         const SolverTolerances& solver, RotationRows* rows, std::string* error);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_METHODS_BETWEEN_POSE_ROTATIONS_H_
