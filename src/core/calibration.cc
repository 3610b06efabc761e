#include "gravcal/core/calibration.h"

#include <algorithm>
#include <cmath>

#include "gravcal/core/imu_model.h"
#include "util/error.h"
#include "util/statistics.h"

namespace gravcal {

using internal::MaxAbs;
using internal::Rms;

ResidualSummary SummarizeResiduals(const std::vector<double>& residuals) {
  return {Rms(residuals), MaxAbs(residuals)};
}

bool Calibration::Model(ImuCorrector* model, std::vector<std::string>* undetermined,
                        std::string* error) const {
  ImuCorrector corrector;
  corrector.accel = accel.model;
  if (gyro.estimated) {
    corrector.has_gyro = true;
    corrector.gyro = gyro.model;
  }
  if (!effects.estimates.empty()) {
    corrector.effects.reference_time = effects.reference_time;
    corrector.effects.reference_temperature = effects.reference_temperature;
  }
  for (const EffectEstimate& estimate : effects.estimates) {
    // accel_misalignment is the off-diagonal of accel.upper.
    if (Info(estimate.effect).form == EffectForm::kInUpper) continue;
    const EffectInfo& info = Info(estimate.effect);
    const std::string key = std::string("effects.") + info.name;
    std::vector<double> values = estimate.values;
    for (size_t i = 0; i < values.size(); ++i) {
      if (std::isfinite(values[i])) continue;
      if (undetermined != nullptr && i < info.parameter_names.size()) {
        undetermined->push_back(key + "." + info.parameter_names[i]);
      }
      values[i] = 0.0;
    }
    if (!corrector.effects.SetValues(estimate.effect, values)) {
      return internal::SetError(error, "key '" + key + ".value': must have " +
                                           std::to_string(info.num_parameters) + " numbers");
    }
    if (info.sensor == EffectSensor::kGyroscope && !corrector.has_gyro) {
      return internal::SetError(
          error, "key '" + key + "': is a gyroscope effect but there is no gyroscope model");
    }
    corrector.active_effects.push_back(estimate.effect);
  }
  // In the order a file gives them (its keys sorted by name).
  std::sort(corrector.active_effects.begin(), corrector.active_effects.end(),
            [](Effect a, Effect b) { return std::string(ToString(a)) < ToString(b); });
  if (!effects.estimates.empty()) {
    if (corrector.RequiresTemperature() &&
        !std::isfinite(corrector.effects.reference_temperature)) {
      return internal::SetError(error,
                                "key 'effects.reference_temperature': must be a number when a "
                                "temperature effect is present");
    }
    if (!std::isfinite(corrector.effects.reference_temperature)) {
      corrector.effects.reference_temperature = 0.0;
    }
  }
  *model = std::move(corrector);
  return true;
}

}  // namespace gravcal
