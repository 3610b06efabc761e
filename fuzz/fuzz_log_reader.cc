// Fuzz target: the IMU log reader in every layout. The first byte picks the
// layout (csv with a header, whitespace with columns, renamed columns,
// skip_lines, sample_rate without time, a second gyroscope file); the rest
// is the file (for the two-file layout, split at the first 0 byte: log,
// then gyroscope file). A log read must have at least one sample, finite
// values, strictly increasing time and matching lengths.
#include <cmath>
#include <cstdint>
#include <string>

#include "fuzz_check.h"
#include "gravcal/core/imu_log.h"
#include "gravcal/io/log_reader.h"

using gravcal::fuzz::Require;

namespace {

void CheckLog(const gravcal::ImuLog& log) {
  const size_t n = log.t.size();
  Require(n > 0, "a log read without samples");
  Require(log.accel.size() == n, "accel length");
  Require(log.gyro.empty() || log.gyro.size() == n, "gyro length");
  Require(log.temperature.empty() || log.temperature.size() == n, "temperature length");
  for (size_t i = 0; i < n; ++i) {
    Require(std::isfinite(log.t[i]) && log.accel[i].allFinite(), "non-finite sample");
    Require(log.gyro.empty() || log.gyro[i].allFinite(), "non-finite gyro");
    Require(log.temperature.empty() || std::isfinite(log.temperature[i]), "non-finite temp");
    Require(i == 0 || log.t[i] > log.t[i - 1], "time does not increase");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const uint8_t layout = data[0] % 6;
  std::string text(reinterpret_cast<const char*>(data + 1), size - 1);
  gravcal::LogReaderOptions options;
  switch (layout) {
    case 0:  // CSV with its header row.
      break;
    case 1:
      options.format = gravcal::LogFormat::kWhitespace;
      options.columns = {"t", "ax", "ay", "az", "gx", "gy", "gz", "temp"};
      break;
    case 2:
      options.rename = {{"t", "time"}, {"ax", "acc_x"}, {"ay", "acc_y"}, {"az", "acc_z"}};
      options.time_scale = 1e-3;
      break;
    case 3:
      options.skip_lines = 2;
      options.columns = {"t", "ax", "ay", "az"};
      break;
    case 4:
      options.sample_rate = 100.0;
      break;
    case 5: {
      const size_t split = text.find('\0');
      const std::string gyro = split == std::string::npos ? std::string() : text.substr(split + 1);
      if (split != std::string::npos) text.resize(split);
      options.format = gravcal::LogFormat::kWhitespace;
      options.columns = {"t", "ax", "ay", "az"};
      options.gyro_path = gravcal::fuzz::WriteScratch(
          "_gyro.txt", reinterpret_cast<const uint8_t*>(gyro.data()), gyro.size());
      break;
    }
  }
  gravcal::ImuLog log;
  std::string error;
  const bool ok = gravcal::ParseImuLog(text, "fuzz.csv", options, &log, &error);
  gravcal::fuzz::RequireOutcome(ok, error);
  if (ok) {
    CheckLog(log);
    if (layout == 5) Require(log.gyro.size() == log.t.size(), "two-file log without gyro");
  }
  return 0;
}
