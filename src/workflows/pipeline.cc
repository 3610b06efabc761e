#include "gravcal/workflows/pipeline.h"

#include "gravcal/methods/effect_fit.h"
#include "gravcal/methods/gyro_calibration.h"
#include "gravcal/methods/handheld_kalman.h"
#include "gravcal/methods/known_attitude.h"
#include "gravcal/methods/ten_position.h"

namespace gravcal {

bool RunCalibration(const Config& config, const PipelineInput& input, Calibration* calibration) {
  *calibration = Calibration();
  std::string error;
  if (!config.IsValid(&error)) {
    calibration->message = error;
    return false;
  }
  // One branch per method; each fills the same Calibration.
  if (config.method == "twelve_position") {
    // accel_misalignment on a scale baseline is the scale_misalignment model.
    CalibrationOptions options = config.calibration;
    if (Contains(config.effects, Effect::kAccelMisalignment) &&
        options.refinement.parameterization == AccelParameterization::kScale) {
      options.refinement.parameterization = AccelParameterization::kScaleMisalignment;
    }
    // Detected once; the effect and gyroscope steps reuse the intervals.
    std::vector<StaticInterval> intervals;
    bool ok = CalibrateAccelerometer(input.log, options, calibration, &intervals);
    if (ok && !config.effects.empty()) {
      ok = FitCalibrationEffects(input.log, intervals, options, config.effects, calibration);
    }
    calibration->method = config.method;
    if (!ok || config.gyro.parameterization == GyroParameterization::kNone) return ok;
    return AddGyroscopeCalibration(input.log, intervals, config.gyro, calibration);
  }
  if (config.method == "ten_position") {
    return CalibrateTenPosition(input.log, config.calibration, config.ten_position, calibration);
  }
  if (config.method == "known_attitude") {
    return CalibrateKnownAttitude(input.log, input.attitudes_path, config.calibration, calibration);
  }
  if (config.method == "handheld_kalman") {
    HandheldKalmanOptions options = config.handheld;
    options.gravity = config.calibration.gravity;
    options.accel_nominal_scale = config.calibration.nominal_scale;
    const bool ok = CalibrateHandheld(input.log, options, calibration);
    calibration->method = config.method;
    return ok;
  }
  calibration->message = "key 'method': unknown method '" + config.method + "'";
  return false;
}

}  // namespace gravcal
