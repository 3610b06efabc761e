// Private: the noise both simulators (simulator.cc, handheld_simulator.cc)
// add to a simulated sensor's raw output, in raw units:
//   white noise        N(0, accel_noise^2), N(0, gyro_noise^2) per sample;
//   bias random walk   the drift before the sample, then a step
//                      N(0, walk^2 dt);
//   bias instability   per axis a NoiseProcess (gravcal/simulation/
//                      noise_process.h) with only its bias instability
//                      term, from a stream of its own, so that switching it
//                      on changes no other number of a session;
//   tones              amplitude sin(2 pi f k / rate) on the raw axes named
//                      (no random draw);
//   slow line          amplitude sin(2 pi k / (period rate) + phase_i) on
//                      every axis i, the phases from a stream of their own;
// then quantisation to counts when the output is in counts. The white and
// random-walk draws come from the caller's stream (`normal3`, three N(0, 1)),
// in the order the simulators have always drawn them.
#ifndef GRAVCAL_SRC_SIMULATION_SENSOR_NOISE_H_
#define GRAVCAL_SRC_SIMULATION_SENSOR_NOISE_H_

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "gravcal/simulation/noise_process.h"
#include "gravcal/simulation/simulator.h"

namespace gravcal {
namespace internal {

// Limit on a simulated log's samples, against a typo asking for gigabytes.
constexpr double kMaxSimulatedSamples = 1e8;

// Three axes of bias instability B (sensor units) flat over [tau_low,
// tau_high] seconds at rate_hz; B = 0 gives zero forever. `stream` tells the
// accelerometer's from the gyroscope's processes of the same seed.
class BiasInstability {
 public:
  BiasInstability(double bias_instability, double tau_low, double tau_high, double rate_hz,
                  uint64_t seed, uint64_t stream);

  bool on() const { return !axes_.empty(); }
  // The next sample of the three axes (zero when off).
  Eigen::Vector3d Next();

 private:
  std::vector<std::unique_ptr<NoiseProcess>> axes_;
};

class SensorNoise {
 public:
  // Raw units per m/s^2 and per rad/s.
  SensorNoise(const SimulatorOptions& options, double accel_units_per_si, double gyro_units_per_si,
              uint64_t seed);

  // Adds the noise of one sample to the raw accelerometer v and gyroscope u.
  template <typename Normal3>
  void Add(Normal3&& normal3, Eigen::Vector3d* v, Eigen::Vector3d* u) {
    if (accel_noise_ > 0.0) *v += accel_noise_ * normal3();
    if (gyro_noise_ > 0.0) *u += gyro_noise_ * normal3();
    if (accel_walk_ > 0.0) {
      *v += accel_drift_;
      accel_drift_ += accel_walk_ * normal3();
    }
    if (gyro_walk_ > 0.0) {
      *u += gyro_drift_;
      gyro_drift_ += gyro_walk_ * normal3();
    }
    if (accel_instability_.on()) *v += accel_units_per_si_ * accel_instability_.Next();
    if (gyro_instability_.on()) *u += gyro_units_per_si_ * gyro_instability_.Next();
    if (accel_tone_ > 0.0 || gyro_tone_ > 0.0) {
      const double wave = std::sin(tone_step_ * static_cast<double>(sample_));
      *v += accel_tone_ * wave * tone_axes_;
      *u += gyro_tone_ * wave * tone_axes_;
    }
    if (accel_slow_ > 0.0 || gyro_slow_ > 0.0) {
      const double phase = slow_step_ * static_cast<double>(sample_);
      for (int a = 0; a < 3; ++a) {
        const double wave = std::sin(phase + slow_phase_(a));
        (*v)(a) += accel_slow_ * wave;
        (*u)(a) += gyro_slow_ * wave;
      }
    }
    ++sample_;
    if (raw_counts_) {
      *v = v->array().round();
      *u = u->array().round();
    }
  }

 private:
  double accel_units_per_si_;
  double gyro_units_per_si_;
  bool raw_counts_;
  double accel_noise_;
  double gyro_noise_;
  double accel_walk_;
  double gyro_walk_;
  // Raw units, the phase step per sample (rad) and the axes (1 where on).
  double accel_tone_;
  double gyro_tone_;
  double tone_step_;
  Eigen::Vector3d tone_axes_;
  // The slow line: raw units, phase step per sample and each axis's phase.
  double accel_slow_;
  double gyro_slow_;
  double slow_step_;
  Eigen::Vector3d slow_phase_;
  uint64_t sample_ = 0;
  BiasInstability accel_instability_;
  BiasInstability gyro_instability_;
  Eigen::Vector3d accel_drift_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_drift_ = Eigen::Vector3d::Zero();
};

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_SIMULATION_SENSOR_NOISE_H_
