// gravcal/io/imu_stream.h: raw logs (docs/data_contract.md, "Raw log") read
// and contract CSV written one sample at a time, in constant memory, for logs
// larger than memory. "-" names standard input / standard output.
//
// The reader holds every text log to the same rules as log_reader.h (one
// checked line reader, src/io/log_text.h): the same layouts and input keys,
// finite values, strictly increasing time, a byte order mark dropped, "\n",
// "\r\n" or "\r" line ends, lines of at most 64 KiB (a file without line
// ends costs one buffer), the same messages naming the file and line. Text
// is read in constant memory; a ROS bag, rosbag2 or MCAP file and a layout
// with a second gyroscope file (gyro_path) are read whole by log_reader.h
// and served from memory.
//
// The writer writes through AtomicFile (files.h: the destination contract),
// so a failure leaves no partial file; on standard output it writes
// as it goes (callers check everything they can before the first sample).
#ifndef GRAVCAL_IO_IMU_STREAM_H_
#define GRAVCAL_IO_IMU_STREAM_H_

#include <Eigen/Core>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "gravcal/io/files.h"
#include "gravcal/io/log_reader.h"

namespace gravcal {

// One row of a contract log. gyro is zero and temperature NaN when the log
// has no such columns.
struct ImuSample {
  double t = 0.0;
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();
  double temperature = NAN;
};

class ImuCsvStreamReader {
 public:
  ImuCsvStreamReader();
  ~ImuCsvStreamReader();
  ImuCsvStreamReader(const ImuCsvStreamReader&) = delete;
  ImuCsvStreamReader& operator=(const ImuCsvStreamReader&) = delete;

  // Opens `path` ("-" = standard input) and reads up to the header row
  // (contract CSV, or the layout `options` describe). A log without a row
  // is "log.csv: no samples", as for ReadImuLog.
  bool Open(const std::string& path, std::string* error);
  bool Open(const std::string& path, const LogReaderOptions& options, std::string* error);
  bool has_gyro() const { return has_gyro_; }
  bool has_temperature() const { return has_temperature_; }
  // The next sample. False at the end of the file (error left empty) or on
  // a bad row (error set: "log.csv:17: column 'ay': 'abc' is not a number").
  bool Next(ImuSample* sample, std::string* error);
  // The name used in messages ("standard input" for "-").
  const std::string& name() const { return name_; }
  // Where the last sample was, for messages: "log.csv:17" for text,
  // "log.bag: sample 16" for a log read whole.
  std::string where() const;
  // The same place as a number (the line for text, the sample for a log
  // read whole), to name it later with where(position) (gravcal apply
  // corrects rows on other threads).
  size_t position() const;
  std::string where(size_t position) const;

 private:
  struct State;
  std::unique_ptr<State> state_;
  std::string name_;
  bool has_gyro_ = false;
  bool has_temperature_ = false;
};

class ImuCsvStreamWriter {
 public:
  ImuCsvStreamWriter() = default;
  // Abort()s when not committed.
  ~ImuCsvStreamWriter();
  ImuCsvStreamWriter(const ImuCsvStreamWriter&) = delete;
  ImuCsvStreamWriter& operator=(const ImuCsvStreamWriter&) = delete;

  // Opens `path` ("-" = standard output) and writes `comment` (lines without
  // the leading "# ", may be empty) and the header row t,ax,ay,az[,gx,gy,gz]
  // [,temp].
  bool Open(const std::string& path, bool gyro, bool temperature,
            const std::vector<std::string>& comment, std::string* error);
  // Numbers are written in the shortest form that reads back exactly.
  bool Write(const ImuSample& sample, std::string* error);
  // The row Write writes, formatted at p (room for kMaxRowBytes); returns
  // its end. For callers that format rows on several threads.
  static constexpr size_t kMaxRowBytes = 8 * 25;
  static char* FormatRow(const ImuSample& sample, bool gyro, bool temperature, char* p);
  // Rows formatted by FormatRow (with this writer's gyro and temperature).
  bool WriteRows(const char* text, size_t size, std::string* error);
  // Flushes, closes and renames the temporary file onto the output.
  bool Commit(std::string* error);
  // Removes the temporary file (nothing for standard output).
  void Abort();

 private:
  bool Flush(std::string* error);
  bool WriteOut(const char* data, size_t size, std::string* error);

  // Standard output, or nullptr when writing to `file_`.
  std::FILE* stdout_ = nullptr;
  AtomicFile file_;
  bool open_ = false;
  std::string path_;
  bool gyro_ = false;
  bool temperature_ = false;
  std::string buffer_;
};

}  // namespace gravcal

#endif  // GRAVCAL_IO_IMU_STREAM_H_
