#include "gravcal/workflows/calibration_store.h"

#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "gravcal/io/calibration_uncertainty_io.h"
#include "gravcal/io/files.h"
#include "io/json_helpers.h"
#include "util/statistics.h"

namespace gravcal {

namespace {

using json = nlohmann::json;

constexpr double kSecondsPerDay = 86400.0;

std::string IndexPath(const std::string& store) { return store + "/index.json"; }

// "2026-11-27T16:45:00Z" -> "20261127T164500Z".
std::string FileStem(const std::string& date) {
  std::string out;
  for (char c : date) {
    if (c != '-' && c != ':') out += c;
  }
  return out;
}

bool MakeFolder(const std::string& path, std::string* error) {
  struct stat st;
  if (stat(path.c_str(), &st) == 0) {
    if (S_ISDIR(st.st_mode)) return true;
    *error = path + ": exists and is not a folder";
    return false;
  }
  if (mkdir(path.c_str(), 0755) != 0) {
    *error = path + ": cannot create the folder";
    return false;
  }
  return true;
}

std::vector<StoreEntry> UnitEntries(const std::vector<StoreEntry>& all, const std::string& unit) {
  std::vector<StoreEntry> out;
  for (const StoreEntry& e : all) {
    if (e.unit == unit) out.push_back(e);
  }
  std::sort(out.begin(), out.end(),
            [](const StoreEntry& a, const StoreEntry& b) { return a.date < b.date; });
  return out;
}

}  // namespace

bool ParseUtcDate(const std::string& date, std::time_t* seconds) {
  std::tm tm = {};
  int y, mo, d, h, mi, s;
  char z = 0;
  if (date.size() != 20 ||
      std::sscanf(date.c_str(), "%4d-%2d-%2dT%2d:%2d:%2d%c", &y, &mo, &d, &h, &mi, &s, &z) != 7 ||
      z != 'Z' || mo < 1 || mo > 12 || d < 1 || d > 31 || h > 23 || mi > 59 || s > 60) {
    return false;
  }
  tm.tm_year = y - 1900;
  tm.tm_mon = mo - 1;
  tm.tm_mday = d;
  tm.tm_hour = h;
  tm.tm_min = mi;
  tm.tm_sec = s;
  *seconds = timegm(&tm);
  return true;
}

std::string FormatUtcDate(std::time_t seconds) {
  std::tm tm;
  gmtime_r(&seconds, &tm);
  char buffer[32];
  std::strftime(buffer, sizeof(buffer), "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buffer;
}

bool ReadStoreIndex(const std::string& store, std::vector<StoreEntry>* entries,
                    std::string* error) {
  entries->clear();
  struct stat st;
  if (stat(IndexPath(store).c_str(), &st) != 0) return true;
  std::string text;
  if (!ReadFileBytes(IndexPath(store), &text, error)) return false;
  const json j = json::parse(text, nullptr, false);
  if (j.is_discarded() || !j.is_object() || !j.contains("calibrations") ||
      !j["calibrations"].is_array()) {
    *error = IndexPath(store) + ": key 'calibrations': must be an array";
    return false;
  }
  for (const json& e : j["calibrations"]) {
    StoreEntry s;
    std::time_t t;
    if (!e.is_object() || !e.contains("unit") || !e["unit"].is_string() || !e.contains("date") ||
        !e["date"].is_string() || !ParseUtcDate(e["date"].get<std::string>(), &t) ||
        !e.contains("file") || !e["file"].is_string()) {
      *error = IndexPath(store) + ": key 'calibrations[" + std::to_string(entries->size()) +
               "]': needs unit, date (UTC, 2026-11-27T16:45:00Z) and file";
      return false;
    }
    s.unit = e["unit"].get<std::string>();
    s.date = e["date"].get<std::string>();
    s.file = e["file"].get<std::string>();
    if (e.contains("method") && e["method"].is_string()) s.method = e["method"].get<std::string>();
    if (e.contains("log_hash") && e["log_hash"].is_string()) {
      s.log_hash = e["log_hash"].get<std::string>();
    }
    entries->push_back(s);
  }
  return true;
}

bool FileCalibration(const std::string& store, const std::string& unit, const std::string& date,
                     const std::string& calibration_json, std::string* error) {
  std::time_t t;
  if (unit.empty() || unit == "." || unit == ".." || unit.find('/') != std::string::npos) {
    *error = "unit '" + unit + "': must be a plain name (no '/')";
    return false;
  }
  if (!ParseUtcDate(date, &t)) {
    *error = "date '" + date + "': must be UTC as 2026-11-27T16:45:00Z";
    return false;
  }
  const json cal = json::parse(calibration_json, nullptr, false);
  if (cal.is_discarded() || !cal.is_object()) {
    *error = "the calibration to file is not a JSON object";
    return false;
  }
  std::vector<StoreEntry> entries;
  if (!ReadStoreIndex(store, &entries, error) || !MakeFolder(store, error) ||
      !MakeFolder(store + "/" + unit, error)) {
    return false;
  }
  StoreEntry entry;
  entry.unit = unit;
  entry.date = date;
  // Two different calibrations filed within one second get their own files
  // (stem, stem-2, ...): a calibration filed is never replaced by another.
  // The same calibration filed again stays one entry.
  const std::string stem = unit + "/" + FileStem(date);
  entry.file = stem + ".json";
  for (int k = 2;; ++k) {
    const bool taken = std::any_of(entries.begin(), entries.end(),
                                   [&](const StoreEntry& e) { return e.file == entry.file; });
    std::string stored, ignored;
    if (!taken || (ReadFileBytes(store + "/" + entry.file, &stored, &ignored) &&
                   stored == calibration_json)) {
      break;
    }
    entry.file = stem + "-" + std::to_string(k) + ".json";
  }
  if (cal.contains("method") && cal["method"].is_string()) entry.method = cal["method"];
  if (cal.contains("provenance") && cal["provenance"].is_object() &&
      cal["provenance"].contains("log_hash") && cal["provenance"]["log_hash"].is_string()) {
    entry.log_hash = cal["provenance"]["log_hash"];
  }
  if (!WriteFileAtomically(store + "/" + entry.file, calibration_json, error)) return false;
  entries.erase(std::remove_if(entries.begin(), entries.end(),
                               [&](const StoreEntry& e) { return e.file == entry.file; }),
                entries.end());
  entries.push_back(entry);
  nlohmann::ordered_json index;
  index["calibrations"] = nlohmann::ordered_json::array();
  for (const StoreEntry& e : entries) {
    index["calibrations"].push_back({{"unit", e.unit},
                                     {"date", e.date},
                                     {"file", e.file},
                                     {"method", e.method},
                                     {"log_hash", e.log_hash}});
  }
  return WriteFileAtomically(IndexPath(store), index.dump(2) + "\n", error);
}

bool ClosestCalibration(const std::string& store, const std::string& unit, const std::string& date,
                        double max_age_days, StoreEntry* entry, std::string* warning,
                        std::string* error) {
  warning->clear();
  std::time_t at;
  if (!ParseUtcDate(date, &at)) {
    *error = "date '" + date + "': must be UTC as 2026-11-27T16:45:00Z";
    return false;
  }
  std::vector<StoreEntry> all;
  if (!ReadStoreIndex(store, &all, error)) return false;
  const std::vector<StoreEntry> mine = UnitEntries(all, unit);
  if (mine.empty()) {
    *error = store + ": no calibration of unit '" + unit + "'";
    return false;
  }
  double best = INFINITY;
  for (const StoreEntry& e : mine) {
    std::time_t t;
    ParseUtcDate(e.date, &t);
    const double gap = std::fabs(std::difftime(at, t));
    if (gap < best) {
      best = gap;
      *entry = e;
    }
  }
  std::time_t t;
  ParseUtcDate(entry->date, &t);
  const double age_days = std::difftime(at, t) / kSecondsPerDay;
  if (max_age_days > 0.0 && age_days > max_age_days) {
    char buffer[256];
    std::snprintf(buffer, sizeof(buffer),
                  "the closest calibration of '%s' (%s) is %.1f days older than %s, beyond "
                  "%.1f days: recalibrate",
                  unit.c_str(), entry->date.c_str(), age_days, date.c_str(), max_age_days);
    *warning = buffer;
  }
  return true;
}

bool ReadUnitHistory(const std::string& store, const std::string& unit, double level,
                     UnitHistory* history, std::string* error) {
  *history = UnitHistory();
  history->unit = unit;
  std::vector<StoreEntry> all;
  if (!ReadStoreIndex(store, &all, error)) return false;
  history->calibrations = UnitEntries(all, unit);
  if (history->calibrations.empty()) {
    *error = store + ": no calibration of unit '" + unit + "'";
    return false;
  }
  const size_t n = history->calibrations.size();
  std::vector<ParameterVector> params(n);
  std::vector<double> days(n);
  std::time_t t0;
  ParseUtcDate(history->calibrations[0].date, &t0);
  for (size_t k = 0; k < n; ++k) {
    Calibration c;
    if (!ReadCalibrationUncertainty(store + "/" + history->calibrations[k].file, &c, nullptr,
                                    error) ||
        !CalibrationParameters(c, ComparisonSpace::kModel, &params[k], error)) {
      *error = store + "/" + history->calibrations[k].file + ": " + *error;
      return false;
    }
    std::time_t t;
    ParseUtcDate(history->calibrations[k].date, &t);
    days[k] = std::difftime(t, t0) / kSecondsPerDay;
  }
  ComparisonOptions options;
  options.level = level;
  for (size_t k = 1; k < n; ++k) {
    ComparisonResult r;
    CompareParameters(params[k - 1], params[k], options, &r);
    history->steps.push_back(r);
  }
  // Every parameter of the first calibration that all of them have.
  int drifting = 0;
  for (size_t j = 0; j < params[0].names.size(); ++j) {
    ParameterHistory h;
    h.name = params[0].names[j];
    std::vector<double> t;
    for (size_t k = 0; k < n; ++k) {
      const auto it = std::find(params[k].names.begin(), params[k].names.end(), h.name);
      if (it == params[k].names.end()) continue;
      const size_t i = it - params[k].names.begin();
      h.values.push_back(params[k].values(i));
      h.stds.push_back(params[k].determined[i] ? std::sqrt(params[k].covariance(i, i)) : NAN);
      t.push_back(days[k]);
    }
    h.days = t;
    // Weighted mean, chi2 about it, and the weighted line.
    double sw = 0, swx = 0, swy = 0, swxx = 0, swxy = 0;
    int used = 0;
    for (size_t k = 0; k < h.values.size(); ++k) {
      if (!(h.stds[k] > 0.0)) continue;
      const double w = 1.0 / (h.stds[k] * h.stds[k]);
      sw += w;
      swx += w * t[k];
      swy += w * h.values[k];
      swxx += w * t[k] * t[k];
      swxy += w * t[k] * h.values[k];
      ++used;
    }
    if (used >= 2) {
      const double mean = swy / sw;
      h.mean = mean;
      h.chi2 = 0.0;
      for (size_t k = 0; k < h.values.size(); ++k) {
        if (h.stds[k] > 0.0) h.chi2 += std::pow((h.values[k] - mean) / h.stds[k], 2);
      }
      h.dof = used - 1;
      h.p_value = internal::ChiSquareUpperTail(h.chi2, h.dof);
      const double det = sw * swxx - swx * swx;
      if (det > 0.0) {
        h.slope_per_day = (sw * swxy - swx * swy) / det;
        h.slope_std = std::sqrt(sw / det);
        h.intercept = (swy - h.slope_per_day * swx) / sw;
      }
    }
    history->parameters.push_back(h);
  }
  // Bonferroni over the parameters tested: a unit that does not drift is
  // said to in at most a fraction `level` of its histories.
  int tested = 0;
  for (const ParameterHistory& h : history->parameters) tested += h.dof > 0 ? 1 : 0;
  for (ParameterHistory& h : history->parameters) {
    h.drifts = h.dof > 0 && h.p_value < level / tested;
    drifting += h.drifts ? 1 : 0;
  }
  history->message =
      std::to_string(n) + " calibration" + (n == 1 ? "" : "s") + " of '" + unit + "'; " +
      (drifting == 0 ? std::string("no parameter drifts beyond its sigmas")
                     : std::to_string(drifting) + " parameter(s) not constant within their sigmas");
  return true;
}

std::string UnitHistoryToJson(const UnitHistory& h) {
  using Json = nlohmann::ordered_json;
  using internal::JsonArray;
  using internal::JsonNumber;
  Json j;
  j["unit"] = h.unit;
  Json cals = Json::array();
  for (const StoreEntry& e : h.calibrations) {
    cals.push_back({{"date", e.date}, {"file", e.file}, {"method", e.method}});
  }
  j["calibrations"] = cals;
  Json params = Json::array();
  for (const ParameterHistory& p : h.parameters) {
    params.push_back({{"name", p.name},
                      {"values", JsonArray<Json>(p.values)},
                      {"std", JsonArray<Json>(p.stds)},
                      {"days", JsonArray<Json>(p.days)},
                      {"slope_per_day", JsonNumber<Json>(p.slope_per_day)},
                      {"slope_std", JsonNumber<Json>(p.slope_std)},
                      {"chi2", JsonNumber<Json>(p.chi2)},
                      {"dof", p.dof},
                      {"p_value", JsonNumber<Json>(p.p_value)},
                      {"drifts", p.drifts}});
  }
  j["parameters"] = params;
  Json steps = Json::array();
  for (const ComparisonResult& r : h.steps) {
    steps.push_back({{"consistent", r.consistent},
                     {"p_value", JsonNumber<Json>(r.p_value)},
                     {"changed", r.changed},
                     {"message", r.message}});
  }
  j["steps"] = steps;
  j["message"] = h.message;
  return j.dump(2) + "\n";
}

}  // namespace gravcal
