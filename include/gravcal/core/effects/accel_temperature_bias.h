// gravcal/core/effects/accel_temperature_bias.h: one effect of the registry
// (core/effect_registry.h).
//
// The accelerometer bias linear in temperature, m/s^2 per degree C:
//
//   o_i = beta_i dT,     d o / d dT = beta.
#ifndef GRAVCAL_CORE_EFFECTS_ACCEL_TEMPERATURE_BIAS_H_
#define GRAVCAL_CORE_EFFECTS_ACCEL_TEMPERATURE_BIAS_H_

#include "gravcal/core/effects/effect_definition.h"

namespace gravcal {
namespace effects {

struct AccelTemperatureBias {
  static constexpr const char* kName = "accel_temperature_bias";
  static constexpr const char* kDescription =
      "accelerometer bias linear in temperature (m/s^2 per degree C)";
  static constexpr EffectSensor kSensor = EffectSensor::kAccelerometer;
  static constexpr EffectRegressor kRegressor = EffectRegressor::kTemperature;
  static constexpr EffectForm kForm = EffectForm::kAccelOffset;
  static constexpr int kSize = 3;
  static constexpr const char* kParameters[kSize] = {"beta_x", "beta_y", "beta_z"};
  static constexpr const char* kUnit = "m/s^2/degC";
  static constexpr EffectSimulation kSimulation = {
      "sim_accel_temperature_bias", "accel_temperature_bias_std",
      "truth accelerometer bias tempco spread, m/s^2/degC"};
  static constexpr const char* kC = "p[i] * dT";

  template <typename T>
  static void Add(const T* beta, int i, double dT, double /*dt*/, T* x) {
    *x += beta[i] * T(dT);
  }
  template <typename T>
  static void Remove(const T* beta, int i, double dT, double /*dt*/, T* x) {
    *x -= beta[i] * T(dT);
  }
  template <typename T>
  static T RateT(const T* beta, int i, double /*dT*/) {
    return beta[i];
  }
  template <typename T>
  static T Ratet(const T* /*beta*/, int /*i*/) {
    return T(0.0);
  }
};

}  // namespace effects
}  // namespace gravcal

#endif  // GRAVCAL_CORE_EFFECTS_ACCEL_TEMPERATURE_BIAS_H_
