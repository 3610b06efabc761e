#include "gravcal/io/attitude_fixture.h"

#include <cerrno>
#include <cstdlib>
#include <fstream>
#include <map>
#include <random>
#include <sstream>

#include "gravcal/estimation/static_alignment.h"
#include "io/csv_table.h"
#include "util/units.h"

namespace gravcal {
namespace {

using internal::kRadToDeg;
// Smallest standard deviation written for a simulated fixture, degrees.

std::string Trim(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  const size_t e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

// A finite number filling the whole field.
bool ParseNumber(const std::string& text, double* value) {
  if (text.empty()) return false;
  char* end = nullptr;
  errno = 0;
  *value = std::strtod(text.c_str(), &end);
  return errno == 0 && end == text.c_str() + text.size() && std::isfinite(*value);
}

}  // namespace

bool ReadFixtureAttitudes(const std::string& path, std::vector<FixtureAttitude>* rows,
                          std::string* error) {
  std::ifstream in(path);
  if (!in) {
    *error = path + ": cannot open the attitudes file";
    return false;
  }
  rows->clear();
  std::map<std::string, int> column;
  std::string line;
  int line_number = 0;
  auto fail = [&](const std::string& what) {
    *error = path + ":" + std::to_string(line_number) + ": " + what;
    return false;
  };
  std::map<int, int> position_line;
  while (std::getline(in, line)) {
    ++line_number;
    const std::string trimmed = Trim(line);
    if (trimmed.empty() || trimmed[0] == '#') continue;
    std::vector<std::string> fields;
    {
      std::vector<CsvCell> cells;
      size_t column = 0;
      std::string what;
      if (!internal::SplitCsvLine(trimmed, &cells, &column, &what)) return fail(what);
      for (CsvCell& cell : cells) fields.push_back(std::move(cell.text));
    }
    if (column.empty()) {
      for (size_t i = 0; i < fields.size(); ++i) {
        if (column.count(fields[i])) return fail("column '" + fields[i] + "' appears twice");
        column[fields[i]] = static_cast<int>(i);
      }
      for (const char* required : {"roll_deg", "pitch_deg", "roll_std_deg", "pitch_std_deg"}) {
        if (!column.count(required)) {
          return fail(std::string("header has no column '") + required +
                      "' (needs position or t_begin,t_end; roll_deg, pitch_deg, roll_std_deg, "
                      "pitch_std_deg; optional heading_deg, heading_std_deg)");
        }
      }
      const bool by_time = column.count("t_begin") && column.count("t_end");
      if (!by_time && !column.count("position")) {
        return fail("header needs a 'position' column or 't_begin' and 't_end'");
      }
      continue;
    }
    if (fields.size() != column.size()) {
      std::ostringstream s;
      s << "has " << fields.size() << " fields, the header " << column.size();
      return fail(s.str());
    }
    FixtureAttitude row;
    row.line = line_number;
    // Reads column `name` into *v, checking [lo, hi].
    auto number = [&](const char* name, double lo, double hi, double* v) {
      const std::string& text = fields[column.at(name)];
      if (!ParseNumber(text, v)) {
        return fail(std::string(name) + " = '" + text + "' is not a finite number");
      }
      if (*v < lo || *v > hi) {
        std::ostringstream s;
        s << name << " = " << *v << " is out of range (" << lo << ".." << hi << ")";
        return fail(s.str());
      }
      return true;
    };
    if (!number("roll_deg", -180.0, 180.0, &row.roll_deg) ||
        !number("pitch_deg", -90.0, 90.0, &row.pitch_deg) ||
        !number("roll_std_deg", 1e-9, 90.0, &row.roll_std_deg) ||
        !number("pitch_std_deg", 1e-9, 90.0, &row.pitch_std_deg)) {
      return false;
    }
    if (column.count("heading_deg") && !fields[column.at("heading_deg")].empty() &&
        !number("heading_deg", -360.0, 360.0, &row.heading_deg)) {
      return false;
    }
    if (column.count("heading_std_deg") && !fields[column.at("heading_std_deg")].empty() &&
        !number("heading_std_deg", 1e-9, 360.0, &row.heading_std_deg)) {
      return false;
    }
    if (column.count("t_begin") && column.count("t_end")) {
      if (!number("t_begin", -1e12, 1e12, &row.t_begin) ||
          !number("t_end", -1e12, 1e12, &row.t_end)) {
        return false;
      }
      if (!(row.t_end > row.t_begin)) return fail("t_end must be after t_begin");
    } else {
      double p = 0.0;
      if (!number("position", 0.0, 1e6, &p)) return false;
      if (p != std::floor(p)) return fail("position must be a whole number");
      row.position = static_cast<int>(p);
      if (position_line.count(row.position)) {
        return fail("position " + std::to_string(row.position) + " already given on line " +
                    std::to_string(position_line[row.position]));
      }
      position_line[row.position] = line_number;
    }
    rows->push_back(row);
  }
  if (column.empty()) {
    *error = path + ": no header row (and no attitudes)";
    return false;
  }
  if (rows->empty()) {
    *error = path + ":" + std::to_string(line_number) + ": no attitude rows after the header";
    return false;
  }
  return true;
}

bool MatchFixtureAttitudes(const std::vector<FixtureAttitude>& rows,
                           const std::vector<StaticInterval>& intervals, const std::string& path,
                           std::vector<int>* row_of_position, std::string* error) {
  const int n = static_cast<int>(intervals.size());
  row_of_position->assign(n, -1);
  for (size_t r = 0; r < rows.size(); ++r) {
    const FixtureAttitude& row = rows[r];
    std::vector<int> matched;
    for (int k = 0; k < n; ++k) {
      const double mid = 0.5 * (intervals[k].t_begin + intervals[k].t_end);
      const bool hit =
          row.position >= 0 ? row.position == k : (mid >= row.t_begin && mid <= row.t_end);
      if (hit) matched.push_back(k);
    }
    std::ostringstream s;
    s << path << ":" << row.line << ": ";
    if (matched.empty()) {
      if (row.position >= 0) {
        s << "position " << row.position << " does not exist (" << n
          << " static positions detected, 0.." << n - 1 << ")";
      } else {
        s << "no detected static position lies in t " << row.t_begin << ".." << row.t_end << " s";
      }
      *error = s.str();
      return false;
    }
    if (matched.size() > 1) {
      s << "the window t " << row.t_begin << ".." << row.t_end << " s holds static positions "
        << matched[0] << " and " << matched[1] << "; give one row per position";
      *error = s.str();
      return false;
    }
    const int k = matched[0];
    if ((*row_of_position)[k] >= 0) {
      s << "static position " << k << " already has an attitude (line "
        << rows[(*row_of_position)[k]].line << ")";
      *error = s.str();
      return false;
    }
    (*row_of_position)[k] = static_cast<int>(r);
  }
  for (int k = 0; k < n; ++k) {
    if ((*row_of_position)[k] < 0) {
      std::ostringstream s;
      s << path << ": no attitude for static position " << k << " (t " << intervals[k].t_begin
        << "-" << intervals[k].t_end << " s); every detected position needs one";
      *error = s.str();
      return false;
    }
  }
  return true;
}

std::string FixtureAttitudesToCsv(const std::vector<FixtureAttitude>& rows) {
  const bool by_time = !rows.empty() && std::isfinite(rows[0].t_begin);
  std::ostringstream s;
  s.precision(10);
  s << "# gravcal fixture attitudes: one row per static position, degrees\n";
  s << (by_time ? "t_begin,t_end" : "position")
    << ",roll_deg,pitch_deg,heading_deg,roll_std_deg,pitch_std_deg,heading_std_deg\n";
  for (const FixtureAttitude& r : rows) {
    if (by_time) {
      s << r.t_begin << "," << r.t_end;
    } else {
      s << r.position;
    }
    s << "," << r.roll_deg << "," << r.pitch_deg << ",";
    if (std::isfinite(r.heading_deg)) s << r.heading_deg;
    s << "," << r.roll_std_deg << "," << r.pitch_std_deg << ",";
    if (std::isfinite(r.heading_std_deg)) s << r.heading_std_deg;
    s << "\n";
  }
  return s.str();
}

}  // namespace gravcal
