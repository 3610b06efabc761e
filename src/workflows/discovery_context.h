// Private: what every fit of one discovery run (discovery.h) shares, and
// the fit itself.
#ifndef GRAVCAL_SRC_WORKFLOWS_DISCOVERY_CONTEXT_H_
#define GRAVCAL_SRC_WORKFLOWS_DISCOVERY_CONTEXT_H_

#include <cstdio>
#include <string>
#include <vector>

#include "gravcal/core/model_effects.h"
#include "gravcal/methods/effect_fit.h"
#include "gravcal/workflows/discovery.h"

namespace gravcal {
namespace internal {

// What every fit in one discovery run shares.
struct DiscoveryContext {
  const std::vector<StaticObservation>* observations = nullptr;
  double gravity = kStandardGravity;
  AccelParameterization parameterization = AccelParameterization::kScaleMisalignment;
  bool has_gyro = false;
  bool has_temperature = false;
  double temperature_range = 0.0;
  // The accelerometer's fits take the rotations between poses as rows.
  bool use_rotations = false;
};

inline bool IsAccel(Effect e) { return Info(e).sensor == EffectSensor::kAccelerometer; }

// v printed with a printf format such as "%.3g".
inline std::string FormatNumber(const char* format, double v) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, v);
  return buffer;
}

// Fits `effects` to `observations` from `start` (the sensors asked for; the
// gyroscope only where the session has one).
inline bool FitDiscoveryModel(const DiscoveryContext& ctx,
                              const std::vector<StaticObservation>& observations,
                              const std::vector<Effect>& effects, const EffectFitResult& start,
                              bool fit_accel, bool fit_gyro, bool covariance,
                              EffectFitResult* out) {
  EffectFitOptions o;
  o.parameterization = ctx.parameterization;
  o.effects = effects;
  o.fit_accel = fit_accel;
  o.fit_gyro = fit_gyro && ctx.has_gyro;
  o.compute_covariance = covariance;
  o.use_within_pose_trends = true;
  o.use_between_pose_rotations = ctx.use_rotations && fit_accel;
  return FitEffects(observations, start.accel, start.gyro, start.parameters, ctx.gravity, o, out);
}

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_WORKFLOWS_DISCOVERY_CONTEXT_H_
