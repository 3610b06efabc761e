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

// a = R h^-1((I + D(x))^-1 U (v - b - db(x))): the thermal terms (none when
// the model is inactive), then the effects, then the housing rotation.
bool AccelOf(const ImuParameters& p, const ThermalBlocks<double>& thermal, double x,
             const Eigen::Vector3d& raw, double temperature, double time, Eigen::Vector3d* a) {
  const ImuModel<double> model = p.Model();
  double db[3];
  thermal.BiasChange(x, db);
  const Eigen::Vector3d shifted = raw - Eigen::Vector3d(db[0], db[1], db[2]);
  double s[3];
  model.SensorFrame(shifted, s);
  thermal.RemoveScale(x, s);
  if (!RemoveAccelEffects<double>(model.accel().effect, p.TemperatureOffset(temperature),
                                  p.TimeOffset(time), s)) {
    return false;
  }
  double out[3];
  model.ToHousing(s, out);
  *a = Eigen::Vector3d(out[0], out[1], out[2]);
  return true;
}

// w = (I + D_g(x))^-1 M_g (u - db_g(x) - b_g - o) - G f.
Eigen::Vector3d GyroOf(const ImuParameters& p, const ThermalBlocks<double>& thermal, double x,
                       const Eigen::Matrix3d& rotation, const Eigen::Vector3d& raw,
                       const Eigen::Vector3d& accel_housing, double temperature, double time) {
  // The effects' G' was fitted against the force in the sensor frame.
  const Eigen::Vector3d force = rotation.transpose() * accel_housing;
  const ImuModel<double> model = p.Model();
  double db[3];
  thermal.BiasChange(x, db);
  const Eigen::Vector3d shifted = raw - Eigen::Vector3d(db[0], db[1], db[2]);
  double e[3];
  model.GyroRestError(shifted, force.data(), p.TemperatureOffset(temperature), p.TimeOffset(time),
                      e);
  // M_g e, then the thermal scale removed, then the g-sensitivity.
  double w[3];
  GyroBlocks<double> linear = model.gyro();
  linear.g_sensitivity = nullptr;
  ImuModel<double>(linear).GyroRateFrom(e, force.data(), w);
  thermal.RemoveScale(x, w);
  Eigen::Vector3d out(w[0], w[1], w[2]);
  if (model.gyro().g_sensitivity != nullptr) {
    const double* g = model.gyro().g_sensitivity;
    for (int r = 0; r < 3; ++r) {
      out(r) -= g[3 * r] * force(0) + g[3 * r + 1] * force(1) + g[3 * r + 2] * force(2);
    }
  }
  return out;
}

}  // namespace

bool ImuCorrector::CorrectAccel(const Eigen::Vector3d& raw, double temperature, double time,
                                Eigen::Vector3d* a) const {
  const double x = thermal.Offset(temperature, NAN, nullptr);
  return AccelOf(ImuParameters(accel, nullptr, effects, active_effects),
                 thermal.Blocks(ThermalSensor::kAccel), x, raw, temperature, time, a);
}

Eigen::Vector3d ImuCorrector::CorrectGyro(const Eigen::Vector3d& raw,
                                          const Eigen::Vector3d& accel_housing, double temperature,
                                          double time) const {
  if (!has_gyro) return raw;
  const double x = thermal.Offset(temperature, NAN, nullptr);
  return GyroOf(ImuParameters(accel, &gyro, effects, active_effects),
                thermal.Blocks(ThermalSensor::kGyro), x, accel.rotation, raw, accel_housing,
                temperature, time);
}

bool ImuCorrector::CorrectRow(double temperature, double time, Eigen::Vector3d* accel_row,
                              Eigen::Vector3d* gyro_row) const {
  return CorrectRow(temperature, NAN, time, accel_row, gyro_row, nullptr);
}

bool ImuCorrector::CorrectRow(double temperature, double temperature_rate, double time,
                              Eigen::Vector3d* accel_row, Eigen::Vector3d* gyro_row,
                              bool* clamped) const {
  // One set of blocks for both sensors.
  const ImuParameters p(accel, has_gyro ? &gyro : nullptr, effects, active_effects);
  const double x = thermal.Offset(temperature, temperature_rate, clamped);
  Eigen::Vector3d a;
  if (!AccelOf(p, thermal.Blocks(ThermalSensor::kAccel), x, *accel_row, temperature, time, &a)) {
    return false;
  }
  if (gyro_row != nullptr && has_gyro) {
    *gyro_row = GyroOf(p, thermal.Blocks(ThermalSensor::kGyro), x, accel.rotation, *gyro_row, a,
                       temperature, time);
  }
  *accel_row = a;
  return true;
}

size_t ImuCorrector::CorrectRows(size_t n, const double* temperature,
                                 const double* temperature_rate, const double* time,
                                 Eigen::Vector3d* accel_rows, Eigen::Vector3d* gyro_rows,
                                 bool* clamped) const {
  // CorrectRow's steps, the parameters and thermal blocks made once.
  const ImuParameters p(accel, has_gyro ? &gyro : nullptr, effects, active_effects);
  const ThermalBlocks<double> accel_thermal = thermal.Blocks(ThermalSensor::kAccel);
  const ThermalBlocks<double> gyro_thermal = thermal.Blocks(ThermalSensor::kGyro);
  for (size_t i = 0; i < n; ++i) {
    const double x = thermal.Offset(temperature[i], temperature_rate[i], &clamped[i]);
    Eigen::Vector3d a;
    if (!AccelOf(p, accel_thermal, x, accel_rows[i], temperature[i], time[i], &a)) return i;
    if (gyro_rows != nullptr && has_gyro) {
      gyro_rows[i] =
          GyroOf(p, gyro_thermal, x, accel.rotation, gyro_rows[i], a, temperature[i], time[i]);
    }
    accel_rows[i] = a;
  }
  return n;
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
