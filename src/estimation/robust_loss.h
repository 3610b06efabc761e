// Private: the Ceres robust loss of a LossType, shared by the Ceres fits
// (refinement, known_attitude, gyroscope calibration).
#ifndef GRAVCAL_SRC_ESTIMATION_ROBUST_LOSS_H_
#define GRAVCAL_SRC_ESTIMATION_ROBUST_LOSS_H_

#include <ceres/loss_function.h>

#include <vector>

#include "gravcal/estimation/refinement.h"

namespace gravcal {
namespace internal {

// A new loss with the given scale (in whitened units), or nullptr for kNone.
ceres::LossFunction* MakeLoss(LossType type, double scale);

// The graduated loss scales of a robust solve, narrowest first: loss_scale,
// then doubled while the double stays below `largest_whitened` (the largest
// initial whitened residual), so the widest stage holds every residual and is
// close to least squares. Just {loss_scale} for kNone.
std::vector<double> GraduatedLossScales(LossType type, double loss_scale, double largest_whitened);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_ESTIMATION_ROBUST_LOSS_H_
