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

namespace {

// a = R h^-1(U (v - b)) and w = M_g (u - b_g - o) of one model's blocks.
bool AccelOf(const ImuParameters& p, const Eigen::Vector3d& raw, double temperature, double time,
             Eigen::Vector3d* a) {
  Eigen::Vector3d out;
  if (!p.Model().CorrectAccel(raw, p.TemperatureOffset(temperature), p.TimeOffset(time),
                              out.data())) {
    return false;
  }
  *a = out;
  return true;
}

Eigen::Vector3d GyroOf(const ImuParameters& p, const Eigen::Matrix3d& rotation,
                       const Eigen::Vector3d& raw, const Eigen::Vector3d& accel_housing,
                       double temperature, double time) {
  // The effects' G' was fitted against the force in the sensor frame.
  const Eigen::Vector3d force = rotation.transpose() * accel_housing;
  Eigen::Vector3d w;
  p.Model().CorrectGyro(raw, force.data(), p.TemperatureOffset(temperature), p.TimeOffset(time),
                        w.data());
  return w;
}

}  // namespace

bool ImuCorrector::CorrectAccel(const Eigen::Vector3d& raw, double temperature, double time,
                                Eigen::Vector3d* a) const {
  return AccelOf(ImuParameters(accel, nullptr, effects, active_effects), raw, temperature, time, a);
}

Eigen::Vector3d ImuCorrector::CorrectGyro(const Eigen::Vector3d& raw,
                                          const Eigen::Vector3d& accel_housing, double temperature,
                                          double time) const {
  if (!has_gyro) return raw;
  return GyroOf(ImuParameters(accel, &gyro, effects, active_effects), accel.rotation, raw,
                accel_housing, temperature, time);
}

bool ImuCorrector::CorrectRow(double temperature, double time, Eigen::Vector3d* accel_row,
                              Eigen::Vector3d* gyro_row) const {
  // One set of blocks for both sensors.
  const ImuParameters p(accel, has_gyro ? &gyro : nullptr, effects, active_effects);
  Eigen::Vector3d a;
  if (!AccelOf(p, *accel_row, temperature, time, &a)) return false;
  if (gyro_row != nullptr && has_gyro) {
    *gyro_row = GyroOf(p, accel.rotation, *gyro_row, a, temperature, time);
  }
  *accel_row = a;
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
