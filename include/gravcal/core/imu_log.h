// gravcal/core/imu_log.h: an IMU recording held in memory.
//
// One sample per index: time t[i] in seconds (strictly increasing), the raw
// accelerometer vector accel[i] in whatever units the sensor wrote (counts,
// volts, g or m/s^2), and optionally the raw gyroscope vector gyro[i] and the
// sensor temperature[i] in degrees Celsius. Calibration maps raw to SI.
//
// Invariants (checked by Validate): accel.size() == t.size(); gyro and
// temperature are either empty or the same size as t; every value finite.
#ifndef GRAVCAL_CORE_IMU_LOG_H_
#define GRAVCAL_CORE_IMU_LOG_H_

#include <Eigen/Core>
#include <string>
#include <vector>

namespace gravcal {

struct ImuLog {
  // Where the data came from (a file name), used in messages.
  std::string source;
  std::vector<double> t;
  std::vector<Eigen::Vector3d> accel;
  // Empty when the recording has no gyroscope.
  std::vector<Eigen::Vector3d> gyro;
  // Empty when the recording has no temperature column.
  std::vector<double> temperature;

  size_t size() const { return t.size(); }
  bool has_gyro() const { return !gyro.empty(); }
  bool has_temperature() const { return !temperature.empty(); }

  // Returns false and says why (naming source and sample index) when the
  // invariants above do not hold.
  bool Validate(std::string* error) const;
};

}  // namespace gravcal

#endif  // GRAVCAL_CORE_IMU_LOG_H_
