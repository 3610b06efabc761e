#include "gravcal/workflows/noise_workflow.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

#include "gravcal/core/gravity.h"
#include "gravcal/io/files.h"
#include "gravcal/io/noise_io.h"
#include "gravcal/workflows/report.h"

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
  mean /= static_cast<double>(m.still_end - m.still_begin);
  const bool offset_stated = options.accel_offset.squaredNorm() > 0.0;
  const double g = options.accel_scale * (mean - options.accel_offset).norm();
  char text[400];
  if (std::abs(g / kStandardGravity - 1.0) <= 0.1) {
    std::snprintf(text, sizeof(text),
                  "checked: |mean accelerometer%s| over the still interval is %.4g m/s^2 with "
                  "nominal_scale %.6g, within 10 %% of standard gravity",
                  offset_stated ? " - nominal_offset" : "", g, options.accel_scale);
    noise->unit_check = text;
    return true;
  }
  // An unknown offset can move |mean| anywhere below the largest offset a
  // sensor has (about 30 g: unsigned counts of a +-16 g part), but not to
  // 1 m/s^2 exactly (data in g) nor far beyond.
  const bool in_g = std::abs(g - 1.0) <= 0.1;
  if (offset_stated || in_g || g > 100.0 * kStandardGravity) {
    std::snprintf(
        text, sizeof(text),
        "%s: |mean accelerometer%s| over the still interval is %.4g m/s^2 with "
        "nominal_scale %.6g, not about 9.8%s",
        log.source.c_str(), offset_stated ? " - nominal_offset" : "", g, options.accel_scale,
        in_g            ? ": the data look like g, set nominal_scale 9.80665"
        : offset_stated ? ": set nominal_scale to m/s^2 per raw unit and nominal_offset to the raw "
                          "value at zero specific force"
                        : ": set nominal_scale to m/s^2 per raw unit");
    *error = text;
    return false;
  }
  std::snprintf(text, sizeof(text),
                "not checked: |mean accelerometer| over the still interval is %.4g m/s^2 with "
                "nominal_scale %.6g, not about 9.8, taken as a raw offset (the Allan deviation "
                "removes the mean; nominal_offset would let the unit be checked against gravity)",
                g, options.accel_scale);
  noise->unit_check = text;
  noise->message += std::string("; unit ") + text;
  return true;
}

bool CharacteriseLongLogNoise(const ImuLog& log, const LongLogReading& reading,
                              const NoiseOptions& options, ImuNoise* noise, std::string* error) {
  const size_t block = std::max<size_t>(reading.samples_averaged, 1);
  if (block == 1) return CharacteriseLogNoise(log, options, noise, error);
  const double b = static_cast<double>(block);
  NoiseOptions on_means = options;
  on_means.rate_hz /= b;
  if (!CharacteriseLogNoise(log, on_means, noise, error)) return false;
  ImuNoiseModel& model = noise->model;
  model.rate_hz *= b;
  model.still_begin *= block;
  model.still_end *= block;
  noise->timing.rate_hz *= b;
  noise->timing.median_step /= b;
  auto per_row = [&](AllanDeviation* curve) {
    curve->rate_hz *= b;
    curve->samples *= block;
    for (AllanPoint& p : curve->points) p.m *= block;
  };
  for (int a = 0; a < 3; ++a) {
    per_row(&noise->accel_curves[a]);
    per_row(&noise->gyro_curves[a]);
  }
  per_row(&noise->temperature_curve);
  char text[300];
  std::snprintf(text, sizeof(text),
                ": the rate above is the means' (the rows' is %.6g Hz, noise.json's rate_hz), "
                "and the Allan deviation is the overlapping estimate on the means (stride %zu "
                "rows), taus from %.4g s",
                model.rate_hz, block, block / model.rate_hz);
  const std::string said = reading.Describe() + text;
  noise->message += "; " + said;
  noise->timing.message += noise->timing.message.empty() ? said : "; " + said;
  return true;
}

bool WriteNoiseFiles(const ImuNoise& noise, const std::string& source, const NoiseFiles& files,
                     std::vector<std::string>* written, std::string* error) {
  if (!CheckDestinations({{files.json, "noise.json"},
                          {files.kalibr, "kalibr"},
                          {files.handheld, "handheld"},
                          {files.report, "report"}},
                         {{source, "log"}}, error)) {
    return false;
  }
  std::vector<FileContents> texts;
  if (!files.json.empty()) texts.push_back({files.json, NoiseToJson(noise)});
  if (!files.kalibr.empty()) {
    std::string yaml;
    if (!NoiseToKalibrYaml(noise.model, &yaml, error)) {
      *error = files.kalibr + ": " + *error;
      return false;
    }
    texts.push_back({files.kalibr, yaml});
  }
  if (!files.handheld.empty()) texts.push_back({files.handheld, NoiseToHandheldYaml(noise.model)});
  if (!files.report.empty()) texts.push_back({files.report, NoiseToHtml(noise, source)});
  // All or none: a failed second file leaves the first as it was.
  if (!WriteFilesAtomically(texts, error)) return false;
  std::vector<std::string> done;
  for (const FileContents& f : texts) done.push_back(f.path);
  if (written != nullptr) *written = done;
  return true;
}

}  // namespace gravcal
