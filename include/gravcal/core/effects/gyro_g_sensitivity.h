// gravcal/core/effects/gyro_g_sensitivity.h: one effect of the registry
// (core/effect_registry.h).
//
// The gyroscope bias proportional to the calibrated specific force f (m/s^2,
// the accelerometer's sensor frame), raw gyroscope units per m/s^2, G
// row-major (row = gyroscope axis):
//
//   o_i += sum_j G_ij f_j.
//
// The static data cannot separate it from the gyroscope's scale matrix: G
// here is M_g^-1 G_true.
#ifndef GRAVCAL_CORE_EFFECTS_GYRO_G_SENSITIVITY_H_
#define GRAVCAL_CORE_EFFECTS_GYRO_G_SENSITIVITY_H_

#include "gravcal/core/effects/effect_definition.h"

namespace gravcal {
namespace effects {

struct GyroGSensitivity {
  static constexpr const char* kName = "gyro_g_sensitivity";
  static constexpr const char* kDescription =
      "gyroscope bias proportional to specific force (3x3 G, raw gyro units per m/s^2)";
  static constexpr EffectSensor kSensor = EffectSensor::kGyroscope;
  static constexpr EffectRegressor kRegressor = EffectRegressor::kOrientation;
  static constexpr EffectForm kForm = EffectForm::kGyroOffset;
  static constexpr int kSize = 9;
  static constexpr const char* kParameters[kSize] = {"g_xx", "g_xy", "g_xz", "g_yx", "g_yy",
                                                     "g_yz", "g_zx", "g_zy", "g_zz"};
  static constexpr const char* kUnit = "raw gyro units/(m/s^2)";
  // The simulator's G is in rad/s per m/s^2 (u = M_g^-1 (w + G f) + ...).
  static constexpr EffectSimulation kSimulation = {
      "sim_gyro_g_sensitivity", "gyro_g_sensitivity_std",
      "truth gyroscope g-sensitivity spread, rad/s per m/s^2"};
  static constexpr const char* kC =
      "p[3 * i] * force[0] + p[3 * i + 1] * force[1] + p[3 * i + 2] * force[2]";

  template <typename T>
  static void Add(const T* g, int i, const double* force, double /*dT*/, double /*dt*/, T* o) {
    for (int j = 0; j < 3; ++j) *o += g[3 * i + j] * T(force[j]);
  }
};

}  // namespace effects
}  // namespace gravcal

#endif  // GRAVCAL_CORE_EFFECTS_GYRO_G_SENSITIVITY_H_
