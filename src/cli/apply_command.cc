// gravcal apply: every term of a calibration applied to a raw log, sample by
// sample (io/imu_stream.h: the log reader's layouts, rules and messages; text
// in constant memory), "-" for standard input and output. Exit 0 written; 1
// bad input (no output file; on standard output nothing is written when the
// problem shows before the first sample).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "gravcal/core/thermal_rate.h"
#include "gravcal/io/calibration_io.h"
#include "gravcal/io/imu_stream.h"
#include "gravcal/io/log_reader.h"

namespace gravcal {
namespace cli {

namespace {

// The comment lines above the header: what was applied and the units.
std::vector<std::string> OutputComment(const std::string& calibration_path,
                                       const LoadedCalibration& c, bool gyro) {
  std::vector<std::string> lines = {
      "gravcal apply: corrected with " + calibration_path +
          (c.provenance.log_file.empty() ? "" : " (from " + c.provenance.log_file + ")"),
      std::string("units: t s (as read), ax ay az m/s^2 (housing frame)") +
          (gyro ? (c.corrector.has_gyro ? ", gx gy gz rad/s"
                                        : ", gx gy gz raw (the calibration has no gyroscope)")
                : "") +
          ", temp degC (as read)"};
  return lines;
}

}  // namespace

// Samples further than this outside a thermal model's valid range are
// counted in apply's warning, degrees C.
constexpr double kClampWarningDegrees = 0.5;

int RunApply(const ApplyArgs& args) {
  std::string calibration_path, error;
  if (!ResolveCalibrationPath(args.calibration, args.stored, &calibration_path, &error)) {
    return Fail(error);
  }
  if (calibration_path.empty()) {
    return Fail("apply needs --calibration <calib.json> (or --store DIR --unit SN)");
  }
  if (args.input.empty()) return Fail("apply needs --input <raw log, or - for standard input>");
  if (args.output.empty())
    return Fail("apply needs --output <corrected.csv, or - for standard output>");
  LoadedCalibration calibration;
  if (!ReadCalibrationJson(calibration_path, &calibration, &error)) return Fail(error);
  for (const std::string& key : calibration.undetermined) {
    std::fprintf(stderr,
                 "gravcal: warning: %s: %s is undetermined in the calibration; applied as 0\n",
                 calibration_path.c_str(), key.c_str());
  }
  const ImuCorrector& corrector = calibration.corrector;
  if (!args.config.IsValid(&error)) return Fail(error);
  // Every layout through the one checked reader (io/imu_stream.h): text in
  // constant memory, the same rules and messages as calibrate.
  ImuCsvStreamReader reader;
  if (!reader.Open(args.input, args.config.input, &error)) return Fail(error);
  if (corrector.RequiresTemperature() && !reader.has_temperature()) {
    return Fail(reader.name() +
                ": the calibration has temperature effects and needs a 'temp' column");
  }
  if (corrector.HasThermal() && !reader.has_temperature()) {
    return Fail(reader.name() +
                ": the calibration has a thermal model (key 'thermal') and needs a 'temp' column");
  }
  if (corrector.has_gyro && !reader.has_gyro()) {
    std::fprintf(stderr,
                 "gravcal: warning: %s has no gx, gy, gz: only the accelerometer is corrected\n",
                 reader.name().c_str());
  }
  // The first sample is read before the output is opened, so that a bad
  // first row writes nothing (a log without one is an error).
  ImuSample sample;
  if (!reader.Next(&sample, &error)) return Fail(error);
  ImuCsvStreamWriter writer;
  if (!writer.Open(args.output, reader.has_gyro(), reader.has_temperature(),
                   OutputComment(calibration_path, calibration, reader.has_gyro()), &error)) {
    return Fail(error);
  }
  size_t count = 0;
  // Issue 35: the thermal model's lag needs the element temperature's rate; its
  // range is clamped (and counted for one warning).
  ThermalElementRate rate(corrector.thermal.lag_time_constant);
  size_t clamped_count = 0;
  double lowest = INFINITY, highest = -INFINITY;
  for (bool more = true; more; more = reader.Next(&sample, &error)) {
    bool clamped = false;
    const double temperature_rate = rate.Add(sample.t, sample.temperature);
    if (!corrector.CorrectRow(sample.temperature, temperature_rate, sample.t, &sample.accel,
                              reader.has_gyro() ? &sample.gyro : nullptr, &clamped)) {
      writer.Abort();
      return Fail(reader.where() +
                  ": the quadratic term has no real root (reading outside the calibrated range)");
    }
    // Finite readings and a checked calibration can still overflow (a
    // reading of 1e300 counts): nothing that is not a number is written.
    if (!sample.accel.allFinite() || !sample.gyro.allFinite()) {
      writer.Abort();
      return Fail(reader.where() +
                  ": the corrected sample is not finite (the reading times the "
                  "calibration overflows)");
    }
    if (!writer.Write(sample, &error)) return Fail(error);
    ++count;
    // Clamped by more than the temperature sensor's noise: counted.
    const ThermalModel& th = corrector.thermal;
    if (clamped && (sample.temperature < th.min_temperature - kClampWarningDegrees ||
                    sample.temperature > th.max_temperature + kClampWarningDegrees)) {
      ++clamped_count;
      lowest = std::min(lowest, sample.temperature);
      highest = std::max(highest, sample.temperature);
    }
  }
  if (!error.empty()) {
    writer.Abort();
    return Fail(error);
  }
  if (!writer.Commit(&error)) return Fail(error);
  if (clamped_count > 0) {
    std::fprintf(stderr,
                 "gravcal: warning: %zu samples (temperatures %.1f to %.1f degC) lie more than "
                 "0.5 degC outside the thermal model's range [%.1f, %.1f] degC; the correction "
                 "there is clamped at the range's ends, as PX4 does\n",
                 clamped_count, lowest, highest, corrector.thermal.min_temperature,
                 corrector.thermal.max_temperature);
  }
  if (args.output != "-") {
    std::fprintf(stderr, "gravcal: corrected %zu samples; wrote %s\n", count, args.output.c_str());
  }
  return 0;
}

}  // namespace cli
}  // namespace gravcal
