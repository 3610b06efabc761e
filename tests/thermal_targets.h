// The autopilots' own corrections, written for the tests from their sources
// (not from gravcal's exporter), in their single precision:
//
// PX4 (src/modules/temperature_compensation/TemperatureCompensation.cpp,
// calc_thermal_offsets_3D; src/lib/sensor_calibration/Accelerometer.hpp and
// Gyroscope.hpp, Correct):
//   only when TC_A_ENABLE == 1 and TC_A0_ID equals the sensor's device id,
//   d = T - TREF with T first clipped to [TMIN, TMAX],
//   thermal[i] = X0_i + X1_i d + X2_i d^2 + X3_i d^3,
//   accel = (raw - thermal - CAL_ACC0_OFF) .* CAL_ACC0_SCALE,
//   gyro  =  raw - thermal - CAL_GYRO0_OFF          (rotation = identity).
//
// ArduPilot (libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp,
// TCal::correct_sensor, polynomial_eval; AP_InertialSensor_Backend.cpp,
// _rotate_and_correct_accel):
//   only when INS_TCALn_ENABLE == 1 (n the IMU instance, 1..3; the first
//   IMU's offsets are INS_ACCOFFS_*, the second's INS_ACC2OFFS_*, with
//   INS_ACCn_CALTEMP, INS_GYRn_CALTEMP); T and CALTEMP each clipped to
//   [TMIN, TMAX]; P(x) = (c1 + (c2 + c3 x) x) x * 1e-6 with x = T - 35;
//   v = raw - P(T) + P(CALTEMP), then accel = (v - INS_ACCOFFS) .* INS_ACCSCAL,
//   gyro = v - INS_GYROFFS.
#ifndef GRAVCAL_TESTS_THERMAL_TARGETS_H_
#define GRAVCAL_TESTS_THERMAL_TARGETS_H_

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <map>
#include <sstream>
#include <string>

namespace gravcal {
namespace targets {

using Params = std::map<std::string, double>;

// QGroundControl .params: "vehicle component name value type", tabs; '#'
// lines are comments.
inline Params ReadQgcParams(const std::string& text) {
  Params p;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    int vehicle = 0, component = 0, type = 0;
    std::string name;
    double value = 0.0;
    if (fields >> vehicle >> component >> name >> value >> type) p[name] = value;
  }
  return p;
}

// ArduPilot .parm: "NAME VALUE" (or NAME,VALUE); '#' comments.
inline Params ReadParm(const std::string& text) {
  Params p;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream fields(line);
    std::string name;
    double value = 0.0;
    if (fields >> name >> value) p[name] = value;
  }
  return p;
}

inline float Get(const Params& p, const std::string& name, float otherwise) {
  const auto it = p.find(name);
  return it == p.end() ? otherwise : static_cast<float>(it->second);
}

// PX4's thermal offset of sensor prefix "TC_A0_" / "TC_G0_" (zero when the
// compensation is off or the id does not match).
inline Eigen::Vector3f Px4ThermalOffset(const Params& p, const char* enable, const std::string& tc,
                                        uint32_t device_id, float temperature) {
  if (Get(p, enable, 0.0f) != 1.0f) return Eigen::Vector3f::Zero();
  if (static_cast<uint32_t>(static_cast<int32_t>(Get(p, tc + "ID", 0.0f))) != device_id) {
    return Eigen::Vector3f::Zero();
  }
  const float tmin = Get(p, tc + "TMIN", 0.0f), tmax = Get(p, tc + "TMAX", 100.0f);
  float d;
  if (temperature > tmax) {
    d = tmax - Get(p, tc + "TREF", 25.0f);
  } else if (temperature < tmin) {
    d = tmin - Get(p, tc + "TREF", 25.0f);
  } else {
    d = temperature - Get(p, tc + "TREF", 25.0f);
  }
  const float d2 = d * d, d3 = d2 * d;
  Eigen::Vector3f offset;
  for (int i = 0; i < 3; ++i) {
    const std::string axis = "_" + std::to_string(i);
    offset[i] = Get(p, tc + "X0" + axis, 0.0f) + Get(p, tc + "X1" + axis, 0.0f) * d +
                Get(p, tc + "X2" + axis, 0.0f) * d2 + Get(p, tc + "X3" + axis, 0.0f) * d3;
  }
  return offset;
}

