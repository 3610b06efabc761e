// gravcal batch and gravcal merge-summaries.
//
// Output folder of a batch:
//   <unit>.json              the calibration JSON, as `gravcal calibrate` writes it
//   batch_state/<unit>.json  the unit's content hash and summary row (resume)
//   summary.csv, summary.json
// Every file is written atomically. A unit is skipped when its state file
// has the unit's current content hash (and, if it calibrated, <unit>.json
// exists): its summary row is taken from the state file. Units whose input
// could not be read get no state file, so they are tried again. Temporary
// files a killed run left behind are removed when their process is gone.
#include <dirent.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <system_error>

#include "cli/commands.h"
#include "gravcal/io/calibration_io.h"
#include "gravcal/io/log_reader.h"
#include "gravcal/workflows/batch.h"
#include "gravcal/workflows/batch_manifest.h"
#include "gravcal/workflows/fleet_summary.h"
#include "gravcal/workflows/report.h"

namespace gravcal {
namespace cli {
namespace {

using Json = nlohmann::json;

const char kStateFolder[] = "batch_state";
// Failed units listed by name on stderr; summary.json lists all.
constexpr size_t kFailuresShown = 10;

// mkdir -p.
bool MakeFolders(const std::string& path, std::string* error) {
  for (size_t pos = 1; pos <= path.size(); ++pos) {
    if (pos != path.size() && path[pos] != '/') continue;
    const std::string prefix = path.substr(0, pos);
    if (mkdir(prefix.c_str(), 0755) != 0 && errno != EEXIST) {
      *error = prefix + ": cannot create the folder: " + std::generic_category().message(errno);
      return false;
    }
  }
  struct stat st;
  if (stat(path.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) {
    *error = path + ": is not a folder";
    return false;
  }
  return true;
}

// Removes the temporary files (<name>.tmp.<pid>) that a killed run left in
// `folder`, when their process is gone.
void RemoveStaleTemporaries(const std::string& folder) {
  DIR* dir = opendir(folder.c_str());
  if (dir == nullptr) return;
  while (const dirent* entry = readdir(dir)) {
    const std::string name = entry->d_name;
    const size_t tmp = name.rfind(".tmp.");
    if (tmp == std::string::npos) continue;
    const std::string pid = name.substr(tmp + 5);
    if (pid.empty() || pid.find_first_not_of("0123456789") != std::string::npos) continue;
    if (kill(static_cast<pid_t>(std::atol(pid.c_str())), 0) != 0 && errno == ESRCH) {
      unlink((folder + "/" + name).c_str());
    }
  }
  closedir(dir);
}

bool FileExists(const std::string& path) {
  struct stat st;
  return stat(path.c_str(), &st) == 0;
}

Json RowToJson(const SummaryRow& row) {
  Json values = Json::object();
  for (const auto& [name, value] : row.values) {
    values[name] = std::isfinite(value) ? Json(value) : Json(nullptr);
  }
  return {{"unit", row.unit},
          {"status", ToString(row.status)},
          {"message", row.message},
          {"values", values}};
}

// The state file's row, if it has `hash`.
bool ReadState(const std::string& path, const std::string& hash, size_t index, SummaryRow* row) {
  std::string text;
  std::string error;
  if (!ReadFileBytes(path, &text, &error)) return false;
  try {
    const Json j = Json::parse(text);
    if (j.at("content_hash").get<std::string>() != hash) return false;
    const Json& r = j.at("row");
    SummaryRow out;
    out.index = index;
    out.unit = r.at("unit").get<std::string>();
    if (!FromString(r.at("status").get<std::string>(), &out.status)) return false;
    out.message = r.at("message").get<std::string>();
    for (const auto& [name, value] : r.at("values").items()) {
      out.values[name] = value.is_null() ? NAN : value.get<double>();
    }
    *row = std::move(out);
    return true;
  } catch (const std::exception&) {
    return false;  // Unreadable state: calibrate the unit again.
  }
}

// Progress on stderr: a bar redrawn in place on a terminal, a plain line
// every few seconds otherwise.
class ProgressDisplay {
 public:
  ProgressDisplay() : terminal_(isatty(2) != 0) {}

  void Update(const BatchProgress& p) {
    const bool last = p.done == p.total;
    const double interval = terminal_ ? 0.1 : 5.0;
    if (!last && p.elapsed_seconds - shown_at_ < interval) return;
    shown_at_ = p.elapsed_seconds;
    const double rate = p.elapsed_seconds > 0 ? p.done / p.elapsed_seconds : 0.0;
    const double left = rate > 0 ? (p.total - p.done) / rate : 0.0;
    char status[160];
    std::snprintf(status, sizeof(status),
                  "%zu/%zu units, %zu failed, %zu skipped, %.0f units/s, %.0f s left", p.done,
                  p.total, p.failed, p.skipped, rate, left);
    if (terminal_) {
      constexpr int kWidth = 30;
      const int filled = p.total > 0 ? static_cast<int>(kWidth * p.done / p.total) : kWidth;
      std::fprintf(stderr, "\r[%s%s] %s\033[K%s", std::string(filled, '#').c_str(),
                   std::string(kWidth - filled, '.').c_str(), status, last ? "\n" : "");
    } else if (!last) {
      std::fprintf(stderr, "gravcal: batch: %s\n", status);
    }
    std::fflush(stderr);
  }

 private:
  const bool terminal_;
  double shown_at_ = 0.0;
};

bool WriteSummary(const std::string& folder, const std::vector<SummaryRow>& rows,
                  const FleetInfo& info, const FleetOptions& fleet_options,
                  FleetStatistics* statistics, std::string* error) {
  if (!ComputeFleetStatistics(rows, info, fleet_options, statistics, error)) return false;
  return WriteFileAtomically(folder + "/summary.csv", SummaryToCsv(rows), error) &&
         WriteFileAtomically(folder + "/summary.json", FleetStatisticsToJson(*statistics), error);
}

// On stderr, one line each: the first failed units and every outlier.
void ReportFleet(const FleetStatistics& s) {
  size_t shown = 0;
  for (const SummaryRow& f : s.failures) {
    if (shown++ == kFailuresShown) {
      std::fprintf(stderr, "gravcal: ... and %zu more failed units (summary.json lists them)\n",
                   s.failures.size() - kFailuresShown);
      break;
    }
    std::fprintf(stderr, "gravcal: unit %s %s: %s\n", f.unit.c_str(), ToString(f.status),
                 f.message.c_str());
  }
  for (const FleetOutlier& o : s.outliers) {
    std::fprintf(stderr, "gravcal: outlier %s: %s\n", o.unit.c_str(), o.reasons.front().c_str());
  }
}

int ExitCode(const FleetStatistics& s) {
  if (s.failed > 0) {
    return Fail(std::to_string(s.failed + s.not_converged) + " of " + std::to_string(s.units) +
                " units failed (" + std::to_string(s.not_converged) +
                " did not converge); summary.json lists them");
  }
  if (s.not_converged > 0) {
    return Fail(std::to_string(s.not_converged) + " of " + std::to_string(s.units) +
                    " units did not converge; summary.json lists them",
                2);
  }
  return 0;
}

}  // namespace

int RunBatch(const CommandArgs& args) {
  if (args.output_dir.empty()) return Fail("batch needs --output-dir <folder>");
  const bool by_topic = !args.topics.empty();
  if (by_topic && (args.topics != "all" || args.input.empty())) {
    return Fail("--topics takes 'all', with --input <bag or MCAP file>");
  }
  if (by_topic ? !args.manifest.empty() || !args.input_dir.empty()
               : args.manifest.empty() == args.input_dir.empty()) {
    return Fail(
        "batch needs either --manifest <units.csv>, --input-dir <folder> or --input "
        "<bag> --topics all");
  }
  std::string error;
  if (!args.config.IsValid(&error)) return Fail(error);
  FleetOptions fleet_options;
  fleet_options.outlier_sigmas = args.outlier_sigmas;
  fleet_options.min_units = args.outlier_min_units;
  if (!fleet_options.IsValid(&error)) return Fail(error);
  BatchOptions options;
  options.threads = args.threads;
  options.keep_calibrations = false;
  if (!options.IsValid(&error)) return Fail(error);
  Shard shard;
  if (!args.shard.empty() && !ParseShard(args.shard, &shard, &error)) return Fail(error);

  std::vector<BatchUnit> fleet;
  const bool listed = by_topic ? UnitsFromTopics(args.input, &fleet, &error)
                      : args.manifest.empty()
                          ? UnitsFromDirectory(args.input_dir, args.pattern, &fleet, &error)
                          : ReadBatchManifest(args.manifest, args.config, &fleet, &error);
  if (!listed) return Fail(error);
  FleetInfo info;
  {
    std::vector<std::string> ids;
    for (const BatchUnit& u : fleet) ids.push_back(u.id);
    info.fleet = FleetHash(ids);
  }
  info.config = ConfigHash(args.config);
  info.units_in_fleet = fleet.size();
  info.shard_index = shard.index;
  info.shard_count = shard.count;
  const std::vector<size_t> positions = ShardPositions(fleet.size(), shard);
  std::vector<BatchUnit> units;
  units.reserve(positions.size());
  for (size_t p : positions) units.push_back(std::move(fleet[p]));

  const std::string& out = args.output_dir;
  const std::string state_folder = out + "/" + kStateFolder;
  if (!MakeFolders(state_folder, &error)) return Fail(error);
  RemoveStaleTemporaries(out);
  RemoveStaleTemporaries(state_folder);

  std::vector<SummaryRow> rows(units.size());
  std::vector<char> have_row(units.size(), 0);
  options.skip = [&](size_t i, const BatchUnit& unit, const std::string& hash) {
    SummaryRow row;
    if (!ReadState(state_folder + "/" + unit.id + ".json", hash, positions[i], &row)) return false;
    if (row.status == BatchStatus::kOk && !FileExists(out + "/" + unit.id + ".json")) return false;
    rows[i] = std::move(row);
    have_row[i] = 1;
    return true;
  };
  options.on_result = [&](size_t i, const BatchResult& r) {
    if (r.skipped) return;
    const std::string result_path = out + "/" + r.unit + ".json";
    std::string why;
    if (r.status == BatchStatus::kOk) {
      Config config;
      if (!EffectiveConfig(units[i], args.config, &config, &why) ||
          !WriteCalibrationJson(r.calibration, config.output_covariance, result_path, &why)) {
        throw std::runtime_error(why);
      }
    } else if (unlink(result_path.c_str()) != 0 && errno != ENOENT) {
      throw std::runtime_error(result_path + ": cannot remove the stale result: " +
                               std::generic_category().message(errno));
    }
    SummaryRow row = MakeSummaryRow(positions[i], r);
    if (!r.content_hash.empty()) {
      const Json state = {{"unit", r.unit},
                          {"content_hash", r.content_hash},
                          {"gravcal_version", GravcalVersion()},
                          {"row", RowToJson(row)}};
      if (!WriteFileAtomically(state_folder + "/" + r.unit + ".json", state.dump(2) + "\n", &why)) {
        throw std::runtime_error(why);
      }
    }
    rows[i] = std::move(row);
    have_row[i] = 1;
  };
  ProgressDisplay display;
  options.progress = [&display](const BatchProgress& p) { display.Update(p); };

  const auto start = std::chrono::steady_clock::now();
  std::vector<BatchResult> results;
  if (!CalibrateBatch(units, args.config, options, &results, &error)) return Fail(error);
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  size_t skipped = 0;
  BatchTimings sum;
  for (size_t i = 0; i < units.size(); ++i) {
    // A unit whose result could not be stored has no row yet.
    if (!have_row[i]) rows[i] = MakeSummaryRow(positions[i], results[i]);
    if (results[i].skipped) {
      ++skipped;
      continue;
    }
    sum.read_seconds += results[i].timings.read_seconds;
    sum.detect_seconds += results[i].timings.detect_seconds;
    sum.solve_seconds += results[i].timings.solve_seconds;
  }
  FleetStatistics statistics;
  if (!WriteSummary(out, rows, info, fleet_options, &statistics, &error)) return Fail(error);
  ReportFleet(statistics);
  const size_t computed = units.size() - skipped;
  if (!args.report.empty()) {
    const BatchThroughput throughput = {elapsed,          computed,           skipped,
                                        sum.read_seconds, sum.detect_seconds, sum.solve_seconds};
    if (!WriteFileAtomically(args.report, FleetToHtml(statistics, rows, throughput), &error)) {
      return Fail(error);
    }
  }
  const double busy = sum.read_seconds + sum.detect_seconds + sum.solve_seconds;
  std::fprintf(
      stderr,
      "gravcal: batch: %zu units (shard %d/%d of a fleet of %zu): %zu ok, %zu failed, %zu not "
      "converged, %zu outliers; skipped %zu (stored results up to date); %.1f units/s "
      "computed; time in read %.0f %%, detect %.0f %%, solve %.0f %%; wrote %s/summary.csv "
      "and summary.json\n",
      units.size(), shard.index, shard.count, fleet.size(), statistics.ok, statistics.failed,
      statistics.not_converged, statistics.outliers.size(), skipped,
      elapsed > 0 ? computed / elapsed : 0.0, busy > 0 ? 100 * sum.read_seconds / busy : 0.0,
      busy > 0 ? 100 * sum.detect_seconds / busy : 0.0,
      busy > 0 ? 100 * sum.solve_seconds / busy : 0.0, out.c_str());
  return ExitCode(statistics);
}

int RunMergeSummaries(const CommandArgs& args) {
  if (args.output_dir.empty()) return Fail("merge-summaries needs --output-dir <folder>");
  if (args.positional.empty()) {
    return Fail("merge-summaries needs the folders of the shards' summaries");
  }
  FleetOptions fleet_options;
  fleet_options.outlier_sigmas = args.outlier_sigmas;
  fleet_options.min_units = args.outlier_min_units;
  std::string error;
  if (!fleet_options.IsValid(&error)) return Fail(error);

  FleetInfo merged;
  std::vector<std::string> shard_folder;
  std::vector<SummaryRow> rows;
  for (size_t d = 0; d < args.positional.size(); ++d) {
    const std::string& folder = args.positional[d];
    const std::string json_path = folder + "/summary.json";
    const std::string csv_path = folder + "/summary.csv";
    std::string text;
    FleetInfo info;
    if (!ReadFileBytes(json_path, &text, &error) ||
        !ParseFleetInfo(text, json_path, &info, &error)) {
      return Fail(error);
    }
    std::vector<SummaryRow> shard_rows;
    if (!ReadFileBytes(csv_path, &text, &error) ||
        !ParseSummaryCsv(text, csv_path, &shard_rows, &error)) {
      return Fail(error);
    }
    if (d == 0) {
      merged = info;
      shard_folder.assign(info.shard_count, "");
    } else if (info.fleet != merged.fleet || info.units_in_fleet != merged.units_in_fleet ||
               info.shard_count != merged.shard_count) {
      return Fail(json_path + ": not a shard of the same fleet as " + args.positional[0] +
                  " (the unit list or the shard count differs)");
    } else if (info.config != merged.config) {
      return Fail(json_path + ": computed with another config (or gravcal version) than " +
                  args.positional[0]);
    }
    std::string& seen = shard_folder[info.shard_index - 1];
    if (!seen.empty()) {
      return Fail(json_path + ": shard " + std::to_string(info.shard_index) + "/" +
                  std::to_string(info.shard_count) + " is also in " + seen);
    }
    seen = folder;
    rows.insert(rows.end(), shard_rows.begin(), shard_rows.end());
  }
  std::string missing;
  for (size_t k = 0; k < shard_folder.size(); ++k) {
    if (shard_folder[k].empty()) missing += (missing.empty() ? "" : ", ") + std::to_string(k + 1);
  }
  if (!missing.empty()) {
    return Fail("shards " + missing + " of " + std::to_string(merged.shard_count) +
                " are missing: merge-summaries needs every shard of the fleet");
  }
  std::stable_sort(rows.begin(), rows.end(),
                   [](const SummaryRow& a, const SummaryRow& b) { return a.index < b.index; });
  for (size_t i = 0; i < std::max(rows.size(), merged.units_in_fleet); ++i) {
    if (i >= rows.size() || rows[i].index != i) {
      return Fail("the shards' summaries hold " + std::to_string(rows.size()) +
                  " rows for a fleet of " + std::to_string(merged.units_in_fleet) +
                  " units: the row of unit index " + std::to_string(i) +
                  " is missing or appears twice");
    }
  }
  merged.shard_index = 1;
  merged.shard_count = 1;
  if (!MakeFolders(args.output_dir, &error)) return Fail(error);
  FleetStatistics statistics;
  if (!WriteSummary(args.output_dir, rows, merged, fleet_options, &statistics, &error)) {
    return Fail(error);
  }
  ReportFleet(statistics);
  std::fprintf(stderr,
               "gravcal: merged %zu shards, %zu units: %zu ok, %zu failed, %zu not converged, %zu "
               "outliers; wrote %s/summary.csv and summary.json\n",
               args.positional.size(), statistics.units, statistics.ok, statistics.failed,
               statistics.not_converged, statistics.outliers.size(), args.output_dir.c_str());
  return 0;
}

}  // namespace cli
}  // namespace gravcal
