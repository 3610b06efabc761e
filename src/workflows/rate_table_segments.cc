#include "gravcal/workflows/rate_table_segments.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "io/csv_table.h"
#include "util/numbers.h"
#include "util/units.h"

namespace gravcal {
namespace {

constexpr const char* kColumns[] = {"t_begin", "t_end", "rate_x_dps", "rate_y_dps", "rate_z_dps"};
// Times equal to a sample's within this are that sample's (printed times
// round-trip exactly; hand-written ones may not).
constexpr double kSegmentTimeTolerance = 1e-6;

bool ParseNumber(const std::string& text, double* v) {
  return ParseCsvNumber(text, v) && std::isfinite(*v);
}

using internal::ExactNumber;

}  // namespace

bool ParseRateTableSegments(std::string_view text, const std::string& name, const ImuLog& log,
                            std::vector<RateTableSegment>* segments, std::string* error) {
  std::vector<CsvRecord> records;
  if (!ParseCsvRecords(text, name, &records, error)) return false;
  if (records.empty()) {
    *error = name + ": no header row (t_begin, t_end, rate_x_dps, rate_y_dps, rate_z_dps)";
    return false;
  }
  std::map<std::string, size_t> column;
  for (size_t i = 0; i < records[0].cells.size(); ++i) column[records[0].cells[i].text] = i;
  for (const char* required : kColumns) {
    if (!column.count(required)) {
      *error = name + ":" + std::to_string(records[0].line) + ": header has no column '" +
               required + "' (needs t_begin, t_end, rate_x_dps, rate_y_dps, rate_z_dps)";
      return false;
    }
  }
  std::vector<RateTableSegment> out;
  for (size_t r = 1; r < records.size(); ++r) {
    const CsvRecord& record = records[r];
    auto fail = [&](const std::string& what) {
      *error = name + ":" + std::to_string(record.line) + ": " + what;
      return false;
    };
    if (record.cells.size() != records[0].cells.size()) {
      return fail("has " + std::to_string(record.cells.size()) + " fields, the header " +
                  std::to_string(records[0].cells.size()));
    }
    double v[5];
    for (int k = 0; k < 5; ++k) {
      if (!ParseNumber(record.cells[column[kColumns[k]]].text, &v[k])) {
        return fail(std::string("'") + kColumns[k] + "' is not a finite number");
      }
    }
    if (!(v[1] > v[0])) return fail("t_end must be after t_begin");
    RateTableSegment s;
    s.begin =
        std::lower_bound(log.t.begin(), log.t.end(), v[0] - kSegmentTimeTolerance) - log.t.begin();
    s.end =
        std::upper_bound(log.t.begin(), log.t.end(), v[1] + kSegmentTimeTolerance) - log.t.begin();
    if (s.end < s.begin + 2) {
      std::ostringstream m;
      m << "the segment " << v[0] << " .. " << v[1] << " s holds fewer than 2 samples of "
        << log.source;
      return fail(m.str());
    }
    s.rate = Eigen::Vector3d(v[2], v[3], v[4]) * internal::kDegToRad;
    out.push_back(s);
  }
  *segments = out;
  return true;
}

bool ReadRateTableSegments(const std::string& path, const ImuLog& log,
                           std::vector<RateTableSegment>* segments, std::string* error) {
  std::ifstream in(path);
  if (!in) {
    *error = path + ": cannot open the segments file";
    return false;
  }
  std::stringstream buffer;
  buffer << in.rdbuf();
  return ParseRateTableSegments(buffer.str(), path, log, segments, error);
}

std::string RateTableSegmentsToCsv(const std::vector<RateTableSegment>& segments,
                                   const ImuLog& log) {
  std::string text = "t_begin,t_end,rate_x_dps,rate_y_dps,rate_z_dps\n";
  for (const RateTableSegment& s : segments) {
    if (s.end <= s.begin || s.end > log.size()) continue;
    // + 0.0 writes a zero rate as 0, not -0.
    const Eigen::Vector3d dps = (s.rate * internal::kRadToDeg).array() + 0.0;
    text += ExactNumber(log.t[s.begin]) + "," + ExactNumber(log.t[s.end - 1]) + "," +
            ExactNumber(dps.x()) + "," + ExactNumber(dps.y()) + "," + ExactNumber(dps.z()) + "\n";
  }
  return text;
}

}  // namespace gravcal
