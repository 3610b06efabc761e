// A simulated still IMU log of known noise, for the noise tests.
#ifndef GRAVCAL_TESTS_STILL_LOG_H_
#define GRAVCAL_TESTS_STILL_LOG_H_

#include <cstdint>

#include "gravcal/core/imu_log.h"
#include "gravcal/simulation/noise_process.h"

namespace gravcal {
namespace testing_util {

// `seconds` at rest at accel.rate_hz: accelerometer in m/s^2 (gravity on z)
// with `accel` noise on every axis, gyroscope in counts of gyro_scale rad/s
// with `gyro` noise; deterministic from the seed.
inline ImuLog StillLog(const NoiseProcessOptions& accel, const NoiseProcessOptions& gyro,
                       double gyro_scale, uint64_t seed, double seconds) {
  ImuLog log;
  log.source = "still.csv";
  const double rate = accel.rate_hz;
  const size_t n = static_cast<size_t>(seconds * rate);
  log.t.resize(n);
  log.accel.assign(n, Eigen::Vector3d(0.0, 0.0, 9.80665));
  log.gyro.assign(n, Eigen::Vector3d::Zero());
  for (size_t i = 0; i < n; ++i) log.t[i] = i / rate;
  for (int a = 0; a < 3; ++a) {
    NoiseProcess pa(accel, seed * 16 + a);
    NoiseProcess pg(gyro, seed * 16 + 8 + a);
    for (size_t i = 0; i < n; ++i) {
      log.accel[i](a) += pa.Next();
      log.gyro[i](a) = pg.Next() / gyro_scale;
    }
  }
  return log;
}

}  // namespace testing_util
}  // namespace gravcal

#endif  // GRAVCAL_TESTS_STILL_LOG_H_
