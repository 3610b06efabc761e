#include "gravcal/pipeline.h"

#include "gravcal/effect_fit.h"

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
    bool ok = CalibrateAccelerometer(input.log, options, calibration);
    if (ok && !config.effects.empty()) {
      ok = FitCalibrationEffects(input.log, options, config.effects, calibration);
    }
    calibration->method = config.method;
    return ok;
  }
  calibration->message = "key 'method': unknown method '" + config.method + "'";
  return false;
}

}  // namespace gravcal
