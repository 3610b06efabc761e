#include "gravcal/workflows/fleet_summary.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <set>

#include "io/csv_table.h"
#include "io/json_helpers.h"
#include "util/content_hash.h"
#include "util/numbers.h"
#include "util/statistics.h"

namespace gravcal {

using internal::ContentHash;
using internal::Median;

namespace {

using Json = nlohmann::ordered_json;

constexpr double kMadToStd = 1.4826;
const char kAxes[] = "xyz";

// Numbers in documented order, before any gyroscope extras.
const std::vector<std::string>& LeadingNumberColumns() {
  static const std::vector<std::string> columns = [] {
    std::vector<std::string> c = {"gravity", "positions", "residual_rms", "residual_max",
                                  "chi2_dof"};
    for (const char* sensor : {"accel", "gyro"}) {
      for (int i = 0; i < 3; ++i) {
        const std::string name = std::string(sensor) + "_bias_" + kAxes[i];
        c.push_back(name);
        c.push_back(name + "_std");
      }
      for (int r = 0; r < 3; ++r) {
        for (int k = 0; k < 3; ++k) {
          const std::string name = std::string(sensor) + "_m_" + kAxes[r] + kAxes[k];
          c.push_back(name);
          c.push_back(name + "_std");
        }
      }
    }
    return c;
  }();
  return columns;
}

const std::vector<std::string>& TimeColumns() {
  static const std::vector<std::string> columns = {"read_s", "detect_s", "solve_s", "total_s"};
  return columns;
}

const char* const kTextColumns[] = {"index", "unit", "status", "message"};

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// A parameter the fleet statistics look at.
bool IsParameterColumn(const std::string& name) {
  return (name.rfind("accel_", 0) == 0 || name.rfind("gyro_", 0) == 0) && !EndsWith(name, "_std");
}

// A cell of the fleet CSV: empty for a value that is not finite.
std::string CellText(double v) { return std::isfinite(v) ? internal::ExactNumber(v) : ""; }

std::string Short(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.6g", v);
  return buffer;
}

double ValueOf(const SummaryRow& row, const std::string& column) {
  const auto it = row.values.find(column);
  return it == row.values.end() ? NAN : it->second;
}

Json JsonNumber(double v) { return internal::JsonNumber<Json>(v); }

}  // namespace

bool FleetOptions::IsValid(std::string* error) const {
  if (!(outlier_sigmas > 0.0) || !std::isfinite(outlier_sigmas)) {
    *error = "outlier_sigmas: must be a positive number, is " + Short(outlier_sigmas);
    return false;
  }
  if (min_units < 2) {
    *error = "min_units: must be >= 2, is " + std::to_string(min_units);
    return false;
  }
  return true;
}

SummaryRow MakeSummaryRow(size_t index, const BatchResult& result) {
  SummaryRow row;
  row.index = index;
  row.unit = result.unit;
  row.status = result.status;
  row.message = result.message;
  auto& v = row.values;
  const BatchTimings& t = result.timings;
  v["read_s"] = t.read_seconds;
  v["detect_s"] = t.detect_seconds;
  v["solve_s"] = t.solve_seconds;
  v["total_s"] = t.total_seconds;
  const Calibration& c = result.calibration;
  if (!c.positions.empty()) v["positions"] = static_cast<double>(c.positions.size());
  if (result.status != BatchStatus::kOk) return row;
  v["gravity"] = c.gravity;
  v["residual_rms"] = c.residual_refined.rms;
  v["residual_max"] = c.residual_refined.max;
  v["chi2_dof"] = c.refinement.dof > 0 ? c.refinement.chi2 / c.refinement.dof : NAN;
  auto put = [&v](const std::string& name, double value, double std) {
    v[name] = value;
    v[name + "_std"] = std;
  };
  const Eigen::Matrix3d m = c.accel.model.matrix();
  for (int i = 0; i < 3; ++i) {
    put(std::string("accel_bias_") + kAxes[i], c.accel.model.bias(i), c.accel.bias_std(i));
  }
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 3; ++k) {
      put(std::string("accel_m_") + kAxes[r] + kAxes[k], m(r, k), c.accel.matrix_std(r, k));
    }
  }
  if (c.gyro.estimated) {
    for (int i = 0; i < 3; ++i) {
      put(std::string("gyro_bias_") + kAxes[i], c.gyro.model.bias(i), c.gyro.bias_std(i));
    }
    for (int r = 0; r < 3; ++r) {
      for (int k = 0; k < 3; ++k) {
        put(std::string("gyro_m_") + kAxes[r] + kAxes[k], c.gyro.model.matrix(r, k),
            c.gyro.matrix_std(r, k));
      }
    }
    for (size_t i = 0; i < c.gyro.extra_names.size(); ++i) {
      put("gyro_" + c.gyro.extra_names[i], c.gyro.extra_values[i],
          i < c.gyro.extra_std.size() ? c.gyro.extra_std[i] : NAN);
    }
  }
  return row;
}

