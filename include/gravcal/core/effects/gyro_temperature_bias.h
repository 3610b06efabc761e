// gravcal/core/effects/gyro_temperature_bias.h: one effect of the registry
// (core/effect_registry.h).
//
// The gyroscope bias linear in temperature, raw gyroscope units per degree
// C: o_i += gamma_i dT.
#ifndef GRAVCAL_CORE_EFFECTS_GYRO_TEMPERATURE_BIAS_H_
#define GRAVCAL_CORE_EFFECTS_GYRO_TEMPERATURE_BIAS_H_

#include "gravcal/core/effects/effect_definition.h"

namespace gravcal {
namespace effects {

struct GyroTemperatureBias {
  static constexpr const char* kName = "gyro_temperature_bias";
  static constexpr const char* kDescription =
      "gyroscope bias linear in temperature (raw gyro units per degree C)";
  static constexpr EffectSensor kSensor = EffectSensor::kGyroscope;
  static constexpr EffectRegressor kRegressor = EffectRegressor::kTemperature;
  static constexpr EffectForm kForm = EffectForm::kGyroOffset;
  static constexpr int kSize = 3;
  static constexpr const char* kParameters[kSize] = {"gamma_x", "gamma_y", "gamma_z"};
  static constexpr const char* kUnit = "raw gyro units/degC";
  static constexpr EffectSimulation kSimulation = {
      "sim_gyro_temperature_bias", "gyro_temperature_bias_std",
      "truth gyroscope bias tempco spread, rad/s/degC"};
  static constexpr const char* kC = "p[i] * dT";

  template <typename T>
  static void Add(const T* gamma, int i, const double* /*force*/, double dT, double /*dt*/, T* o) {
    *o += gamma[i] * T(dT);
  }
};

}  // namespace effects
}  // namespace gravcal

#endif  // GRAVCAL_CORE_EFFECTS_GYRO_TEMPERATURE_BIAS_H_
