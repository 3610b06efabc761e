// The simulated sensor's noise model as `gravcal noise` would measure it,
// and `gravcal calibrate --noise` with it: shared by the hand-placed
// property test and gyro_bias_wander_test.
#ifndef GRAVCAL_TESTS_SIMULATED_NOISE_H_
#define GRAVCAL_TESTS_SIMULATED_NOISE_H_

#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "gravcal/estimation/allan_deviation.h"
#include "gravcal/io/noise_io.h"
#include "gravcal/simulation/simulator.h"
#include "gravcal/workflows/config.h"
#include "gravcal/workflows/pipeline.h"
#include "test_util.h"

namespace gravcal {
namespace testing_util {

// The noise model of the simulated sensor (SimulatorOptions: white noise
// per sample, bias instability B, rate random walk K), in noise.json's SI
// units, as a perfect `gravcal noise` on a long still log would fit it.
inline ImuNoise SimulatedNoiseModel(const SimulatorOptions& o) {
  ImuNoise noise;
  noise.model.rate_hz = o.sample_rate;
  auto fill = [&](std::array<AxisNoiseModel, 3>* axes, double white, double b, double k) {
    for (AxisNoiseModel& a : *axes) {
      a.white_noise.value = white / std::sqrt(o.sample_rate);
      if (b > 0.0) a.bias_instability.value = b;
      if (k > 0.0) a.random_walk.value = k;
    }
  };
  fill(&noise.model.accel, o.accel_noise, o.accel_bias_instability, o.accel_bias_random_walk);
  fill(&noise.model.gyro, o.gyro_noise, o.gyro_bias_instability, o.gyro_bias_random_walk);
  // noise.json writes a sensor with its curves: one point each, at 1 s.
  auto curve = [&](const std::array<AxisNoiseModel, 3>& axes, std::array<AllanDeviation, 3>* out) {
    for (int a = 0; a < 3; ++a) {
      AllanPoint p;
      p.tau = 1.0;
      p.m = static_cast<size_t>(o.sample_rate);
      p.adev = p.lo = p.hi = std::sqrt(axes[a].AllanVariance(1.0));
      p.edf = 1.0;
      (*out)[a].rate_hz = o.sample_rate;
      (*out)[a].confidence = AllanOptions().confidence;
      (*out)[a].points = {p};
    }
  };
  curve(noise.model.accel, &noise.accel_curves);
  curve(noise.model.gyro, &noise.gyro_curves);
  return noise;
}

// RunCalibration of `log` with --noise: config.simulation's noise.json,
// written to a temporary file and removed after.
inline bool CalibrateWithSimulatedNoise(const Config& config, const ImuLog& log,
                                        const std::string& source, Calibration* calibration) {
  std::string path = testing_util::ScratchFileTemplate("gravcal_noise_");
  const int fd = mkstemp(path.data());
  if (fd < 0) {
    calibration->message = "cannot create a temporary noise.json";
    return false;
  }
  close(fd);
  std::string error;
  if (!WriteNoiseJson(SimulatedNoiseModel(config.simulation), path, &error)) {
    std::remove(path.c_str());
    calibration->message = error;
    return false;
  }
  PipelineInput pipeline;
  pipeline.log = log;
  pipeline.source = source;
  pipeline.noise_path = path;
  const bool ok = RunCalibration(config, pipeline, calibration);
  std::remove(path.c_str());
  return ok;
}

}  // namespace testing_util
}  // namespace gravcal

#endif  // GRAVCAL_TESTS_SIMULATED_NOISE_H_