std::vector<std::string> SummaryColumns(const std::vector<SummaryRow>& rows) {
  std::set<std::string> present;
  for (const SummaryRow& row : rows) {
    for (const auto& kv : row.values) present.insert(kv.first);
  }
  std::vector<std::string> columns(std::begin(kTextColumns), std::end(kTextColumns));
  std::set<std::string> known;
  for (const std::string& c : LeadingNumberColumns()) {
    known.insert(c);
    if (present.count(c)) columns.push_back(c);
  }
  known.insert(TimeColumns().begin(), TimeColumns().end());
  for (const std::string& c : present) {
    if (!known.count(c)) columns.push_back(c);
  }
  for (const std::string& c : TimeColumns()) {
    if (present.count(c)) columns.push_back(c);
  }
  return columns;
}

std::string SummaryToCsv(const std::vector<SummaryRow>& rows) {
  const std::vector<std::string> columns = SummaryColumns(rows);
  std::string out;
  for (size_t i = 0; i < columns.size(); ++i) out += (i ? "," : "") + columns[i];
  out += '\n';
  const size_t text_columns = std::size(kTextColumns);
  for (const SummaryRow& row : rows) {
    out += std::to_string(row.index) + "," + CsvField(row.unit) + "," + ToString(row.status) + "," +
           CsvField(row.message);
    for (size_t i = text_columns; i < columns.size(); ++i) {
      out += "," + CellText(ValueOf(row, columns[i]));
    }
    out += '\n';
  }
  return out;
}

bool ParseSummaryCsv(std::string_view text, const std::string& name, std::vector<SummaryRow>* rows,
                     std::string* error) {
  std::vector<CsvRecord> records;
  if (!ParseCsvRecords(text, name, &records, error)) return false;
  if (records.empty()) {
    *error = name + ": no header row";
    return false;
  }
  const CsvRecord& header = records[0];
  const size_t text_columns = std::size(kTextColumns);
  for (size_t i = 0; i < text_columns; ++i) {
    if (header.cells.size() <= i || header.cells[i].text != kTextColumns[i]) {
      *error = CsvWhere(name, header.line, i < header.cells.size() ? header.cells[i].column : 1) +
               "the header must start with index,unit,status,message";
      return false;
    }
  }
  std::vector<SummaryRow> out;
  for (size_t r = 1; r < records.size(); ++r) {
    const CsvRecord& record = records[r];
    if (record.cells.size() != header.cells.size()) {
      *error = CsvWhere(name, record.line, 1) + "has " + std::to_string(record.cells.size()) +
               " fields, the header " + std::to_string(header.cells.size());
      return false;
    }
    SummaryRow row;
    const std::string& index = record.cells[0].text;
    char* end = nullptr;
    const unsigned long long parsed_index = std::strtoull(index.c_str(), &end, 10);
    if (index.empty() || *end != '\0' || index[0] == '-') {
      *error = CsvWhere(name, record.line, record.cells[0].column) + "index '" + index +
               "' is not a non-negative integer";
      return false;
    }
    row.index = static_cast<size_t>(parsed_index);
    row.unit = record.cells[1].text;
    if (!FromString(record.cells[2].text, &row.status)) {
      *error = CsvWhere(name, record.line, record.cells[2].column) + "status '" +
               record.cells[2].text + "' is not ok, failed or not_converged";
      return false;
    }
    row.message = record.cells[3].text;
    for (size_t i = text_columns; i < record.cells.size(); ++i) {
      const CsvCell& cell = record.cells[i];
      if (cell.text.empty()) {
        // Kept as NaN, so the parsed rows have the same columns.
        row.values[header.cells[i].text] = NAN;
        continue;
      }
      double value = 0.0;
      if (!ParseCsvNumber(cell.text, &value)) {
        *error = CsvWhere(name, record.line, cell.column) + "column '" + header.cells[i].text +
                 "': '" + cell.text + "' is not a number";
        return false;
      }
      row.values[header.cells[i].text] = value;
    }
    out.push_back(std::move(row));
  }
  *rows = std::move(out);
  return true;
}

std::string FleetHash(const std::vector<std::string>& unit_ids) {
  ContentHash hash;
  for (const std::string& id : unit_ids) hash.Add(id);
  return hash.Hex();
}

std::string ConfigHash(const Config& base) {
  ContentHash hash;
  hash.Add(GravcalVersion());
  hash.Add(ConfigText(base));
  return hash.Hex();
}

