#include "gravcal/io/calibration_models.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "gravcal/core/imu_model.h"
#include "util/error.h"

namespace gravcal {

bool ModelsFromCalibration(const Calibration& calibration, const std::string& name,
                           LoadedCalibration* models, std::string* error) {
  LoadedCalibration out;
  ImuCorrector& corrector = out.corrector;
  corrector.accel = calibration.accel.model;
  if (calibration.gyro.estimated) {
    corrector.has_gyro = true;
    corrector.gyro = calibration.gyro.model;
  }
  const EffectCalibration& effects = calibration.effects;
  if (!effects.estimates.empty()) {
    corrector.effects.reference_time = effects.reference_time;
    corrector.effects.reference_temperature = effects.reference_temperature;
  }
  for (const EffectEstimate& estimate : effects.estimates) {
    // accel_misalignment is the off-diagonal of accel.upper.
    if (estimate.effect == Effect::kAccelMisalignment) continue;
    const std::string key = std::string("effects.") + ToString(estimate.effect);
    std::vector<double> values = estimate.values;
    for (size_t i = 0; i < values.size(); ++i) {
      if (std::isfinite(values[i])) continue;
      out.undetermined.push_back(key + "." + Info(estimate.effect).parameter_names[i]);
      values[i] = 0.0;
    }
    if (!SetEffectValues(estimate.effect, values, &corrector.effects)) {
      return internal::SetError(error, name + ": key '" + key + ".value': must have " +
                                           std::to_string(Info(estimate.effect).num_parameters) +
                                           " numbers");
    }
    if (Info(estimate.effect).sensor == EffectSensor::kGyroscope && !corrector.has_gyro) {
      return internal::SetError(error, name + ": key '" + key +
                                           "': is a gyroscope effect but there is no gyroscope "
                                           "model");
    }
    corrector.active_effects.push_back(estimate.effect);
  }
  // In the order a file gives them (its keys sorted by name).
  std::sort(corrector.active_effects.begin(), corrector.active_effects.end(),
            [](Effect a, Effect b) { return std::string(ToString(a)) < ToString(b); });
  if (!effects.estimates.empty()) {
    if (corrector.RequiresTemperature() &&
        !std::isfinite(corrector.effects.reference_temperature)) {
      return internal::SetError(error, name +
                                           ": key 'effects.reference_temperature': must be a "
                                           "number when a temperature effect is present");
    }
    if (!std::isfinite(corrector.effects.reference_temperature)) {
      corrector.effects.reference_temperature = 0.0;
    }
  }
  for (const PositionReport& report : calibration.positions) {
    RecordedPosition p;
    p.raw_mean = report.position.raw_mean;
    p.time = 0.5 * (report.position.t_begin + report.position.t_end);
    p.temperature = report.position.temperature;
    out.positions.push_back(p);
  }
  out.corrector.thermal = calibration.thermal;
  out.gravity = calibration.gravity;
  out.method = calibration.method;
  out.provenance = calibration.provenance;
  if (!CheckCalibrationModels(out, name, error)) return false;
  *models = std::move(out);
  return true;
}

}  // namespace gravcal
