#include "io/log_pair.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string_view>
#include <system_error>

#include "io/block_averager.h"
#include "util/error.h"
#include "util/numbers.h"

namespace gravcal {
namespace internal {
namespace {

struct PairFileCloser {
  void operator()(std::FILE* file) const { std::fclose(file); }
};

// The next row of the gyroscope file: true with it in `parser`; false at
// the end of the file (error empty) or on its first error.
bool NextGyroRow(LogLines* lines, LogRowParser* parser, std::string* error) {
  std::string_view line;
  while (lines->Next(&line, error)) {
    bool row = false;
    if (!parser->Line(line, lines->number(), &row, error)) return false;
    if (row) return true;
  }
  return false;
}

}  // namespace

bool ParseLogPair(LogLines* source, const std::string& name, const LogReaderOptions& options,
                  size_t max_samples, ImuLog* out, size_t* samples_averaged, size_t* rows_read,
                  std::string* error) {
  const std::string& gyro_name = options.gyro_path;
  // The gyroscope file's first problem waits until the main file is read
  // (whose errors come first, as when both are read whole).
  std::string gyro_error;
  std::unique_ptr<std::FILE, PairFileCloser> file(std::fopen(gyro_name.c_str(), "rb"));
  if (file == nullptr) {
    gyro_error = gyro_name + ": cannot open: " + std::generic_category().message(errno);
  }
  LogLines gyro_lines(file.get(), gyro_name);
  LogRowParser parser(name, options, false);
  LogRowParser gyro_parser(gyro_name, options, true);
  ImuLog log;
  BlockAverager averager(max_samples, &log);
  bool gyro_ended = false;
  size_t gyro_rows = 0;
  std::string_view line;
  std::string why;
  double row[kNumSlots] = {};
  while (source->Next(&line, &why)) {
    bool is_row = false;
    if (!parser.Line(line, source->number(), &is_row, &why)) break;
    if (!is_row) continue;
    const size_t index = parser.rows() - 1;
    if (gyro_error.empty() && !gyro_ended) {
      if (NextGyroRow(&gyro_lines, &gyro_parser, &gyro_error)) {
        ++gyro_rows;
        if (gyro_parser.has(kT)) {
          const double t = gyro_parser.value(kT), r = parser.value(kT);
          if (!(std::fabs(t - r) <=
                kRelativeTimeTolerance * std::max(std::fabs(t), std::fabs(r)))) {
            gyro_error = LogWhere(gyro_name, gyro_lines.number()) + "time " + ExactNumber(t) +
                         " differs from time " + ExactNumber(r) + " of sample " +
                         std::to_string(index) + " in " + name;
          }
        }
      } else if (gyro_error.empty()) {
        gyro_ended = true;
      }
    }
    if (!gyro_error.empty() || gyro_ended) continue;  // Reported after the main file.
    for (int slot = 0; slot < kNumSlots; ++slot) row[slot] = parser.value(slot);
    for (int slot : {kGx, kGy, kGz}) row[slot] = gyro_parser.value(slot);
    if (parser.has(kTemp)) {
      averager.AddRows<true, true>(row, 1);
    } else {
      averager.AddRows<true, false>(row, 1);
    }
  }
  if (!why.empty()) return SetError(error, why);
  if (parser.rows() == 0) return SetError(error, name + ": no samples");
  if (gyro_error.empty() && !gyro_ended) {
    // One more row in the gyroscope file is one too many.
    if (NextGyroRow(&gyro_lines, &gyro_parser, &gyro_error)) {
      gyro_error = LogWhere(gyro_name, gyro_lines.number()) + "more samples than " + name + " (" +
                   std::to_string(parser.rows()) + ")";
    }
  }
  if (!gyro_error.empty()) return SetError(error, gyro_error);
  if (gyro_ended) {
    return SetError(error, LogWhere(gyro_name, std::max<size_t>(gyro_lines.number(), 1)) +
                               "ends after " + std::to_string(gyro_rows) + " samples; " + name +
                               " has " + std::to_string(parser.rows()));
  }
  log.source = name;
  *out = std::move(log);
  *samples_averaged = averager.block();
  *rows_read = parser.rows();
  return true;
}

}  // namespace internal
}  // namespace gravcal