bool ComputeFleetStatistics(const std::vector<SummaryRow>& rows, const FleetInfo& info,
                            const FleetOptions& options, FleetStatistics* statistics,
                            std::string* error) {
  if (!options.IsValid(error)) return false;
  FleetStatistics s;
  s.info = info;
  s.options = options;
  s.units = rows.size();
  std::vector<const SummaryRow*> ok;
  for (const SummaryRow& row : rows) {
    if (row.status == BatchStatus::kOk) {
      ok.push_back(&row);
    } else {
      (row.status == BatchStatus::kFailed ? s.failed : s.not_converged)++;
      s.failures.push_back(row);
    }
  }
  s.ok = ok.size();

  std::vector<std::string> columns = {"residual_rms"};
  for (const std::string& c : SummaryColumns(rows)) {
    if (IsParameterColumn(c)) columns.push_back(c);
  }
  for (const std::string& column : columns) {
    std::vector<double> values;
    for (const SummaryRow* row : ok) {
      const double v = ValueOf(*row, column);
      if (std::isfinite(v)) values.push_back(v);
    }
    if (values.empty()) continue;
    ParameterStatistics p;
    p.name = column;
    p.units = values.size();
    p.median = Median(values);
    std::vector<double> deviations;
    for (double v : values) deviations.push_back(std::abs(v - p.median));
    p.robust_std = kMadToStd * Median(deviations);
    p.min = *std::min_element(values.begin(), values.end());
    p.max = *std::max_element(values.begin(), values.end());
    s.parameters.push_back(p);
  }

  if (s.ok < static_cast<size_t>(options.min_units)) {
    s.outlier_check = "skipped: " + std::to_string(s.ok) + " calibrated units, needs " +
                      std::to_string(options.min_units);
  } else {
    s.outlier_check = "done";
    const double k = options.outlier_sigmas;
    for (const SummaryRow* row : ok) {
      FleetOutlier outlier;
      outlier.unit = row->unit;
      outlier.index = row->index;
      for (const ParameterStatistics& p : s.parameters) {
        const double v = ValueOf(*row, p.name);
        if (!std::isfinite(v) || !(p.robust_std > 0.0)) continue;
        const double z = (v - p.median) / p.robust_std;
        // A residual only counts when it is worse than the fleet's.
        const bool out = p.name == "residual_rms" ? z > k : std::abs(z) > k;
        if (!out) continue;
        outlier.reasons.push_back(p.name + " = " + Short(v) + " is " + Short(std::abs(z)) +
                                  " robust std " + (z > 0 ? "above" : "below") +
                                  " the fleet median " + Short(p.median) + " (robust std " +
                                  Short(p.robust_std) + ")");
      }
      if (!outlier.reasons.empty()) s.outliers.push_back(outlier);
    }
  }
  *statistics = std::move(s);
  return true;
}

std::string FleetStatisticsToJson(const FleetStatistics& s) {
  Json out;
  out["gravcal_version"] = GravcalVersion();
  out["fleet"] = s.info.fleet;
  out["config"] = s.info.config;
  out["units_in_fleet"] = s.info.units_in_fleet;
  out["shard"] = std::to_string(s.info.shard_index) + "/" + std::to_string(s.info.shard_count);
  out["units"] = s.units;
  out["ok"] = s.ok;
  out["failed"] = s.failed;
  out["not_converged"] = s.not_converged;
  out["outlier_sigmas"] = s.options.outlier_sigmas;
  out["outlier_min_units"] = s.options.min_units;
  out["outlier_check"] = s.outlier_check;
  Json parameters = Json::object();
  for (const ParameterStatistics& p : s.parameters) {
    parameters[p.name] = {{"units", p.units},
                          {"median", JsonNumber(p.median)},
                          {"robust_std", JsonNumber(p.robust_std)},
                          {"min", JsonNumber(p.min)},
                          {"max", JsonNumber(p.max)}};
  }
  out["parameters"] = parameters;
  Json outliers = Json::array();
  for (const FleetOutlier& o : s.outliers) {
    outliers.push_back({{"unit", o.unit}, {"index", o.index}, {"reasons", o.reasons}});
  }
  out["outliers"] = outliers;
  Json failures = Json::array();
  for (const SummaryRow& f : s.failures) {
    failures.push_back({{"unit", f.unit},
                        {"index", f.index},
                        {"status", ToString(f.status)},
                        {"message", f.message}});
  }
  out["failures"] = failures;
  return out.dump(2) + "\n";
}

bool ParseFleetInfo(std::string_view json_text, const std::string& name, FleetInfo* info,
                    std::string* error) {
  Json j;
  try {
    j = Json::parse(json_text);
  } catch (const std::exception& e) {
    *error = name + ": not valid JSON: " + e.what();
    return false;
  }
  FleetInfo out;
  std::string key;
  try {
    key = "fleet";
    out.fleet = j.at(key).get<std::string>();
    key = "config";
    out.config = j.at(key).get<std::string>();
    key = "units_in_fleet";
    out.units_in_fleet = j.at(key).get<size_t>();
    key = "shard";
    const std::string shard = j.at(key).get<std::string>();
    if (std::sscanf(shard.c_str(), "%d/%d", &out.shard_index, &out.shard_count) != 2 ||
        out.shard_index < 1 || out.shard_index > out.shard_count) {
      throw std::runtime_error("'" + shard + "' is not K/N with 1 <= K <= N");
    }
  } catch (const std::exception& e) {
    *error = name + ": key '" + key + "': " + e.what();
    return false;
  }
  *info = out;
  return true;
}

}  // namespace gravcal
