// gravcal/core/effects/accel_misalignment.h: one effect of the registry
// (core/effect_registry.h).
//
// The non-orthogonality of the accelerometer axes: the cross-axis terms
// u_xy, u_xz, u_yz of U (accel_model.h). It has no term of its own: it frees
// the off-diagonal of U, so it is an effect only when the baseline
// parameterisation is `scale` (the other baselines already hold it).
#ifndef GRAVCAL_CORE_EFFECTS_ACCEL_MISALIGNMENT_H_
#define GRAVCAL_CORE_EFFECTS_ACCEL_MISALIGNMENT_H_

#include "gravcal/core/effects/effect_definition.h"

namespace gravcal {
namespace effects {

struct AccelMisalignment {
  static constexpr const char* kName = "accel_misalignment";
  static constexpr const char* kDescription =
      "non-orthogonality of the accelerometer axes (cross-axis terms u_xy, u_xz, u_yz of U), "
      "missing from a scale-only baseline";
  static constexpr EffectSensor kSensor = EffectSensor::kAccelerometer;
  static constexpr EffectRegressor kRegressor = EffectRegressor::kOrientation;
  static constexpr EffectForm kForm = EffectForm::kInUpper;
  static constexpr int kSize = 3;
  static constexpr const char* kParameters[kSize] = {"u_xy", "u_xz", "u_yz"};
  static constexpr const char* kUnit = "m/s^2 per raw unit";
  // Simulated by sim_accel_misalignment (the truth model's own key).
  static constexpr EffectSimulation kSimulation = {};
};

}  // namespace effects
}  // namespace gravcal

#endif  // GRAVCAL_CORE_EFFECTS_ACCEL_MISALIGNMENT_H_
