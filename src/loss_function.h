// Private: the Ceres robust loss of a LossType, shared by the fits that
// offer one (refinement, gyroscope calibration).
#ifndef GRAVCAL_SRC_LOSS_FUNCTION_H_
#define GRAVCAL_SRC_LOSS_FUNCTION_H_

#include <ceres/loss_function.h>

#include "gravcal/refinement.h"

namespace gravcal {

// A new loss of `type` with `scale` (caller owns it), or nullptr for kNone.
ceres::LossFunction* MakeLoss(LossType type, double scale);

}  // namespace gravcal

#endif  // GRAVCAL_SRC_LOSS_FUNCTION_H_
