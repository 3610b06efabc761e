// Private: the local gravity of a calibration, shared by every method that
// starts from a raw log.
#ifndef GRAVCAL_SRC_CORE_CALIBRATION_GRAVITY_H_
#define GRAVCAL_SRC_CORE_CALIBRATION_GRAVITY_H_

#include "gravcal/core/calibration.h"
#include "gravcal/core/gravity.h"

namespace gravcal {
namespace internal {

// Fills calibration->gravity and gravity_source from `options`, and warns
// when it falls back to standard gravity (its error goes into the scale
// factors). Returns false with calibration->message on invalid options.
bool ResolveCalibrationGravity(const GravityOptions& options, Calibration* calibration);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_CORE_CALIBRATION_GRAVITY_H_
