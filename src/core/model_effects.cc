#include "gravcal/core/model_effects.h"

#include <algorithm>

namespace gravcal {

const std::vector<EffectInfo>& EffectCatalogue() {
  // Never destroyed (Google style for static storage): a batch worker abandoned
  // with a hung unit may still read it while the process exits (found by TSan).
  static const std::vector<EffectInfo>& catalogue = *new std::vector<EffectInfo>([] {
    std::vector<EffectInfo> entries = {
        {Effect::kAccelMisalignment,
         "non-orthogonality of the accelerometer axes (cross-axis terms u_xy, u_xz, u_yz of U), "
         "missing from a scale-only baseline",
         EffectSensor::kAccelerometer,
         EffectRegressor::kOrientation,
         3,
         {"u_xy", "u_xz", "u_yz"},
         "m/s^2 per raw unit"},
        {Effect::kAccelQuadratic,
         "second-order scale factor per axis: the reading is a + k2 a^2",
         EffectSensor::kAccelerometer,
         EffectRegressor::kOrientation,
         3,
         {"k2_x", "k2_y", "k2_z"},
         "1/(m/s^2)"},
        {Effect::kAccelTemperatureBias,
         "accelerometer bias linear in temperature (m/s^2 per degree C)",
         EffectSensor::kAccelerometer,
         EffectRegressor::kTemperature,
         3,
         {"beta_x", "beta_y", "beta_z"},
         "m/s^2/degC"},
        {Effect::kAccelTemperatureScale,
         "accelerometer scale factor linear in temperature (fraction per degree C)",
         EffectSensor::kAccelerometer,
         EffectRegressor::kTemperature,
         3,
         {"c_x", "c_y", "c_z"},
         "1/degC"},
        {Effect::kAccelBiasDrift,
         "accelerometer bias linear in time (m/s^2 per second)",
         EffectSensor::kAccelerometer,
         EffectRegressor::kTime,
         3,
         {"delta_x", "delta_y", "delta_z"},
         "m/s^2/s"},
        {Effect::kGyroGSensitivity,
         "gyroscope bias proportional to specific force (3x3 G, raw gyro units per m/s^2)",
         EffectSensor::kGyroscope,
         EffectRegressor::kOrientation,
         9,
         {"g_xx", "g_xy", "g_xz", "g_yx", "g_yy", "g_yz", "g_zx", "g_zy", "g_zz"},
         "raw gyro units/(m/s^2)"},
        {Effect::kGyroTemperatureBias,
         "gyroscope bias linear in temperature (raw gyro units per degree C)",
         EffectSensor::kGyroscope,
         EffectRegressor::kTemperature,
         3,
         {"gamma_x", "gamma_y", "gamma_z"},
         "raw gyro units/degC"},
        {Effect::kGyroBiasDrift,
         "gyroscope bias linear in time (raw gyro units per second)",
         EffectSensor::kGyroscope,
         EffectRegressor::kTime,
         3,
         {"eta_x", "eta_y", "eta_z"},
         "raw gyro units/s"},
    };
    // The names come from the one table in types.cc.
    for (EffectInfo& info : entries) info.name = ToString(info.effect);
    return entries;
  }());
  return catalogue;
}

const EffectInfo& Info(Effect effect) {
  for (const EffectInfo& info : EffectCatalogue()) {
    if (info.effect == effect) return info;
  }
  return EffectCatalogue().front();
}

bool ParseEffects(const std::vector<std::string>& names, std::vector<Effect>* effects,
                  std::string* error) {
  std::vector<Effect> out;
  for (const std::string& name : names) {
    Effect e;
    if (!FromString(name, &e)) {
      std::string known;
      for (const EffectInfo& info : EffectCatalogue()) {
        known += (known.empty() ? "" : ", ") + std::string(info.name);
      }
      if (error) *error = "unknown effect '" + name + "' (known: " + known + ")";
      return false;
    }
    if (!Contains(out, e)) out.push_back(e);
  }
  *effects = out;
  return true;
}

std::vector<std::string> EffectNames(const std::vector<Effect>& effects) {
  std::vector<std::string> names;
  for (Effect e : effects) names.push_back(ToString(e));
  return names;
}

bool Contains(const std::vector<Effect>& effects, Effect effect) {
  return std::find(effects.begin(), effects.end(), effect) != effects.end();
}

std::vector<double> EffectParameters::Values(Effect effect) const {
  auto three = [](const Eigen::Vector3d& v) { return std::vector<double>{v(0), v(1), v(2)}; };
  switch (effect) {
    case Effect::kAccelMisalignment:
      return {};
    case Effect::kAccelQuadratic:
      return three(accel_quadratic);
    case Effect::kAccelTemperatureBias:
      return three(accel_temperature_bias);
    case Effect::kAccelTemperatureScale:
      return three(accel_temperature_scale);
    case Effect::kAccelBiasDrift:
      return three(accel_bias_drift);
    case Effect::kGyroGSensitivity: {
      std::vector<double> v;
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) v.push_back(gyro_g_sensitivity(r, c));
      }
      return v;
    }
    case Effect::kGyroTemperatureBias:
      return three(gyro_temperature_bias);
    case Effect::kGyroBiasDrift:
      return three(gyro_bias_drift);
  }
  return {};
}

