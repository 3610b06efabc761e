// gravcal/core/effects/gyro_bias_drift.h: one effect of the registry
// (core/effect_registry.h).
//
// The gyroscope bias linear in time, raw gyroscope units per second:
// o_i += eta_i dt.
#ifndef GRAVCAL_CORE_EFFECTS_GYRO_BIAS_DRIFT_H_
#define GRAVCAL_CORE_EFFECTS_GYRO_BIAS_DRIFT_H_

#include "gravcal/core/effects/effect_definition.h"

namespace gravcal {
namespace effects {

struct GyroBiasDrift {
  static constexpr const char* kName = "gyro_bias_drift";
  static constexpr const char* kDescription =
      "gyroscope bias linear in time (raw gyro units per second)";
  static constexpr EffectSensor kSensor = EffectSensor::kGyroscope;
  static constexpr EffectRegressor kRegressor = EffectRegressor::kTime;
  static constexpr EffectForm kForm = EffectForm::kGyroOffset;
  static constexpr int kSize = 3;
  static constexpr const char* kParameters[kSize] = {"eta_x", "eta_y", "eta_z"};
  static constexpr const char* kUnit = "raw gyro units/s";
  static constexpr EffectSimulation kSimulation = {"sim_gyro_bias_drift", "gyro_bias_drift_std",
                                                   "truth gyroscope bias drift spread, rad/s/s"};
  static constexpr const char* kC = "p[i] * dt";

  template <typename T>
  static void Add(const T* eta, int i, const double* /*force*/, double /*dT*/, double dt, T* o) {
    *o += eta[i] * T(dt);
  }
};

}  // namespace effects
}  // namespace gravcal

#endif  // GRAVCAL_CORE_EFFECTS_GYRO_BIAS_DRIFT_H_
