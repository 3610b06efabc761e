#include "gravcal/methods/twelve_position_method.h"

#include "gravcal/core/model_effects.h"
#include "gravcal/methods/effect_fit.h"
#include "methods/static_positions.h"

namespace gravcal {

bool TwelvePositionMethodOptions::IsValid(std::string* error) const {
  return accel.IsValid(error) && gyro.IsValid(error);
}

bool CalibrateTwelvePosition(const Session& session, const TwelvePositionMethodOptions& options,
                             Calibration* calibration) {
  CalibrationOptions accel = options.accel;
  if (session.noise) accel.pose_noise.model = session.noise_model();
  // accel_misalignment on a scale baseline is the scale_misalignment model.
  const std::vector<Effect>& effects = options.effects;
  if (Contains(effects, Effect::kAccelMisalignment) &&
      accel.refinement.parameterization == AccelParameterization::kScale) {
    accel.refinement.parameterization = AccelParameterization::kScaleMisalignment;
  }
  // The effect and gyroscope steps reuse the accelerometer's intervals.
  std::vector<StaticInterval> intervals;
  bool ok = internal::CalibrateAccelerometer(session, accel, calibration, &intervals);
  if (ok && !effects.empty()) {
    ok = FitCalibrationEffects(session.log, intervals, accel, effects, calibration);
  }
  if (ok && options.gyro.parameterization != GyroParameterization::kNone) {
    GyroCalibrationOptions gyro = options.gyro;
    if (session.noise) gyro.noise_model = session.noise_model();
    ok = AddGyroscopeCalibration(session.log, intervals, gyro, calibration);
  }
  calibration->method = ToString(Method::kTwelvePosition);
  return ok;
}

}  // namespace gravcal
