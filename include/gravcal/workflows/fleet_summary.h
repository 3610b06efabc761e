// gravcal/workflows/fleet_summary.h: the summary of a batch, one row per unit, and the
// fleet statistics computed from those rows.
//
// Summary CSV (`summary.csv`): columns `index` (the unit's 0-based position
// in the whole fleet, so shards can be merged back in order), `unit`,
// `status` (ok, failed, not_converged), `message`, then numbers: `gravity`,
// `positions`, `residual_rms` and `residual_max` (|a| - g over the positions
// after calibration, m/s^2), `chi2_dof`, every parameter with its standard
// deviation (`accel_bias_x`, `accel_bias_x_std`, ..., `accel_m_xx`, ...
// `accel_m_zz_std` for a = M (v - b); `gyro_bias_*`, `gyro_m_*` and
// `gyro_<extra>` when the method estimates the gyroscope), and the time spent
// (`read_s`, `detect_s`, `solve_s`, `total_s`). An empty cell is a number
// that does not exist (not estimated, not determined, or the unit failed).
// Numbers are written in the shortest form that reads back to the same
// double, so statistics computed from a parsed summary equal those computed
// from the rows in memory.
//
// Fleet statistics, over the units with status ok: for every parameter the
// median and the robust standard deviation 1.4826 * MAD (median absolute
// deviation; equals the standard deviation for normal data, and a few wild
// units hardly move it). A unit is an outlier when one of its parameters is
// more than outlier_sigmas robust standard deviations from the median, or
// its residual_rms more than outlier_sigmas above the median residual.
// Parameters whose robust spread is zero (fixed by the model, e.g. the lower
// triangle of M for scale_misalignment) flag nothing.
#ifndef GRAVCAL_WORKFLOWS_FLEET_SUMMARY_H_
#define GRAVCAL_WORKFLOWS_FLEET_SUMMARY_H_

#include <cstddef>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "gravcal/workflows/batch.h"

namespace gravcal {

struct FleetOptions {
  // Outlier threshold in robust standard deviations.
  double outlier_sigmas = 5.0;
  // With fewer calibrated units than this, median and spread are too
  // uncertain to flag anyone: no outlier check.
  int min_units = 5;

  bool IsValid(std::string* error) const;
};

struct SummaryRow {
  size_t index = 0;
  std::string unit;
  BatchStatus status = BatchStatus::kFailed;
  std::string message;
  // Column name -> value; NaN is an empty cell.
  std::map<std::string, double> values;
};

// The row of one calibrated (not skipped) unit.
SummaryRow MakeSummaryRow(size_t index, const BatchResult& result);

// The columns the rows use, in the documented order (gyroscope extras
// sorted by name, before the times).
std::vector<std::string> SummaryColumns(const std::vector<SummaryRow>& rows);

// summary.csv text: a header and one line per row, in the order given.
std::string SummaryToCsv(const std::vector<SummaryRow>& rows);

// Parses summary.csv text; errors "<name>:<line>:<column>: ...".
bool ParseSummaryCsv(std::string_view text, const std::string& name, std::vector<SummaryRow>* rows,
                     std::string* error);

// Which fleet and which part of it a summary covers.
struct FleetInfo {
  // Content hash of the whole fleet's unit ids in order.
  std::string fleet;
  // Content hash of the base configuration text and the gravcal version.
  std::string config;
  size_t units_in_fleet = 0;
  // This summary covers shard shard_index of shard_count (1/1 = all).
  int shard_index = 1;
  int shard_count = 1;
};

// The hashes of FleetInfo.
std::string FleetHash(const std::vector<std::string>& unit_ids);
std::string ConfigHash(const Config& base);

struct ParameterStatistics {
  std::string name;
  // Calibrated units with a value.
  size_t units = 0;
  double median = 0.0;
  // 1.4826 * median absolute deviation.
  double robust_std = 0.0;
  double min = 0.0;
  double max = 0.0;
};

struct FleetOutlier {
  std::string unit;
  size_t index = 0;
  // One line per parameter (or the residual) out of range, e.g.
  // "accel_bias_x = 612.3 is 11.2 robust std above the fleet median 41.0
  // (robust std 51.0)".
  std::vector<std::string> reasons;
};

struct FleetStatistics {
  FleetInfo info;
  FleetOptions options;
  size_t units = 0;
  size_t ok = 0;
  size_t failed = 0;
  size_t not_converged = 0;
  // Parameters and residuals, in column order.
  std::vector<ParameterStatistics> parameters;
  // "done", or why the outlier check was not made.
  std::string outlier_check;
  std::vector<FleetOutlier> outliers;
  // Failed and not-converged units with their messages, in row order.
  std::vector<SummaryRow> failures;
};

// Statistics over `rows` (any order; reported in row order).
bool ComputeFleetStatistics(const std::vector<SummaryRow>& rows, const FleetInfo& info,
                            const FleetOptions& options, FleetStatistics* statistics,
                            std::string* error);

// summary.json text. Holds nothing that changes from run to run (no times),
// so two runs over the same fleet give the same file.
std::string FleetStatisticsToJson(const FleetStatistics& statistics);

// Reads back the FleetInfo part of summary.json text (for merging shards).
bool ParseFleetInfo(std::string_view json_text, const std::string& name, FleetInfo* info,
                    std::string* error);

}  // namespace gravcal

#endif  // GRAVCAL_WORKFLOWS_FLEET_SUMMARY_H_
