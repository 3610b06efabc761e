#include "gravcal/workflows/noise_workflow.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>
#include <utility>

#include "estimation/nyquist_flatness.h"
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

namespace {

// One axis's note (noise_workflow.h, CheckNoiseAgainstDatasheet).
std::string DatasheetNote(const std::string& name, const AxisNoiseModel& axis, double datasheet,
                          double flatness, double rate_hz, bool block_means) {
  // Datasheet figures are typical values; parts scatter by tens of percent.
  constexpr double kTypical = 1.3;
  // A white spectrum's top band holds at least this share of its middle's
  // amplitude (Welch medians over about 20 bins: a few percent of scatter);
  // a filter at Nyquist would take off about 30 %.
  constexpr double kFlat = 0.85;
  std::ostringstream s;
  s.precision(3);
  if (!axis.white_noise.visible()) {
    s << name << ": N not determined, not compared with the datasheet's " << datasheet;
    return s.str();
  }
  const double ratio = axis.white_noise.value / datasheet;
  s << name << ": N is " << ratio << " times the datasheet's " << datasheet;
  if (ratio <= kTypical && ratio >= 1.0 / kTypical) return s.str() + " (within its scatter)";
  const double nyquist = 0.5 * rate_hz;
  if (ratio < 1.0 / kTypical) {
    s << ": a quieter part than typical, or a low-pass filter below the datasheet's bandwidth";
    if (std::isfinite(flatness)) {
      s << " (the spectrum at Nyquist is " << flatness << " of its mid level)";
    }
  } else if (block_means) {
    s << "; a log read as block means keeps no spectrum up to the rows' Nyquist, so aliasing "
         "is not judged";
  } else if (!std::isfinite(flatness)) {
    s << "; the still interval is too short for the spectrum to tell aliasing";
  } else if (flatness >= kFlat) {
    s << "; the spectrum is flat up to Nyquist (" << nyquist << " Hz: " << flatness
      << " of its level at 0.2-0.4 of Nyquist), so the sensor's bandwidth reaches past it: "
         "possibly aliasing, noise above Nyquist folded in by sampling at "
      << rate_hz << " Hz (a bandwidth B reads sqrt(2 B / " << rate_hz
      << ") times the part's own density), or a part that noisy. N is the density the "
         "sampled data hold, the one a filter at this rate must use; a lower one needs the "
         "sensor's low-pass filter below "
      << nyquist << " Hz";
  } else {
    s << "; the spectrum falls toward Nyquist (" << flatness
      << " of its mid level), so no aliasing shows: the part or its mounting is that noisy";
  }
  return s.str();
}

}  // namespace

void CheckNoiseAgainstDatasheet(const ImuLog& log, const LongLogReading& reading,
                                const ImuNoise& noise, double accel_density, double gyro_density,
                                NoiseDatasheetCheck* check) {
  *check = NoiseDatasheetCheck();
  const ImuNoiseModel& m = noise.model;
  const bool block_means = reading.samples_averaged > 1;
  const char* axes = "xyz";
  for (int sensor = 0; sensor < 2; ++sensor) {
    const bool gyro = sensor == 1;
    if (gyro && !log.has_gyro()) break;
    const std::vector<Eigen::Vector3d>& x = gyro ? log.gyro : log.accel;
    const double scale = gyro ? noise.gyro_scale : noise.accel_scale;
    const double density = gyro ? gyro_density : accel_density;
    for (int a = 0; a < 3; ++a) {
      double& flatness = gyro ? check->gyro_flatness[a] : check->accel_flatness[a];
      if (!block_means && m.still_end <= x.size()) {
        std::vector<double> samples;
        samples.reserve(m.still_end - m.still_begin);
        for (size_t i = m.still_begin; i < m.still_end; ++i) samples.push_back(scale * x[i](a));
        flatness = internal::NyquistFlatness(samples, 0, samples.size(), m.rate_hz);
      }
      if (!(density > 0.0)) continue;
      check->notes.push_back(DatasheetNote(std::string(gyro ? "gyro " : "accel ") + axes[a],
                                           gyro ? m.gyro[a] : m.accel[a], density, flatness,
                                           m.rate_hz, block_means));
    }
  }
}

bool WriteNoiseFiles(const ImuNoise& noise, const std::string& source, const NoiseFiles& files,
                     std::vector<std::string>* written, std::string* error,
                     const NoiseDatasheetCheck* datasheet) {
  if (!CheckDestinations({{files.json, "noise.json"},
                          {files.kalibr, "kalibr"},
                          {files.handheld, "handheld"},
                          {files.report, "report"}},
                         {{source, "log"}}, error)) {
    return false;
  }
  std::vector<FileContents> texts;
  if (!files.json.empty()) {
    std::string text = NoiseToJson(noise);
    if (datasheet != nullptr) {
      // How far each axis's spectrum reaches toward Nyquist, and N against
      // the datasheet's (CheckNoiseAgainstDatasheet).
      nlohmann::json out = nlohmann::json::parse(text);
      auto flatness = [](const std::array<double, 3>& f) {
        nlohmann::json axes = nlohmann::json::array();
        for (double v : f) axes.push_back(std::isfinite(v) ? nlohmann::json(v) : nullptr);
        return axes;
      };
      out["choices"]["spectrum"] = {{"nyquist_flatness",
                                     {{"accel", flatness(datasheet->accel_flatness)},
                                      {"gyro", flatness(datasheet->gyro_flatness)}}},
                                    {"datasheet", datasheet->notes}};
      text = out.dump(2) + "\n";
    }
    texts.push_back({files.json, text});
  }
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
