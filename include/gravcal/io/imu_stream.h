// gravcal/io/imu_stream.h: contract CSV logs (docs/data_contract.md, "Raw
// log") read and written one sample at a time, in constant memory, for logs
// larger than memory. "-" names standard input / standard output.
//
// The reader takes the contract layout only: a header row naming the columns,
// `t`, `ax`, `ay`, `az` required, `gx`, `gy`, `gz`, `temp` optional, other
// columns ignored, `#` lines and blank lines skipped, commas between fields.
// (Other layouts and renamings: log_reader.h, which loads the whole log.)
// Errors name the file and line, like log_reader.h.
//
// The writer writes through AtomicFile (files.h: the destination contract),
// so a failure leaves no partial file; on standard output it writes
// as it goes (callers check everything they can before the first sample).
#ifndef GRAVCAL_IO_IMU_STREAM_H_
#define GRAVCAL_IO_IMU_STREAM_H_

#include <Eigen/Core>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "gravcal/io/files.h"

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
  ImuCsvStreamReader() = default;
  ~ImuCsvStreamReader();
  ImuCsvStreamReader(const ImuCsvStreamReader&) = delete;
  ImuCsvStreamReader& operator=(const ImuCsvStreamReader&) = delete;

  // Opens `path` ("-" = standard input) and reads up to the header row.
  bool Open(const std::string& path, std::string* error);
  bool has_gyro() const { return gyro_column_[0] >= 0; }
  bool has_temperature() const { return temperature_column_ >= 0; }
  // The next sample. False at the end of the file (error left empty) or on
  // a bad row (error set: "log.csv:17: column 'ay': 'abc' is not a number").
  bool Next(ImuSample* sample, std::string* error);
  // The name used in messages ("standard input" for "-").
  const std::string& name() const { return name_; }

 private:
  // The next line without its end of line; false at the end of the file.
  bool ReadLine(const char** begin, const char** end, std::string* error);
  bool Fail(const std::string& message, std::string* error) const;

  std::FILE* file_ = nullptr;
  bool owns_file_ = false;
  std::string name_;
  std::vector<char> buffer_;
  size_t begin_ = 0;
  size_t end_ = 0;
  bool eof_ = false;
  long line_ = 0;
  std::vector<std::string> columns_;
  int time_column_ = -1;
  int accel_column_[3] = {-1, -1, -1};
  int gyro_column_[3] = {-1, -1, -1};
  int temperature_column_ = -1;
  int last_needed_column_ = -1;
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
  // Flushes, closes and renames the temporary file onto the output.
  bool Commit(std::string* error);
  // Removes the temporary file (nothing for standard output).
  void Abort();

 private:
  bool Flush(std::string* error);

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
