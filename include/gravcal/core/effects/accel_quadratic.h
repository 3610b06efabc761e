// gravcal/core/effects/accel_quadratic.h: one effect of the registry
// (core/effect_registry.h).
//
// The second-order scale factor per axis, 1/(m/s^2): the reading of the true
// specific force s is
//
//   x_i = s_i + k2_i s_i^2,
//
// inverted at the root near x: s_i = 2 x_i / (1 + sqrt(1 + 4 k2_i x_i)),
// smooth at k2 = 0; no real root when 1 + 4 k2 x <= 0 (a coefficient far
// outside any sensor's range). It acts first on s (depth 1).
#ifndef GRAVCAL_CORE_EFFECTS_ACCEL_QUADRATIC_H_
#define GRAVCAL_CORE_EFFECTS_ACCEL_QUADRATIC_H_

#include <cmath>

#include "gravcal/core/effects/effect_definition.h"

namespace gravcal {
namespace effects {

struct AccelQuadratic {
  static constexpr const char* kName = "accel_quadratic_nonlinearity";
  static constexpr const char* kDescription =
      "second-order scale factor per axis: the reading is a + k2 a^2";
  static constexpr EffectSensor kSensor = EffectSensor::kAccelerometer;
  static constexpr EffectRegressor kRegressor = EffectRegressor::kOrientation;
  static constexpr EffectForm kForm = EffectForm::kAccelShape;
  static constexpr int kDepth = 1;
  static constexpr bool kVaries = false;
  static constexpr int kSize = 3;
  static constexpr const char* kParameters[kSize] = {"k2_x", "k2_y", "k2_z"};
  static constexpr const char* kUnit = "1/(m/s^2)";
  static constexpr EffectSimulation kSimulation = {"sim_accel_quadratic", "accel_quadratic_std",
                                                   "truth k2 spread per axis, 1/(m/s^2)"};
  static constexpr const char* kC = "2.0 * x / (1.0 + sqrt(1.0 + 4.0 * p[i] * x))";

  template <typename T>
  static void Add(const T* k2, int i, double /*dT*/, double /*dt*/, T* x) {
    *x = *x + k2[i] * *x * *x;
  }
  template <typename T>
  static bool Remove(const T* k2, int i, double /*dT*/, double /*dt*/, T* x) {
    using std::sqrt;
    const T d = T(1.0) + T(4.0) * k2[i] * *x;
    if (!(d > T(0.0))) return false;
    *x = T(2.0) * *x / (T(1.0) + sqrt(d));
    return true;
  }
};

}  // namespace effects
}  // namespace gravcal

#endif  // GRAVCAL_CORE_EFFECTS_ACCEL_QUADRATIC_H_
