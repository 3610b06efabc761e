// gravcal/core/effects/accel_bias_drift.h: one effect of the registry
// (core/effect_registry.h).
//
// The accelerometer bias linear in time, m/s^2 per second:
//
//   o_i = delta_i dt,     d o / d dt = delta.
#ifndef GRAVCAL_CORE_EFFECTS_ACCEL_BIAS_DRIFT_H_
#define GRAVCAL_CORE_EFFECTS_ACCEL_BIAS_DRIFT_H_

#include "gravcal/core/effects/effect_definition.h"

namespace gravcal {
namespace effects {

struct AccelBiasDrift {
  static constexpr const char* kName = "accel_bias_drift";
  static constexpr const char* kDescription =
      "accelerometer bias linear in time (m/s^2 per second)";
  static constexpr EffectSensor kSensor = EffectSensor::kAccelerometer;
  static constexpr EffectRegressor kRegressor = EffectRegressor::kTime;
  static constexpr EffectForm kForm = EffectForm::kAccelOffset;
  static constexpr int kSize = 3;
  static constexpr const char* kParameters[kSize] = {"delta_x", "delta_y", "delta_z"};
  static constexpr const char* kUnit = "m/s^2/s";
  static constexpr EffectSimulation kSimulation = {
      "sim_accel_bias_drift", "accel_bias_drift_std",
      "truth accelerometer bias drift spread, m/s^2/s"};
  static constexpr const char* kC = "p[i] * dt";

  template <typename T>
  static void Add(const T* delta, int i, double /*dT*/, double dt, T* x) {
    *x += delta[i] * T(dt);
  }
  template <typename T>
  static void Remove(const T* delta, int i, double /*dT*/, double dt, T* x) {
    *x -= delta[i] * T(dt);
  }
  template <typename T>
  static T RateT(const T* /*delta*/, int /*i*/, double /*dT*/) {
    return T(0.0);
  }
  template <typename T>
  static T Ratet(const T* delta, int i) {
    return delta[i];
  }
};

}  // namespace effects
}  // namespace gravcal

#endif  // GRAVCAL_CORE_EFFECTS_ACCEL_BIAS_DRIFT_H_
