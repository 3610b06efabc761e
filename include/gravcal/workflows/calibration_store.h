// gravcal/workflows/calibration_store.h: a history of calibrations per unit
// (issue 36): a folder with one calibration JSON per unit and date,
// <unit>/<date>.json (date as YYYYMMDDTHHMMSSZ), and index.json listing
// them ({"calibrations": [{unit, date, file, method, log_hash}]}).
//
// The history of a unit: every parameter (compare's model names) over time
// with its sigma, a weighted straight-line trend with its slope and sigma,
// and a drift test: the chi-square of the values about their weighted mean
// on n - 1 degrees of freedom (p < level / m, Bonferroni over the m
// parameters tested: the parameter is not constant within its sigmas, and a
// unit that does not drift is said to in at most a fraction `level` of its
// histories), plus compare (estimation/calibration_comparison.h)
// between each calibration and the one before.
#ifndef GRAVCAL_WORKFLOWS_CALIBRATION_STORE_H_
#define GRAVCAL_WORKFLOWS_CALIBRATION_STORE_H_

#include <ctime>
#include <string>
#include <vector>

#include "gravcal/core/calibration.h"
#include "gravcal/estimation/calibration_comparison.h"

namespace gravcal {

struct StoreEntry {
  std::string unit;
  // ISO 8601 UTC, "2026-11-27T16:45:00Z".
  std::string date;
  // Relative to the store folder.
  std::string file;
  std::string method;
  std::string log_hash;
};

// "2026-11-27T16:45:00Z" <-> seconds since 1970 (UTC); false when malformed.
bool ParseUtcDate(const std::string& date, std::time_t* seconds);
std::string FormatUtcDate(std::time_t seconds);

// Files the calibration JSON text under `unit` and `date` and adds it to the
// index (both written atomically; the folders made when missing). A unit
// name must be a plain file name (no '/', not "." or ".."). Filing the same
// unit and date again replaces the entry.
bool FileCalibration(const std::string& store, const std::string& unit, const std::string& date,
                     const std::string& calibration_json, std::string* error);

// The index (empty for a store that does not exist yet).
bool ReadStoreIndex(const std::string& store, std::vector<StoreEntry>* entries, std::string* error);

// The unit's calibration closest in time to `date`; `warning` says when it
// is older than `max_age_days` (<= 0: no limit) at that date. False when the
// unit has none.
bool ClosestCalibration(const std::string& store, const std::string& unit, const std::string& date,
                        double max_age_days, StoreEntry* entry, std::string* warning,
                        std::string* error);

struct ParameterHistory {
  std::string name;
  std::vector<double> values, stds;
  // When each value was made: days since the unit's first calibration.
  std::vector<double> days;
  // The weighted mean, and the weighted line's value at day 0 (the line
  // is intercept + slope_per_day * day).
  double mean = NAN;
  double intercept = NAN;
  // Weighted least-squares line value = a + slope * (t - t0), per day.
  double slope_per_day = NAN;
  double slope_std = NAN;
  // Drift test: chi2 about the weighted mean on dof = n - 1.
  double chi2 = NAN;
  int dof = 0;
  double p_value = NAN;
  bool drifts = false;
};

struct UnitHistory {
  std::string unit;
  std::vector<StoreEntry> calibrations;
  std::vector<ParameterHistory> parameters;
  // compare of calibration k with k - 1 (k >= 1).
  std::vector<ComparisonResult> steps;
  std::string message;
};

// The unit's history at `level`. False when the unit has no calibration in
// the store or a stored file cannot be read.
bool ReadUnitHistory(const std::string& store, const std::string& unit, double level,
                     UnitHistory* history, std::string* error);

std::string UnitHistoryToJson(const UnitHistory& history);

// The history as a self-contained HTML page (gravcal history --report):
// each parameter against the date, each value with its 1-sigma bar (and a
// fainter 2-sigma one), the weighted mean and the weighted trend line, and
// the drift test's verdict.
std::string UnitHistoryToHtml(const UnitHistory& history);

}  // namespace gravcal

#endif  // GRAVCAL_WORKFLOWS_CALIBRATION_STORE_H_
