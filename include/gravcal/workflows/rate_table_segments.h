// gravcal/workflows/rate_table_segments.h: the segments file of the
// rate-table method (`method: rate_table`, `--segments segments.csv`): one
// row per stretch of the log turned at a known constant rate.
//
// CSV with a header row; lines starting with '#' and blank lines are
// skipped. Columns (any order):
//   t_begin, t_end          the stretch, s of log time (inclusive; the
//                           ramps of the table excluded);
//   rate_x_dps, rate_y_dps, rate_z_dps  the true body rate about the sensor
//                           axes, deg/s (Earth rate added by the user when
//                           it matters).
// Every row must cover at least 2 samples of the log; errors name the file
// and line.
#ifndef GRAVCAL_WORKFLOWS_RATE_TABLE_SEGMENTS_H_
#define GRAVCAL_WORKFLOWS_RATE_TABLE_SEGMENTS_H_

#include <string>
#include <string_view>
#include <vector>

#include "gravcal/core/imu_log.h"
#include "gravcal/core/rate_table_segment.h"

namespace gravcal {

// Parses the file text into sample ranges of `log`. Errors:
// "<name>:<line>: <what>".
bool ParseRateTableSegments(std::string_view text, const std::string& name, const ImuLog& log,
                            std::vector<RateTableSegment>* segments, std::string* error);

// Reads and parses the file at `path`.
bool ReadRateTableSegments(const std::string& path, const ImuLog& log,
                           std::vector<RateTableSegment>* segments, std::string* error);

// The file text for segments of `log` (times of their first and last
// samples, shortest round-trip form).
std::string RateTableSegmentsToCsv(const std::vector<RateTableSegment>& segments,
                                   const ImuLog& log);

}  // namespace gravcal

#endif  // GRAVCAL_WORKFLOWS_RATE_TABLE_SEGMENTS_H_
