// Private: the linear initial estimate of the gyroscope matrix M_g for the
// rotations gyroscope calibration, so that no nominal scale is needed.
#ifndef GRAVCAL_SRC_METHODS_GYRO_INITIAL_MATRIX_H_
#define GRAVCAL_SRC_METHODS_GYRO_INITIAL_MATRIX_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "gravcal/core/imu_log.h"
#include "gravcal/methods/gyro_calibration.h"
#include "methods/gyro_rotations.h"

namespace gravcal {
namespace internal {

// Linear initial M_g from df/dt = f x w over short windows of the
// rotations: f(t + T) - f(t) = sum_i h_i [f_i]x M (u_i - c), one 3x9 block
// per window (row-major vec(M)); forces[n] is the calibrated specific force
// along segments[n], center the c above. The common scale is fitted first;
// the free entries are then pulled weakly towards it, so an axis the
// rotations do not excite stays at the common scale instead of at noise.
// Returns false with *error on rotations that show no turning.
bool GyroInitialMatrix(const ImuLog& log, const std::vector<GyroSegment>& segments,
                       const std::vector<std::vector<Eigen::Vector3d>>& forces,
                       const Eigen::Vector3d& center, GyroParameterization p, Eigen::Matrix3d* m0,
                       std::string* error);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_METHODS_GYRO_INITIAL_MATRIX_H_
