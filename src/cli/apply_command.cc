// gravcal apply: every term of a calibration applied to a contract CSV log,
// sample by sample in constant memory (io/imu_stream.h), "-" for standard
// input and output. Logs in another layout (the config's input keys) are
// read whole by log_reader.h and written the same way. Exit 0 written; 1 bad input (no output file;
// on standard output nothing is written when the problem shows before the first sample).
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "cli/commands.h"
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

// True when the config's input keys describe the contract CSV layout, which
// streams; any other layout (log_reader.h) is read whole.
bool ContractLayout(const LogReaderOptions& o) {
  return o.format == LogFormat::kCsv && o.columns.empty() && o.rename.empty() &&
         o.skip_lines == 0 && o.sample_rate == 0.0 && o.time_scale == 1.0 && o.gyro_path.empty();
}

// The samples of the input: streamed for the contract layout, from the whole
// log otherwise.
struct SampleSource {
  std::string name;
  bool has_gyro = false;
  bool has_temperature = false;
  std::function<bool(ImuSample*, std::string*)> next;
};

bool OpenSource(const CommandArgs& args, ImuCsvStreamReader* reader, ImuLog* log,
                SampleSource* source, std::string* error) {
  if (ContractLayout(args.config.input)) {
    if (!reader->Open(args.input, error)) return false;
    source->name = reader->name();
    source->has_gyro = reader->has_gyro();
    source->has_temperature = reader->has_temperature();
    source->next = [reader](ImuSample* s, std::string* e) { return reader->Next(s, e); };
    return true;
  }
  if (args.input == "-") {
    *error =
        "apply: standard input takes the contract CSV layout only (the config's input keys "
        "describe another layout)";
    return false;
  }
  if (!ReadImuLog(args.input, args.config.input, log, error)) return false;
  source->name = args.input;
  source->has_gyro = log->has_gyro();
  source->has_temperature = !log->temperature.empty();
  auto index = std::make_shared<size_t>(0);
  source->next = [log, index](ImuSample* s, std::string* e) {
    e->clear();
    if (*index >= log->size()) return false;
    const size_t i = (*index)++;
    s->t = log->t[i];
    s->accel = log->accel[i];
    s->gyro = log->has_gyro() ? log->gyro[i] : Eigen::Vector3d::Zero();
    s->temperature = log->temperature.empty() ? NAN : log->temperature[i];
    return true;
  };
  return true;
}

}  // namespace

int RunApply(const CommandArgs& args) {
  if (args.calibration.empty()) return Fail("apply needs --calibration <calib.json>");
  if (args.input.empty()) return Fail("apply needs --input <raw log, or - for standard input>");
  if (args.output.empty())
    return Fail("apply needs --output <corrected.csv, or - for standard output>");
  std::string error;
  LoadedCalibration calibration;
  if (!ReadCalibrationJson(args.calibration, &calibration, &error)) return Fail(error);
  for (const std::string& key : calibration.undetermined) {
    std::fprintf(stderr,
                 "gravcal: warning: %s: %s is undetermined in the calibration; applied as 0\n",
                 args.calibration.c_str(), key.c_str());
  }
  const ImuCorrector& corrector = calibration.corrector;
  if (!args.config.IsValid(&error)) return Fail(error);
  ImuCsvStreamReader stream;
  ImuLog log;
  SampleSource reader;
  if (!OpenSource(args, &stream, &log, &reader, &error)) return Fail(error);
  if (corrector.RequiresTemperature() && !reader.has_temperature) {
    return Fail(reader.name +
                ": the calibration has temperature effects and needs a 'temp' column");
  }
  if (corrector.has_gyro && !reader.has_gyro) {
    std::fprintf(stderr,
                 "gravcal: warning: %s has no gx, gy, gz: only the accelerometer is corrected\n",
                 reader.name.c_str());
  }
  // The first sample is read before the output is opened, so that a bad
  // first row writes nothing.
  ImuSample sample;
  const bool any = reader.next(&sample, &error);
  if (!any && !error.empty()) return Fail(error);
  ImuCsvStreamWriter writer;
  if (!writer.Open(args.output, reader.has_gyro, reader.has_temperature,
                   OutputComment(args.calibration, calibration, reader.has_gyro), &error)) {
    return Fail(error);
  }
  size_t count = 0;
  for (bool more = any; more; more = reader.next(&sample, &error)) {
    if (!corrector.CorrectRow(sample.temperature, sample.t, &sample.accel,
                              reader.has_gyro ? &sample.gyro : nullptr)) {
      writer.Abort();
      return Fail(reader.name + ": sample at t = " + std::to_string(sample.t) +
                  ": the quadratic term has no real root (reading outside the calibrated range)");
    }
    if (!writer.Write(sample, &error)) return Fail(error);
    ++count;
  }
  if (!error.empty()) {
    writer.Abort();
    return Fail(error);
  }
  if (!writer.Commit(&error)) return Fail(error);
  if (args.output != "-") {
    std::fprintf(stderr, "gravcal: corrected %zu samples; wrote %s\n", count, args.output.c_str());
  }
  return 0;
}

}  // namespace cli
}  // namespace gravcal
