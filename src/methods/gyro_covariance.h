// Private: the covariance of the rotations gyroscope calibration's estimate,
// from Ceres in the tangent space, corrected for the poses two rotations
// share and for the held accelerometer's own uncertainty, then mapped to SI.
#ifndef GRAVCAL_SRC_METHODS_GYRO_COVARIANCE_H_
#define GRAVCAL_SRC_METHODS_GYRO_COVARIANCE_H_

#include <Eigen/Core>
#include <vector>

#include "estimation/normalization.h"
#include "gravcal/core/accel_model.h"
#include "gravcal/methods/gyro_calibration.h"
#include "methods/gyro_problem.h"
#include "methods/gyro_rotations.h"

namespace gravcal {
namespace internal {

// Fills result->covariance, parameter_names, the standard deviations and
// (joint) result->accel.covariance from the solved problem at x, with
// `accel` the accelerometer given and `accel_final` the one at x. Leaves a
// warning instead when Ceres cannot compute the covariance (rank deficient).
// accel_covariance: as for CalibrateGyroscope (used when not joint).
void ComputeGyroCovariance(const GyroPrepared& prep, const GyroLayout& layout,
                           const GyroProblem& built, const GyroFreeColumns& free,
                           const GyroWeights& weights, const AccelModel& accel,
                           const AccelModel& accel_final, const Normalization& norm,
                           const Eigen::MatrixXd& accel_covariance, std::vector<double>* x,
                           GyroCalibrationResult* result);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_METHODS_GYRO_COVARIANCE_H_
