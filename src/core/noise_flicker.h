// Private: the bias instability's flicker part of a noise model's Allan
// variance, shared by the model's Allan variance (core/noise_model.cc) and
// the gyroscope bias's wander over a session (methods/gyro_bias_wander.cc,
// methods/calibration_effects.cc).
#ifndef GRAVCAL_SRC_CORE_NOISE_FLICKER_H_
#define GRAVCAL_SRC_CORE_NOISE_FLICKER_H_

#include "gravcal/core/noise_model.h"

namespace gravcal {
namespace internal {

// kFlickerAllanFactor B^2 less the other terms' Allan variance at B's tau
// (at least 0): a B read at the curve's floor holds the white noise's,
// quantisation's and random walk's share there. A B without a tau (a
// datasheet's) is all flicker; 0 when B is not shown. Divided by
// kFlickerAllanFactor it is the B^2 of the flicker alone.
double FlickerAllanVariance(const AxisNoiseModel& axis);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_CORE_NOISE_FLICKER_H_
