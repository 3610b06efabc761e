// Writing an ImuLog as the contract's CSV (the reader's inverse): the
// shortest text that reads back to each double, so a written log reads
// back to the same bits.
#include <cmath>
#include <cstring>
#include <exception>
#include <string>
#include <utility>

#include "gravcal/io/files.h"
#include "gravcal/io/log_reader.h"
#include "util/error.h"
#include "util/shortest_double.h"

namespace gravcal {
namespace {

using internal::SetError;

// Checks what the writer needs without ImuLog::Validate's per-sample cost.
bool CheckWritable(const ImuLog& log, std::string* why) {
  const size_t n = log.t.size();
  if (n == 0) return SetError(why, "no samples");
  if (log.accel.size() != n) return SetError(why, "accelerometer and time have different lengths");
  if (!log.gyro.empty() && log.gyro.size() != n) {
    return SetError(why, "gyroscope and time have different lengths");
  }
  if (!log.temperature.empty() && log.temperature.size() != n) {
    return SetError(why, "temperature and time have different lengths");
  }
  for (size_t i = 0; i < n; ++i) {
    const bool finite = std::isfinite(log.t[i]) && log.accel[i].allFinite() &&
                        (log.gyro.empty() || log.gyro[i].allFinite()) &&
                        (log.temperature.empty() || std::isfinite(log.temperature[i]));
    if (!finite) return SetError(why, "sample " + std::to_string(i) + ": a value is not finite");
    if (i > 0 && !(log.t[i] > log.t[i - 1])) {
      return SetError(why, "sample " + std::to_string(i) + ": time does not increase");
    }
  }
  return true;
}

}  // namespace

bool ImuLogToCsv(const ImuLog& log, std::string* text, std::string* error) {
  try {
    std::string why;
    if (!CheckWritable(log, &why)) return SetError(error, "cannot write log: " + why);
    const bool gyro = log.has_gyro();
    const bool temperature = log.has_temperature();
    std::string header = "t,ax,ay,az";
    if (gyro) header += ",gx,gy,gz";
    if (temperature) header += ",temp";
    header += '\n';
    const size_t columns = 4 + (gyro ? 3 : 0) + (temperature ? 1 : 0);
    // The shortest round-trip form of a double has at most 24 characters;
    // one more for the separator.
    constexpr size_t kMaxField = 25;
    std::string contents;
    contents.resize(header.size() + log.size() * columns * kMaxField);
    char* p = contents.data();
    std::memcpy(p, header.data(), header.size());
    p += header.size();
    auto put = [&](double x, char separator) {
      p = internal::WriteShortestDouble(x, p);
      *p++ = separator;
    };
    for (size_t i = 0; i < log.size(); ++i) {
      put(log.t[i], ',');
      put(log.accel[i].x(), ',');
      put(log.accel[i].y(), ',');
      put(log.accel[i].z(), gyro || temperature ? ',' : '\n');
      if (gyro) {
        put(log.gyro[i].x(), ',');
        put(log.gyro[i].y(), ',');
        put(log.gyro[i].z(), temperature ? ',' : '\n');
      }
      if (temperature) put(log.temperature[i], '\n');
    }
    contents.resize(static_cast<size_t>(p - contents.data()));
    *text = std::move(contents);
    return true;
  } catch (const std::exception& e) {
    return SetError(error, std::string("cannot write log: ") + e.what());
  }
}

bool WriteImuLogCsv(const ImuLog& log, const std::string& path, std::string* error) {
  std::string contents;
  if (!ImuLogToCsv(log, &contents, error)) return SetError(error, path + ": " + *error);
  return WriteFileAtomically(path, contents, error);
}

}  // namespace gravcal
