// Private: the Ceres robust loss of a LossType, shared by the Ceres fits
// (refinement, known_attitude, gyroscope calibration).
#ifndef GRAVCAL_SRC_ESTIMATION_ROBUST_LOSS_H_
#define GRAVCAL_SRC_ESTIMATION_ROBUST_LOSS_H_

#include <ceres/loss_function.h>

#include "gravcal/estimation/refinement.h"

namespace gravcal {
namespace internal {

// A new loss with the given scale (in whitened units), or nullptr for kNone.
ceres::LossFunction* MakeLoss(LossType type, double scale);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_ESTIMATION_ROBUST_LOSS_H_
