// gravcal/methods/twelve_position_method.h: the twelve-position method as
// `method: twelve_position` runs it, assembled from its steps on one
// session's static poses (detected once):
//   1. the accelerometer from the gravity magnitude (twelve_position.h,
//      CalibrateAccelerometer);
//   2. the effects beyond the textbook model, when any are asked for
//      (effect_fit.h, FitCalibrationEffects);
//   3. the gyroscope from the rotations between the poses, unless its
//      parameterisation is none (gyro_calibration.h, AddGyroscopeCalibration).
// The session's noise model, when it has one, gives the covariance of each
// pose's mean and the gyroscope's bias wander.
#ifndef GRAVCAL_METHODS_TWELVE_POSITION_METHOD_H_
#define GRAVCAL_METHODS_TWELVE_POSITION_METHOD_H_

#include <string>
#include <vector>

#include "gravcal/core/calibration.h"
#include "gravcal/core/types.h"
#include "gravcal/methods/gyro_calibration.h"
#include "gravcal/methods/session.h"
#include "gravcal/methods/twelve_position.h"

namespace gravcal {

// The sections the method reads.
struct TwelvePositionMethodOptions {
  // Gravity, detector, pose noise, model and solver (step 1; also the poses
  // of steps 2 and 3).
  CalibrationOptions accel;
  // Step 3; parameterization kNone leaves the gyroscope out.
  GyroCalibrationOptions gyro;
  // Step 2; empty = none. accel_misalignment on the `scale` model makes the
  // accelerometer fit `scale_misalignment`.
  std::vector<Effect> effects;

  bool IsValid(std::string* error) const;
};

// Runs the steps above on the session. Returns false with a one-line
// calibration->message when a step fails (the steps before it stay filled).
bool CalibrateTwelvePosition(const Session& session, const TwelvePositionMethodOptions& options,
                             Calibration* calibration);

}  // namespace gravcal

#endif  // GRAVCAL_METHODS_TWELVE_POSITION_METHOD_H_
