#include "gravcal/core/imu_corrector.h"

#include <algorithm>

#include "gravcal/core/imu_model.h"

namespace gravcal {

namespace {

bool UsesRegressor(const std::vector<Effect>& effects, EffectRegressor regressor) {
  return std::any_of(effects.begin(), effects.end(),
                     [&](Effect e) { return Info(e).regressor == regressor; });
}

}  // namespace

bool ImuCorrector::RequiresTemperature() const {
  return UsesRegressor(active_effects, EffectRegressor::kTemperature);
}

bool ImuCorrector::RequiresTime() const {
  return UsesRegressor(active_effects, EffectRegressor::kTime);
}

bool ImuCorrector::CorrectAccel(const Eigen::Vector3d& raw, double temperature, double time,
                                Eigen::Vector3d* a) const {
  const ImuParameters p(accel, nullptr, effects, active_effects);
  Eigen::Vector3d out;
  if (!p.Model().CorrectAccel(raw, p.TemperatureOffset(temperature), p.TimeOffset(time),
                              out.data())) {
    return false;
  }
  *a = out;
  return true;
}

Eigen::Vector3d ImuCorrector::CorrectGyro(const Eigen::Vector3d& raw,
                                          const Eigen::Vector3d& accel_housing, double temperature,
                                          double time) const {
  if (!has_gyro) return raw;
  const ImuParameters p(accel, &gyro, effects, active_effects);
  // The effects' G' was fitted against the force in the sensor frame.
  const Eigen::Vector3d force = accel.rotation.transpose() * accel_housing;
  Eigen::Vector3d w;
  p.Model().CorrectGyro(raw, force.data(), p.TemperatureOffset(temperature), p.TimeOffset(time),
                        w.data());
  return w;
}

bool ImuCorrector::CorrectRow(double temperature, double time, Eigen::Vector3d* accel,
                              Eigen::Vector3d* gyro) const {
  Eigen::Vector3d a;
  if (!CorrectAccel(*accel, temperature, time, &a)) return false;
  if (gyro != nullptr) *gyro = CorrectGyro(*gyro, a, temperature, time);
  *accel = a;
  return true;
}

ImuCorrector ImuCorrector::WithEffects(const std::vector<Effect>& keep) const {
  ImuCorrector out = *this;
  out.active_effects.clear();
  for (Effect e : active_effects) {
    if (Contains(keep, e)) out.active_effects.push_back(e);
  }
  return out;
}

}  // namespace gravcal
