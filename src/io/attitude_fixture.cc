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

// The header row: column name -> index; the four attitude columns and either
// position or t_begin and t_end are required.
bool ReadAttitudeHeader(const std::vector<std::string>& fields, std::map<std::string, int>* column,
                        std::string* what) {
  for (size_t i = 0; i < fields.size(); ++i) {
    if (column->count(fields[i])) {
      *what = "column '" + fields[i] + "' appears twice";
      return false;
    }
    (*column)[fields[i]] = static_cast<int>(i);
  }
  for (const char* required : {"roll_deg", "pitch_deg", "roll_std_deg", "pitch_std_deg"}) {
    if (!column->count(required)) {
      *what = std::string("header has no column '") + required +
              "' (needs position or t_begin,t_end; roll_deg, pitch_deg, roll_std_deg, "
              "pitch_std_deg; optional heading_deg, heading_std_deg)";
      return false;
    }
  }
  const bool by_time = column->count("t_begin") && column->count("t_end");
  if (!by_time && !column->count("position")) {
    *what = "header needs a 'position' column or 't_begin' and 't_end'";
    return false;
  }
  return true;
}

// One data row into *row (position rows: the position is checked against
// those already given, position_line).
bool ParseAttitudeRow(const std::vector<std::string>& fields,
                      const std::map<std::string, int>& column, int line_number,
                      std::map<int, int>* position_line, FixtureAttitude* row, std::string* what) {
  if (fields.size() != column.size()) {
    std::ostringstream s;
    s << "has " << fields.size() << " fields, the header " << column.size();
    *what = s.str();
    return false;
  }
  row->line = line_number;
  // Reads column `name` into *v, checking [lo, hi].
  auto number = [&](const char* name, double lo, double hi, double* v) {
    const std::string& text = fields[column.at(name)];
    if (!ParseCsvNumber(text, v) || !std::isfinite(*v)) {
      *what = std::string(name) + " = '" + text + "' is not a finite number";
      return false;
    }
    if (*v < lo || *v > hi) {
      std::ostringstream s;
      s << name << " = " << *v << " is out of range (" << lo << ".." << hi << ")";
      *what = s.str();
      return false;
    }
    return true;
  };
  // An optional column: absent or empty leaves the default.
  auto optional = [&](const char* name, double lo, double hi, double* v) {
    return !column.count(name) || fields[column.at(name)].empty() || number(name, lo, hi, v);
  };
  if (!number("roll_deg", -180.0, 180.0, &row->roll_deg) ||
      !number("pitch_deg", -90.0, 90.0, &row->pitch_deg) ||
      !number("roll_std_deg", 1e-9, 90.0, &row->roll_std_deg) ||
      !number("pitch_std_deg", 1e-9, 90.0, &row->pitch_std_deg) ||
      !optional("heading_deg", -360.0, 360.0, &row->heading_deg) ||
      !optional("heading_std_deg", 1e-9, 360.0, &row->heading_std_deg)) {
    return false;
  }
  if (column.count("t_begin") && column.count("t_end")) {
    if (!number("t_begin", -1e12, 1e12, &row->t_begin) ||
        !number("t_end", -1e12, 1e12, &row->t_end)) {
      return false;
    }
    if (!(row->t_end > row->t_begin)) {
      *what = "t_end must be after t_begin";
      return false;
    }
    return true;
  }
  double p = 0.0;
  if (!number("position", 0.0, 1e6, &p)) return false;
  if (p != std::floor(p)) {
    *what = "position must be a whole number";
    return false;
  }
  row->position = static_cast<int>(p);
  if (position_line->count(row->position)) {
    *what = "position " + std::to_string(row->position) + " already given on line " +
            std::to_string((*position_line)[row->position]);
    return false;
  }
  (*position_line)[row->position] = line_number;
  return true;
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
  std::map<int, int> position_line;
  std::string line;
  int line_number = 0;
  std::string what;
  while (std::getline(in, line)) {
    ++line_number;
    const std::string trimmed = Trim(line);
    if (trimmed.empty() || trimmed[0] == '#') continue;
    std::vector<CsvCell> cells;
    size_t cell_column = 0;
    std::vector<std::string> fields;
    bool ok = internal::SplitCsvLine(trimmed, &cells, &cell_column, &what);
    for (CsvCell& cell : cells) fields.push_back(std::move(cell.text));
    if (ok && column.empty()) {
      ok = ReadAttitudeHeader(fields, &column, &what);
    } else if (ok) {
      FixtureAttitude row;
      ok = ParseAttitudeRow(fields, column, line_number, &position_line, &row, &what);
      if (ok) rows->push_back(row);
    }
    if (!ok) {
      *error = path + ":" + std::to_string(line_number) + ": " + what;
      return false;
    }
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
