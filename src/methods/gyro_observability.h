// Private: which gyroscope parameters the rotations gyroscope calibration
// cannot determine, and the warnings that say what motion is missing.
#ifndef GRAVCAL_SRC_METHODS_GYRO_OBSERVABILITY_H_
#define GRAVCAL_SRC_METHODS_GYRO_OBSERVABILITY_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "gravcal/methods/gyro_calibration.h"
#include "methods/gyro_problem.h"

namespace gravcal {
namespace internal {

// Free parameters the data does not determine: in a null direction of the
// whitened Jacobian (free columns), or with a standard deviation beyond the
// options' limits (normalised units: M' near the identity, G in rad/s per
// m/s^2).
std::vector<std::string> UndeterminedGyroParameters(const Eigen::MatrixXd& jacobian,
                                                    const GyroFreeColumns& free,
                                                    const GyroCalibrationOptions& options);

// Warnings for undetermined gyroscope parameters, grouped by what is missing.
void WarnUndeterminedGyro(const std::vector<std::string>& names,
                          std::vector<std::string>* warnings);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_METHODS_GYRO_OBSERVABILITY_H_
