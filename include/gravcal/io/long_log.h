// gravcal/io/long_log.h: long text logs read in bounded memory (issue 39).
//
// ReadImuLogBounded reads a log as ReadImuLog does (log_reader.h: the same
// layouts, checks and one-line errors naming the file and line), but holds
// at most `max_samples` entries whatever the log's length:
// - a log of at most max_samples rows is read exactly as ReadImuLog reads it;
// - a longer one is read in one pass as block means: when the entries fill
//   up, each two neighbours are replaced by their mean, and from then on
//   every 2^k rows (t, accelerometer, gyroscope and temperature alike) enter
//   as one mean; a last incomplete block (fewer than 2^k rows) is dropped.
// No size refusal applies (memory is bounded). A log with a second
// gyroscope file (gyro_path) is read so too, both files in step. Bags and
// MCAP files are read whole, as by ReadImuLog;
// a pipe or device is streamed from its start, unless a provenance is asked
// (its hash needs the length first: then it is read whole).
#ifndef GRAVCAL_IO_LONG_LOG_H_
#define GRAVCAL_IO_LONG_LOG_H_

#include <cstddef>
#include <string>

#include "gravcal/core/calibration.h"
#include "gravcal/core/imu_log.h"
#include "gravcal/io/log_reader.h"

namespace gravcal {

// 2^21 entries: 128 MiB for a log with gyroscope and temperature.
constexpr size_t kDefaultLongLogSamples = size_t{1} << 21;

struct LongLogReading {
  // Most entries held (at least 16; 0 = no limit, as ReadImuLog).
  size_t max_samples = kDefaultLongLogSamples;
  // Threads that parse a long text file (16 MiB or more; a reader thread
  // besides): 0 = one per core, 1 = the calling thread only (for a caller
  // that runs several reads at once). The result is the same.
  int threads = 0;
  // Set by the read: the rows each entry averages (1: the rows as recorded,
  // else a power of two) and the rows read (those of an incomplete last
  // block included).
  size_t samples_averaged = 1;
  size_t rows_read = 0;

  // "the log's 23800000 rows were read in bounded memory as 1487500 means
  // of 16 rows (at most 2097152 held)"; empty when nothing was averaged.
  std::string Describe() const;
};

// Reads `path` into `log` in bounded memory (above); *provenance (may be
// null) as ReadImuLog's. False with a one-line *error naming the file and
// line, `log` unchanged.
bool ReadImuLogBounded(const std::string& path, const LogReaderOptions& options,
                       LongLogReading* reading, ImuLog* log, CalibrationProvenance* provenance,
                       std::string* error);

// Adds the warning (kParameterSource) that says a calibration came from
// block means, when `reading` averaged.
void AddLongLogWarning(const LongLogReading& reading, Calibration* calibration);

}  // namespace gravcal

#endif  // GRAVCAL_IO_LONG_LOG_H_
