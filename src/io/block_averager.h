// io/block_averager.h (private): the rows of a log kept in bounded memory
// (gravcal/io/long_log.h, ReadImuLogBounded).
#ifndef GRAVCAL_SRC_IO_BLOCK_AVERAGER_H_
#define GRAVCAL_SRC_IO_BLOCK_AVERAGER_H_

#include <Eigen/Core>
#include <cstddef>

#include "gravcal/core/imu_log.h"
#include "io/log_text.h"

namespace gravcal {
namespace internal {

// Rows into a log in bounded memory (LongLogReading::max_samples): pushed
// as they are until the log holds `max` entries, then each two neighbours
// merged into their mean and from then on every `block` rows pushed as one
// mean.
class BlockAverager {
 public:
  BlockAverager(size_t max, ImuLog* out) : max_(max - max % 2), out_(out) {}

  // `count` rows of kNumSlots values (io/log_text.h), in order; with the
  // gyroscope and the temperature when kGyro, kTemperature.
  template <bool kGyro, bool kTemperature>
  void AddRows(const double* rows, size_t count) {
    ImuLog& o = *out_;
    for (const double* v = rows; v < rows + count * kNumSlots; v += kNumSlots) {
      if (count_ == 0 && max_ > 0 && o.t.size() >= max_) Halve();
      const Eigen::Vector3d accel(v[kAx], v[kAy], v[kAz]);
      if (block_ == 1) {
        o.t.push_back(v[kT]);
        o.accel.push_back(accel);
        if (kGyro) o.gyro.emplace_back(v[kGx], v[kGy], v[kGz]);
        if (kTemperature) o.temperature.push_back(v[kTemp]);
        continue;
      }
      t_ += v[kT];
      accel_ += accel;
      if (kGyro) gyro_ += Eigen::Vector3d(v[kGx], v[kGy], v[kGz]);
      if (kTemperature) temperature_ += v[kTemp];
      if (++count_ < block_) continue;
      const double inv = 1.0 / static_cast<double>(block_);
      o.t.push_back(t_ * inv);
      o.accel.push_back(accel_ * inv);
      if (kGyro) o.gyro.push_back(gyro_ * inv);
      if (kTemperature) o.temperature.push_back(temperature_ * inv);
      t_ = 0.0;
      temperature_ = 0.0;
      accel_.setZero();
      gyro_.setZero();
      count_ = 0;
    }
  }

  size_t block() const { return block_; }

 private:
  // Each two neighbouring entries become their mean.
  void Halve() {
    ImuLog& o = *out_;
    const size_t half = o.t.size() / 2;
    for (size_t i = 0; i < half; ++i) {
      o.t[i] = 0.5 * (o.t[2 * i] + o.t[2 * i + 1]);
      o.accel[i] = 0.5 * (o.accel[2 * i] + o.accel[2 * i + 1]);
      if (!o.gyro.empty()) o.gyro[i] = 0.5 * (o.gyro[2 * i] + o.gyro[2 * i + 1]);
      if (!o.temperature.empty()) {
        o.temperature[i] = 0.5 * (o.temperature[2 * i] + o.temperature[2 * i + 1]);
      }
    }
    o.t.resize(half);
    o.accel.resize(half);
    if (!o.gyro.empty()) o.gyro.resize(half);
    if (!o.temperature.empty()) o.temperature.resize(half);
    block_ *= 2;
  }

  const size_t max_;
  ImuLog* out_;
  size_t block_ = 1;
  size_t count_ = 0;
  double t_ = 0.0, temperature_ = 0.0;
  Eigen::Vector3d accel_ = Eigen::Vector3d::Zero(), gyro_ = Eigen::Vector3d::Zero();
};

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_IO_BLOCK_AVERAGER_H_
