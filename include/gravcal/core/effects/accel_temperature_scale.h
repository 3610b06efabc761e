// gravcal/core/effects/accel_temperature_scale.h: one effect of the
// registry (core/effect_registry.h).
//
// The accelerometer scale factor linear in temperature, fraction per degree
// C, acting on the output x of the deeper terms (depth 2):
//
//   y_i = (1 + c_i dT) x_i,     x_i = y_i / (1 + c_i dT),
//
// d y / d x = 1 + c dT, d y / d dT = c x.
#ifndef GRAVCAL_CORE_EFFECTS_ACCEL_TEMPERATURE_SCALE_H_
#define GRAVCAL_CORE_EFFECTS_ACCEL_TEMPERATURE_SCALE_H_

#include "gravcal/core/effects/effect_definition.h"

namespace gravcal {
namespace effects {

struct AccelTemperatureScale {
  static constexpr const char* kName = "accel_temperature_scale";
  static constexpr const char* kDescription =
      "accelerometer scale factor linear in temperature (fraction per degree C)";
  static constexpr EffectSensor kSensor = EffectSensor::kAccelerometer;
  static constexpr EffectRegressor kRegressor = EffectRegressor::kTemperature;
  static constexpr EffectForm kForm = EffectForm::kAccelShape;
  static constexpr int kDepth = 2;
  static constexpr bool kVaries = true;
  static constexpr int kSize = 3;
  static constexpr const char* kParameters[kSize] = {"c_x", "c_y", "c_z"};
  static constexpr const char* kUnit = "1/degC";
  static constexpr EffectSimulation kSimulation = {
      "sim_accel_temperature_scale", "accel_temperature_scale_std",
      "truth accelerometer scale tempco spread, 1/degC", 0.01};
  static constexpr const char* kC = "x / (1.0 + p[i] * dT)";

  template <typename T>
  static void Add(const T* c, int i, double dT, double /*dt*/, T* x) {
    *x = (T(1.0) + c[i] * T(dT)) * *x;
  }
  template <typename T>
  static bool Remove(const T* c, int i, double dT, double /*dt*/, T* x) {
    *x /= T(1.0) + c[i] * T(dT);
    return true;
  }
  template <typename T>
  static T Slope(const T* c, int i, const T& /*x*/, double dT) {
    return T(1.0) + c[i] * T(dT);
  }
  template <typename T>
  static T RateT(const T* c, int i, const T& x) {
    return c[i] * x;
  }
  template <typename T>
  static T Ratet(const T* /*c*/, int /*i*/, const T& /*x*/) {
    return T(0.0);
  }
};

}  // namespace effects
}  // namespace gravcal

#endif  // GRAVCAL_CORE_EFFECTS_ACCEL_TEMPERATURE_SCALE_H_
