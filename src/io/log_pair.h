// io/log_pair.h (private): a log whose gyroscope is in a second file
// (LogReaderOptions::gyro_path) read in bounded memory: both files line by
// line in step, each pair of rows into a BlockAverager (io/block_averager.h),
// so neither file is held whole.
#ifndef GRAVCAL_SRC_IO_LOG_PAIR_H_
#define GRAVCAL_SRC_IO_LOG_PAIR_H_

#include <cstddef>
#include <string>

#include "gravcal/core/imu_log.h"
#include "gravcal/io/log_reader.h"
#include "io/log_text.h"

namespace gravcal {
namespace internal {

// Two times agree when they differ by at most this, relative.
constexpr double kRelativeTimeTolerance = 1e-9;

// The main log in `source` (named `name`) and options.gyro_path read in step
// into *out, with at most `max_samples` entries (> 0; the rows each entry
// averages in *samples_averaged, the main file's rows in *rows_read). The
// checks and messages are those of reading both whole: the first error of
// the main file, else the first of the gyroscope file (a row, a time that
// differs from the main file's, more rows), else differing lengths; "name:
// no samples" for a main file without rows. `out` is filled only on success.
bool ParseLogPair(LogLines* source, const std::string& name, const LogReaderOptions& options,
                  size_t max_samples, ImuLog* out, size_t* samples_averaged, size_t* rows_read,
                  std::string* error);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_IO_LOG_PAIR_H_
