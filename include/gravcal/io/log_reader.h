// gravcal/io/log_reader.h: reads raw IMU logs from text files.
//
// The data contract (docs/data_contract.md, "Raw log"):
// - CSV: a header row naming the columns; `t` (seconds, increasing), `ax`,
//   `ay`, `az` required; `gx`, `gy`, `gz`, `temp` optional; other columns are
//   ignored. Lines starting with '#' are comments; blank lines are skipped.
// - Whitespace-separated text without a header: `columns` gives the names in
//   file order (e.g. {"t", "ax", "ay", "az"}); a second file `gyro_path` in
//   the same layout ({"t", "gx", "gy", "gz"}) may hold the gyroscope, sharing
//   the timestamps of the first.
// Files written by other tools rarely use these names: `rename` maps a
// contract name to the name in the file's header (ax -> acc_x), skip_lines
// drops metadata lines before the header, and a log without a time column gets
// t = index / sample_rate.
//
// ROS 1 bags, rosbag2 .db3, MCAP files and EuRoC / TUM-VI CSV are recognised
// from their first bytes (gravcal/io/recording.h); for them the layout keys
// above do not apply.
//
// Every text log, read here or streamed by imu_stream.h, goes through one
// checked reader: finite values, strictly increasing time, a UTF-8 byte
// order mark dropped, "\n", "\r\n" or CR-only line ends, lines of at most
// 64 KiB, a column named twice refused. Every error names the file and line:
// "session.csv:17: column 'ay': 'abc' is not a number".
#ifndef GRAVCAL_IO_LOG_READER_H_
#define GRAVCAL_IO_LOG_READER_H_

#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "gravcal/core/calibration.h"
#include "gravcal/core/imu_log.h"
#include "gravcal/core/types.h"
#include "gravcal/io/files.h"

namespace gravcal {

struct LogReaderOptions {
  LogFormat format = LogFormat::kCsv;
  // Column names in file order. Required for kWhitespace; for kCsv, when not
  // empty it replaces the header row's names.
  std::vector<std::string> columns;
  // Contract name -> name used in the file, e.g. {"ax", "acc_x"}.
  std::map<std::string, std::string> rename;
  // Lines dropped at the top of the file before the header (metadata).
  int skip_lines = 0;
  // When > 0 and the file has no time column, t = index / sample_rate.
  double sample_rate = 0.0;
  // t in the file is multiplied by this (1e-9 for nanoseconds).
  double time_scale = 1.0;
  // The temperature column in degC: temp = temp_offset + temp_scale * value
  // (a sensor's raw register counts, e.g. ICM-42688: temp_scale 1/132.48,
  // temp_offset 25). temp_scale must be finite and non-zero.
  double temp_scale = 1.0;
  double temp_offset = 0.0;
  // Optional second file holding the gyroscope (kWhitespace layout, columns
  // gyro_columns), sample for sample with the first.
  std::string gyro_path;
  std::vector<std::string> gyro_columns = {"t", "gx", "gy", "gz"};
  // Bags and MCAP files (gravcal/io/recording.h): the sensor_msgs/Imu topic
  // to read; empty takes the only one (several are an error listing them).
  std::string topic;
  // Bags and MCAP files: t is the time the recorder received each message
  // instead of its header.stamp.
  bool record_time = false;
  // Text logs read in bounded memory (gravcal/io/long_log.h: calibrate,
  // noise, batch): at most this many entries held, a longer log read as
  // means of 2^k rows; 0 = no limit (read whole, memory permitting), else at
  // least 16. 2^21 entries are about 128 MiB with gyroscope and temperature.
  int max_log_entries = 1 << 21;

  bool IsValid(std::string* error) const;
};

// Reads `path` into `log`. On failure returns false, leaves `log` unchanged
// and sets `error` to one line naming the file and line.
bool ReadImuLog(const std::string& path, const LogReaderOptions& options, ImuLog* log,
                std::string* error);

// Same, and *provenance gets the file's name, content hash and the
// library's version (calibration_io.h LogProvenance), hashed from the bytes
// read for the log: a text log is read once.
bool ReadImuLog(const std::string& path, const LogReaderOptions& options, ImuLog* log,
                CalibrationProvenance* provenance, std::string* error);

// Same as ReadImuLog on text already in memory; `name` is used in messages.
bool ParseImuLog(std::string_view text, const std::string& name, const LogReaderOptions& options,
                 ImuLog* log, std::string* error);

// Writes the log as contract CSV (t,ax,ay,az[,gx,gy,gz][,temp]) with full
// precision, atomically (temporary file, then rename).
bool WriteImuLogCsv(const ImuLog& log, const std::string& path, std::string* error);

// The text WriteImuLogCsv writes (for a command that puts several files in
// place together, WriteFilesAtomically). False with the reason in `error`.
bool ImuLogToCsv(const ImuLog& log, std::string* contents, std::string* error);

}  // namespace gravcal

#endif  // GRAVCAL_IO_LOG_READER_H_