double TemperatureOffset(const EffectParameters& p, double temperature) {
  return std::isfinite(temperature) ? temperature - p.reference_temperature : 0.0;
}

Eigen::Vector3d ApplyAccelEffects(const EffectParameters& p, const Eigen::Vector3d& s,
                                  double temperature, double time) {
  const double dT = TemperatureOffset(p, temperature);
  const double dt = time - p.reference_time;
  Eigen::Vector3d m;
  for (int i = 0; i < 3; ++i) {
    m(i) = (1.0 + p.accel_temperature_scale(i) * dT) * (s(i) + p.accel_quadratic(i) * s(i) * s(i)) +
           p.accel_temperature_bias(i) * dT + p.accel_bias_drift(i) * dt;
  }
  return m;
}

bool CorrectAccel(const EffectParameters& p, const std::vector<Effect>& effects,
                  const Eigen::Vector3d& m, double temperature, double time, Eigen::Vector3d* a) {
  auto on = [&](Effect e, const Eigen::Vector3d& v) {
    return Contains(effects, e) ? v.data() : nullptr;
  };
  Eigen::Vector3d out = m;
  const bool ok = CorrectAccelEffects<double>(
      on(Effect::kAccelQuadratic, p.accel_quadratic),
      on(Effect::kAccelTemperatureBias, p.accel_temperature_bias),
      on(Effect::kAccelTemperatureScale, p.accel_temperature_scale),
      on(Effect::kAccelBiasDrift, p.accel_bias_drift), TemperatureOffset(p, temperature),
      time - p.reference_time, out.data());
  *a = out;
  return ok;
}

Eigen::Vector3d GyroOffset(const EffectParameters& p, const std::vector<Effect>& effects,
                           const Eigen::Vector3d& force, double temperature, double time) {
  // Row-major copy of G for the templated term.
  double g[9];
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) g[3 * r + c] = p.gyro_g_sensitivity(r, c);
  }
  Eigen::Vector3d offset;
  GyroEffectOffset<double>(
      Contains(effects, Effect::kGyroGSensitivity) ? g : nullptr,
      Contains(effects, Effect::kGyroTemperatureBias) ? p.gyro_temperature_bias.data() : nullptr,
      Contains(effects, Effect::kGyroBiasDrift) ? p.gyro_bias_drift.data() : nullptr, force.data(),
      TemperatureOffset(p, temperature), time - p.reference_time, offset.data());
  return offset;
}

}  // namespace gravcal
