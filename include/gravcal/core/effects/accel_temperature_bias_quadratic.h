// gravcal/core/effects/accel_temperature_bias_quadratic.h: one effect of the
// registry (core/effect_registry.h).
//
// The accelerometer bias quadratic in temperature, m/s^2 per degree C^2: the
// curvature of a MEMS bias-temperature curve (a few hundredths of a mg per
// K^2), which a line through a wide warm-up leaves as a bowl:
//
//   o_i = kappa_i dT^2,     d o / d dT = 2 kappa_i dT.
//
// With accel_temperature_bias it is a parabola about T_ref; the data
// determine it only when the poses span a temperature range.
#ifndef GRAVCAL_CORE_EFFECTS_ACCEL_TEMPERATURE_BIAS_QUADRATIC_H_
#define GRAVCAL_CORE_EFFECTS_ACCEL_TEMPERATURE_BIAS_QUADRATIC_H_

#include "gravcal/core/effects/effect_definition.h"

namespace gravcal {
namespace effects {

struct AccelTemperatureBiasQuadratic {
  static constexpr const char* kName = "accel_temperature_bias_quadratic";
  static constexpr const char* kDescription =
      "accelerometer bias quadratic in temperature (m/s^2 per degree C^2)";
  static constexpr EffectSensor kSensor = EffectSensor::kAccelerometer;
  static constexpr EffectRegressor kRegressor = EffectRegressor::kTemperature;
  static constexpr EffectForm kForm = EffectForm::kAccelOffset;
  static constexpr int kSize = 3;
  static constexpr const char* kParameters[kSize] = {"kappa_x", "kappa_y", "kappa_z"};
  static constexpr const char* kUnit = "m/s^2/degC^2";
  static constexpr EffectSimulation kSimulation = {
      "sim_accel_temperature_bias_quadratic", "accel_temperature_bias_quadratic_std",
      "truth accelerometer bias curvature spread, m/s^2/degC^2"};
  static constexpr const char* kC = "p[i] * (dT * dT)";

  template <typename T>
  static void Add(const T* kappa, int i, double dT, double /*dt*/, T* x) {
    *x += kappa[i] * T(dT * dT);
  }
  template <typename T>
  static void Remove(const T* kappa, int i, double dT, double /*dt*/, T* x) {
    *x -= kappa[i] * T(dT * dT);
  }
  template <typename T>
  static T RateT(const T* kappa, int i, double dT) {
    return T(2.0 * dT) * kappa[i];
  }
  template <typename T>
  static T Ratet(const T* /*kappa*/, int /*i*/) {
    return T(0.0);
  }
};

}  // namespace effects
}  // namespace gravcal

#endif  // GRAVCAL_CORE_EFFECTS_ACCEL_TEMPERATURE_BIAS_QUADRATIC_H_
