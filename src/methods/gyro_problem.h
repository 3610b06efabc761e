// Private: the Ceres problem of the rotations gyroscope calibration
// (gyro_calibration.h): the ambient parameter vector, its free directions,
// the weights of every residual at an estimate, the problem at those weights
// and its whitened Jacobian.
#ifndef GRAVCAL_SRC_METHODS_GYRO_PROBLEM_H_
#define GRAVCAL_SRC_METHODS_GYRO_PROBLEM_H_

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "estimation/normalization.h"
#include "gravcal/core/accel_model.h"
#include "gravcal/methods/gyro_calibration.h"
#include "gravcal/residuals/gyro_rotation_residual.h"
#include "methods/gyro_rotations.h"

namespace gravcal {
namespace internal {

constexpr const char* kGyroAxisNames = "xyz";

// The ambient parameter vector: b' (3), M' (9), [G (9)], [b_a' (3), U' (6)]
// in normalised units (gyro_rotations.h, normalization.h), with their names.
struct GyroLayout {
  int bias = 0;
  int matrix = 3;
  int g = -1;
  int accel_bias = -1;
  int accel_upper = -1;
  int size = 12;
  std::vector<std::string> names;

  GyroLayout(bool with_g, bool joint);
};

// Free directions of the ambient vector: column j of `basis` holds the
// ambient entries free column j moves (the tangent space Ceres sees, in the
// same order: blocks in layout order, entries ascending).
struct GyroFreeColumns {
  std::vector<std::string> names;
  Eigen::MatrixXd basis;
};

GyroFreeColumns MakeGyroFreeColumns(const GyroLayout& layout, GyroParameterization gp,
                                    AccelParameterization ap, const std::vector<bool>& held);

// The accelerometer at x (joint) or the fixed one.
AccelModel GyroAccelAt(const std::vector<double>& x, const GyroLayout& layout,
                       const AccelModel& accel, const Normalization& norm);

// The weights of every residual at one estimate.
struct GyroWeights {
  // Rotation data with directions, tangent bases and square-root information.
  std::vector<GyroRotationData> rotations;
  // Expected size of each rotation residual, degrees.
  std::vector<double> sigma_deg;
  // The integrated attitude change R(dq) of each rotation.
  std::vector<Eigen::Matrix3d> turns;
  // Square-root information of the static poses' mean rates.
  std::vector<Eigen::Matrix3d> static_information;
};

// Weighs every residual at x with the accelerometer accel_now. Returns false
// with *error when a rotation or pose has no usable noise estimate.
bool WeighGyroResiduals(const GyroPrepared& prep, const GyroLayout& layout,
                        const std::vector<double>& x, const AccelModel& accel_now,
                        const Normalization& norm, GyroWeights* weights, std::string* error);

// One Ceres problem at one set of weights.
struct GyroProblem {
  std::unique_ptr<ceres::Problem> problem;
  struct Block {
    const ceres::CostFunction* cost = nullptr;
    std::vector<int> offsets;
  };
  // Residual blocks in order: static poses, rotations, [magnitudes].
  std::vector<Block> blocks;
  int rows = 0;
  // The non-constant parameter blocks, in layout order.
  std::vector<const double*> free_blocks;
};

// Builds the problem over *x: the static and rotation residuals (robust
// loss from the options), the joint magnitude residuals, and the held
// entries (fixed by the parameterization or by `held`) as constants or
// manifolds.
void BuildGyroProblem(const GyroPrepared& prep, const GyroLayout& layout,
                      const GyroCalibrationOptions& options, AccelParameterization ap,
                      const std::vector<bool>& held, const GyroWeights& weights,
                      const std::vector<double>& magnitude_sigmas, double gravity,
                      std::vector<double>* x, GyroProblem* built);

// The whitened Jacobian of all residuals (no loss) with respect to the
// ambient parameters at x.
Eigen::MatrixXd GyroAmbientJacobian(const GyroProblem& built, const GyroLayout& layout,
                                    std::vector<double>* x);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_METHODS_GYRO_PROBLEM_H_
