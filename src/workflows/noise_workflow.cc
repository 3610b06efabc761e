#include "gravcal/workflows/noise_workflow.h"

#include <cmath>
#include <cstdio>

#include "gravcal/core/gravity.h"

namespace gravcal {

bool NoiseOptionsFromConfig(const Config& config, NoiseOptions* options, std::string* error) {
  *options = config.noise;
  options->accel_scale = config.calibration.nominal_scale;
  options->gyro_scale = config.handheld.gyro_nominal_scale;
  options->detector = config.calibration.detector;
  if (!config.input.IsValid(error)) {
    *error = "input: " + *error;
    return false;
  }
  return options->IsValid(error);
}

bool CharacteriseLogNoise(const ImuLog& log, const NoiseOptions& options, ImuNoise* noise,
                          std::string* error) {
  if (!CharacteriseNoise(log, options, noise)) {
    *error = noise->message;
    return false;
  }
  const ImuNoiseModel& m = noise->model;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (size_t i = m.still_begin; i < m.still_end; ++i) mean += log.accel[i];
  const double g =
      options.accel_scale * mean.norm() / static_cast<double>(m.still_end - m.still_begin);
  if (std::abs(g / kStandardGravity - 1.0) <= 0.1) return true;
  char text[256];
  std::snprintf(text, sizeof(text),
                "%s: |mean accelerometer| over the still interval is %.4g m/s^2 with "
                "nominal_scale %.6g, not about 9.8: set nominal_scale to m/s^2 per raw unit",
                log.source.c_str(), g, options.accel_scale);
  *error = text;
  return false;
}

}  // namespace gravcal