inline Eigen::Vector3d Px4Accel(const Params& p, uint32_t device_id, const Eigen::Vector3d& raw,
                                double temperature) {
  const Eigen::Vector3f thermal =
      Px4ThermalOffset(p, "TC_A_ENABLE", "TC_A0_", device_id, static_cast<float>(temperature));
  const char* axes = "XYZ";
  Eigen::Vector3f a;
  for (int i = 0; i < 3; ++i) {
    const std::string n = std::string("CAL_ACC0_") + axes[i];
    a[i] = (static_cast<float>(raw[i]) - thermal[i] - Get(p, n + "OFF", 0.0f)) *
           Get(p, n + "SCALE", 1.0f);
  }
  return a.cast<double>();
}

inline Eigen::Vector3d Px4Gyro(const Params& p, uint32_t device_id, const Eigen::Vector3d& raw,
                               double temperature) {
  const Eigen::Vector3f thermal =
      Px4ThermalOffset(p, "TC_G_ENABLE", "TC_G0_", device_id, static_cast<float>(temperature));
  const char* axes = "XYZ";
  Eigen::Vector3f w;
  for (int i = 0; i < 3; ++i) {
    w[i] = static_cast<float>(raw[i]) - thermal[i] -
           Get(p, std::string("CAL_GYRO0_") + axes[i] + "OFF", 0.0f);
  }
  return w.cast<double>();
}

// ArduPilot's raw reading after TCAL (before offsets and scale), IMU
// instance `imu` (1..3): INS_TCALn_*, and the CALTEMP `caltemp`.
inline Eigen::Vector3f ArduPilotTcal(const Params& p, const char* sensor,
                                     const std::string& caltemp, const Eigen::Vector3d& raw,
                                     double temperature, int imu = 1) {
  Eigen::Vector3f v = raw.cast<float>();
  const std::string tcal = "INS_TCAL" + std::to_string(imu) + "_";
  if (Get(p, tcal + "ENABLE", 0.0f) != 1.0f) return v;
  const float tmin = Get(p, tcal + "TMIN", 0.0f), tmax = Get(p, tcal + "TMAX", 70.0f);
  const float t = std::min(std::max(static_cast<float>(temperature), tmin), tmax);
  const float tc = std::min(std::max(Get(p, caltemp, -300.0f), tmin), tmax);
  const char* axes = "XYZ";
  for (int i = 0; i < 3; ++i) {
    auto c = [&](int k) { return Get(p, tcal + sensor + std::to_string(k) + "_" + axes[i], 0.0f); };
    auto poly = [&](float x) { return (c(1) + (c(2) + c(3) * x) * x) * x * 1.0e-6f; };
    v[i] -= poly(t - 35.0f);
    v[i] += poly(tc - 35.0f);
  }
  return v;
}

// IMU `imu`'s offsets: INS_ACCOFFS_X for the first, INS_ACC2OFFS_X, ...
inline std::string ArduPilotInstance(int imu) { return imu > 1 ? std::to_string(imu) : ""; }

inline Eigen::Vector3d ArduPilotAccel(const Params& p, const Eigen::Vector3d& raw,
                                      double temperature, int imu = 1) {
  const Eigen::Vector3f v =
      ArduPilotTcal(p, "ACC", "INS_ACC" + std::to_string(imu) + "_CALTEMP", raw, temperature, imu);
  const std::string n = ArduPilotInstance(imu);
  const char* axes = "XYZ";
  Eigen::Vector3f a;
  for (int i = 0; i < 3; ++i) {
    a[i] = (v[i] - Get(p, "INS_ACC" + n + "OFFS_" + axes[i], 0.0f)) *
           Get(p, "INS_ACC" + n + "SCAL_" + axes[i], 1.0f);
  }
  return a.cast<double>();
}

inline Eigen::Vector3d ArduPilotGyro(const Params& p, const Eigen::Vector3d& raw,
                                     double temperature, int imu = 1) {
  const Eigen::Vector3f v =
      ArduPilotTcal(p, "GYR", "INS_GYR" + std::to_string(imu) + "_CALTEMP", raw, temperature, imu);
  const std::string n = ArduPilotInstance(imu);
  const char* axes = "XYZ";
  Eigen::Vector3f w;
  for (int i = 0; i < 3; ++i) w[i] = v[i] - Get(p, "INS_GYR" + n + "OFFS_" + axes[i], 0.0f);
  return w.cast<double>();
}

}  // namespace targets
}  // namespace gravcal

#endif  // GRAVCAL_TESTS_THERMAL_TARGETS_H_
