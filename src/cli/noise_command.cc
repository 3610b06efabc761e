// gravcal noise: the noise model of a still log (issue 14): noise.json, and
// optionally Kalibr's imu.yaml and the handheld filter's hk_* keys.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "gravcal/io/long_log.h"
#include "gravcal/workflows/noise_workflow.h"

namespace gravcal {
namespace cli {
namespace {

std::string TermText(const NoiseTerm& term, const std::string& unit) {
  char text[64];
  if (!term.visible()) {
    if (!std::isfinite(term.upper_bound)) return "not shown";
    std::snprintf(text, sizeof(text), "not shown (at most %.3g %s)", term.upper_bound,
                  unit.c_str());
    return text;
  }
  std::snprintf(text, sizeof(text), "%.3g %s", term.value, unit.c_str());
  return text;
}

// "gravcal: accel x: N ..., B ..., K ..." on stderr.
void PrintAxis(const char* sensor, char axis, const AxisNoiseModel& m, const std::string& unit,
               const std::string& walk_unit) {
  std::fprintf(stderr, "gravcal: %s %c: N %s, B %s, K %s\n", sensor, axis,
               TermText(m.white_noise, unit + "/sqrt(Hz)").c_str(),
               TermText(m.bias_instability, unit).c_str(),
               TermText(m.random_walk, walk_unit + "/sqrt(Hz)").c_str());
}

}  // namespace

int RunNoise(const LogReportArgs& args) {
  if (args.input.empty()) return Fail("noise needs --input <still log>");
  if (args.output.empty()) return Fail("noise needs --output <noise.json>");
  std::string error;
  NoiseOptions options;
  if (!NoiseOptionsFromConfig(args.config, &options, &error)) return Fail(error);
  for (double density : {args.accel_noise_density, args.gyro_noise_density}) {
    if (!(density >= 0.0) || !std::isfinite(density)) {
      return Fail("noise: --accel-noise-density and --gyro-noise-density must be finite and >= 0");
    }
  }
  // In bounded memory: a long log is read as block means (io/long_log.h).
  ImuLog log;
  LongLogReading reading;
  reading.max_samples = static_cast<size_t>(args.config.input.max_log_entries);
  if (!ReadImuLogBounded(args.input, args.config.input, &reading, &log, nullptr, &error)) {
    return Fail(error);
  }
  ImuNoise noise;
  if (!CharacteriseLongLogNoise(log, reading, options, &noise, &error)) return Fail(error);
  // Against the datasheet's densities, when given (noise_workflow.h).
  NoiseDatasheetCheck datasheet;
  const bool compared = args.accel_noise_density > 0.0 || args.gyro_noise_density > 0.0;
  if (compared) {
    CheckNoiseAgainstDatasheet(log, reading, noise, args.accel_noise_density,
                               args.gyro_noise_density, &datasheet);
  }
  std::vector<std::string> written;
  if (!WriteNoiseFiles(noise, args.input, {args.output, args.kalibr, args.handheld, args.report},
                       &written, &error, compared ? &datasheet : nullptr)) {
    return Fail(error);
  }
  const char* axes = "xyz";
  for (int a = 0; a < 3; ++a) {
    PrintAxis("accel", axes[a], noise.model.accel[a], "m/s^2", "m/s^3");
  }
  for (int a = 0; a < 3 && log.has_gyro(); ++a) {
    PrintAxis("gyro", axes[a], noise.model.gyro[a], "rad/s", "rad/s^2");
  }
  for (const std::string& note : datasheet.notes) {
    std::fprintf(stderr, "gravcal: %s\n", note.c_str());
  }
  std::string files;
  for (const std::string& w : written) files += (files.empty() ? "" : ", ") + w;
  std::fprintf(stderr, "gravcal: %s; wrote %s\n", noise.message.c_str(), files.c_str());
  return 0;
}

}  // namespace cli
}  // namespace gravcal
