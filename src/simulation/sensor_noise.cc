#include "simulation/sensor_noise.h"

#include <cmath>
#include <random>
#include <string>

namespace gravcal {
namespace internal {

BiasInstability::BiasInstability(double bias_instability, double tau_low, double tau_high,
                                 double rate_hz, uint64_t seed, uint64_t stream) {
  if (!(bias_instability > 0.0)) return;
  NoiseProcessOptions options;
  options.rate_hz = rate_hz;
  options.bias_instability = bias_instability;
  options.bias_tau_low = tau_low;
  options.bias_tau_high = tau_high;
  for (uint64_t axis = 0; axis < 3; ++axis) {
    axes_.push_back(std::make_unique<NoiseProcess>(
        options, seed ^ (stream * 0x9fb21c651e98df25ULL) ^ (axis * 0xd6e8feb86659fd93ULL)));
  }
}

namespace {

// 1 on each axis tone_axis names ("x", "xz", ...).
Eigen::Vector3d ToneAxes(const std::string& axes) {
  Eigen::Vector3d on = Eigen::Vector3d::Zero();
  for (int a = 0; a < 3; ++a) {
    if (axes.find("xyz"[a]) != std::string::npos) on(a) = 1.0;
  }
  return on;
}

// The slow line's phase on each axis, uniform in [0, 2 pi), from a stream
// of its own.
Eigen::Vector3d SlowLinePhases(uint64_t seed) {
  std::mt19937_64 rng(seed ^ 0x3c6ef372fe94f82bULL);
  std::uniform_real_distribution<double> turn(0.0, 2.0 * M_PI);
  Eigen::Vector3d phase;
  for (int a = 0; a < 3; ++a) phase(a) = turn(rng);
  return phase;
}

}  // namespace

Eigen::Vector3d BiasInstability::Next() {
  if (axes_.empty()) return Eigen::Vector3d::Zero();
  return Eigen::Vector3d(axes_[0]->Next(), axes_[1]->Next(), axes_[2]->Next());
}

SensorNoise::SensorNoise(const SimulatorOptions& o, double accel_units_per_si,
                         double gyro_units_per_si, uint64_t seed)
    : accel_units_per_si_(accel_units_per_si),
      gyro_units_per_si_(gyro_units_per_si),
      raw_counts_(o.raw_counts),
      accel_noise_(o.accel_noise * accel_units_per_si),
      gyro_noise_(o.gyro_noise * gyro_units_per_si),
      accel_walk_(o.accel_bias_random_walk * std::sqrt(1.0 / o.sample_rate) * accel_units_per_si),
      gyro_walk_(o.gyro_bias_random_walk * std::sqrt(1.0 / o.sample_rate) * gyro_units_per_si),
      accel_tone_(o.accel_tone * accel_units_per_si),
      gyro_tone_(o.gyro_tone * gyro_units_per_si),
      tone_step_(2.0 * M_PI * o.tone_frequency / o.sample_rate),
      tone_axes_(ToneAxes(o.tone_axis)),
      accel_slow_(o.accel_slow_line * accel_units_per_si),
      gyro_slow_(o.gyro_slow_line * gyro_units_per_si),
      slow_step_(2.0 * M_PI / (o.slow_line_period * o.sample_rate)),
      slow_phase_(SlowLinePhases(seed)),
      accel_instability_(o.accel_bias_instability, o.bias_instability_tau_low,
                         o.bias_instability_tau_high, o.sample_rate, seed, 1),
      gyro_instability_(o.gyro_bias_instability, o.bias_instability_tau_low,
                        o.bias_instability_tau_high, o.sample_rate, seed, 2) {}

}  // namespace internal
}  // namespace gravcal
