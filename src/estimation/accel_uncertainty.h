// Private: the accelerometer's standard deviations from a magnitude fit's
// covariance, shared by the accelerometer calibration and the joint
// accelerometer + gyroscope fit.
#ifndef GRAVCAL_SRC_ESTIMATION_ACCEL_UNCERTAINTY_H_
#define GRAVCAL_SRC_ESTIMATION_ACCEL_UNCERTAINTY_H_

#include "gravcal/core/calibration.h"
#include "gravcal/estimation/housing_rotation.h"
#include "gravcal/estimation/refinement.h"

namespace gravcal {
namespace internal {

// Fills accel->bias_std, matrix_std and the covariance (with its names) from
// the covariance of (b, free entries of U) in `refinement` and, for affine,
// the housing rotation's; parameters in refinement.observability.undetermined
// get NaN.
void PropagateUncertainty(const RefinementResult& refinement, const HousingRotation* housing,
                          AccelCalibration* accel);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_ESTIMATION_ACCEL_UNCERTAINTY_H_
