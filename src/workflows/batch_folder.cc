// A batch written to a folder and resumed from it (batch_folder.h): the
// units of the shard, the state store, the run and its text.
#include "gravcal/workflows/batch_folder.h"

#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <functional>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <system_error>
#include <utility>

#include "gravcal/io/calibration_io.h"
#include "gravcal/io/files.h"
#include "gravcal/workflows/report.h"
#include "util/error.h"
#include "workflows/batch_folder_files.h"

namespace gravcal {

const char kBatchStateFolder[] = "batch_state";

namespace {

using Json = nlohmann::json;
using internal::FileExists;
using internal::MakeFolders;
using internal::SetError;
using internal::WriteSummaryFiles;

// Failed units named one per line in FullReport; summary.json lists all.
constexpr size_t kFailuresShown = 10;

// True when `path` holds a calibration JSON (a result of an earlier run,
// stale once its unit fails): a file of that name the batch did not write
// is never removed.
bool IsOwnResult(const std::string& path) {
  std::string text;
  std::string error;
  if (!ReadFileBytes(path, &text, &error)) return false;
  const Json j = Json::parse(text, nullptr, false);
  return j.is_object() && j.contains("accel") && j.contains("method") && j.contains("provenance");
}

// A unit's state file (the schema in batch_folder.h).
std::string StateFileText(const BatchResult& r, const SummaryRow& row) {
  Json values = Json::object();
  for (const auto& [name, value] : row.values) {
    values[name] = std::isfinite(value) ? Json(value) : Json(nullptr);
  }
  const Json state = {{"unit", r.unit},
                      {"content_hash", r.content_hash},
                      {"gravcal_version", GravcalVersion()},
                      {"row",
                       {{"unit", row.unit},
                        {"status", ToString(row.status)},
                        {"message", row.message},
                        {"values", values}}}};
  return state.dump(2) + "\n";
}

// The state file's row, if it has `hash`.
bool ReadStateFile(const std::string& path, const std::string& hash, size_t index,
                   SummaryRow* row) {
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

// The batch's files: the state of each unit (resume), its calibration JSON,
// and its summary row. A result that cannot be stored stops the batch.
class BatchStore {
 public:
  BatchStore(const BatchFolderUnits& units, const Config& base, const std::string& out,
             std::atomic<bool>* stop)
      : units_(units),
        base_(base),
        out_(out),
        state_folder_(out_ + "/" + kBatchStateFolder),
        stop_(stop),
        rows_(units.units.size()),
        have_row_(units.units.size(), 0) {}

  // Creates the folders and removes the temporaries a killed run left.
  bool Prepare(std::string* error) {
    if (!MakeFolders(state_folder_, error)) return false;
    RemoveStaleTemporaries(out_);
    RemoveStaleTemporaries(state_folder_);
    return true;
  }

  bool Skip(size_t i, const BatchUnit& unit, const std::string& hash) {
    SummaryRow row;
    if (!ReadStateFile(state_folder_ + "/" + unit.id + ".json", hash, units_.positions[i], &row)) {
      return false;
    }
    if (row.status == BatchStatus::kOk && !FileExists(out_ + "/" + unit.id + ".json")) {
      return false;
    }
    rows_[i] = std::move(row);
    have_row_[i] = 1;
    return true;
  }

  void Store(size_t i, const BatchResult& r) {
    if (r.skipped) return;
    std::string why;
    if (!WriteResult(i, r, &why)) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        if (write_error_.empty()) write_error_ = why;
      }
      stop_->store(true);
      throw std::runtime_error(why);
    }
  }

  // Every unit's row: from its state or this run's result.
  std::vector<SummaryRow> Rows(const std::vector<BatchResult>& results) {
    for (size_t i = 0; i < rows_.size(); ++i) {
      if (!have_row_[i]) rows_[i] = MakeSummaryRow(units_.positions[i], results[i]);
    }
    return rows_;
  }

  // The first result that could not be stored ("" when none).
  std::string write_error() {
    std::lock_guard<std::mutex> lock(mutex_);
    return write_error_;
  }

 private:
  bool WriteResult(size_t i, const BatchResult& r, std::string* why) {
    const std::string result_path = out_ + "/" + r.unit + ".json";
    if (r.status == BatchStatus::kOk) {
      Config config;
      if (!EffectiveConfig(units_.units[i], base_, &config, why) ||
          !WriteCalibrationJson(r.calibration, config.output_covariance, result_path, why)) {
        return false;
      }
    } else if (IsOwnResult(result_path) && unlink(result_path.c_str()) != 0 && errno != ENOENT) {
      *why = result_path +
             ": cannot remove the stale result: " + std::generic_category().message(errno);
      return false;
    }
    SummaryRow row = MakeSummaryRow(units_.positions[i], r);
    if (!r.content_hash.empty() &&
        !WriteFileAtomically(state_folder_ + "/" + r.unit + ".json", StateFileText(r, row), why)) {
      return false;
    }
    rows_[i] = std::move(row);
    have_row_[i] = 1;
    return true;
  }

  const BatchFolderUnits& units_;
  const Config& base_;
  const std::string out_;
  const std::string state_folder_;
  std::atomic<bool>* const stop_;
  std::vector<SummaryRow> rows_;
  std::vector<char> have_row_;
  std::mutex mutex_;
  std::string write_error_;
};

// Counts and timings of the run into *s.
void CountRun(BatchFolderSummary* s) {
  for (const BatchResult& r : s->results) {
    if (r.skipped) ++s->skipped;
    if (r.timed_out) ++s->timed_out;
    if (r.not_run) ++s->not_run;
    if (r.skipped || r.not_run) continue;
    s->busy.read_seconds += r.timings.read_seconds;
    s->busy.detect_seconds += r.timings.detect_seconds;
    s->busy.solve_seconds += r.timings.solve_seconds;
  }
  s->units = s->results.size();
  s->computed = s->units - s->skipped - s->not_run;
}

std::string StopReason(const BatchStop* stop, const std::string& write_error) {
  const int signal = stop != nullptr ? stop->signal.load() : 0;
  if (signal != 0) return std::string("stopped by ") + (signal == SIGINT ? "SIGINT" : "SIGTERM");
  if (!write_error.empty()) return "stopped: cannot store a result: " + write_error;
  if (stop != nullptr && stop->requested.load()) return "stopped";
  return "";
}

}  // namespace

bool BatchFolderOptions::IsValid(std::string* error) const {
  if (output_dir.empty()) return SetError(error, "batch needs an output folder");
  if (shard.count < 1 || shard.index < 1 || shard.index > shard.count) {
    return SetError(error, "shard: K/N needs 1 <= K <= N");
  }
  if (!fleet.IsValid(error)) return false;
  BatchOptions batch;
  batch.threads = threads;
  batch.unit_timeout_seconds = unit_timeout_seconds;
  batch.stop_grace_seconds = stop_grace_seconds;
  return batch.IsValid(error);
}

bool ListBatchFolderUnits(const BatchSource& source, const Config& base,
                          const BatchFolderOptions& options, BatchFolderUnits* out,
                          std::string* error) {
  std::vector<BatchUnit> fleet;
  std::vector<std::string> own;
  std::vector<std::string> hidden;
  if (!source.input_dir.empty() && !internal::OwnFilesInInput(source.input_dir, options.output_dir,
                                                              options.report, &own, error)) {
    return false;
  }
  const bool listed =
      !source.topics.empty() ? UnitsFromTopics(source.input, &fleet, error)
      : source.manifest.empty()
          ? UnitsFromDirectory(source.input_dir, source.pattern, &fleet, error, own, &hidden)
          : ReadBatchManifest(source.manifest, base, &fleet, error);
  if (!listed) return false;
  *out = ShardOfFleet(std::move(fleet), base, options.shard);
  out->hidden = std::move(hidden);
  return true;
}

BatchFolderUnits ShardOfFleet(std::vector<BatchUnit> fleet, const Config& base,
                              const Shard& shard) {
  BatchFolderUnits out;
  std::vector<std::string> ids;
  for (const BatchUnit& u : fleet) ids.push_back(u.id);
  out.info.fleet = FleetHash(ids);
  out.info.config = ConfigHash(base);
  out.info.units_in_fleet = fleet.size();
  out.info.shard_index = shard.index;
  out.info.shard_count = shard.count;
  out.positions = ShardPositions(fleet.size(), shard);
  for (size_t p : out.positions) out.units.push_back(std::move(fleet[p]));
  return out;
}

bool CalibrateBatchToFolder(const BatchFolderUnits& units, const Config& base,
                            const BatchFolderOptions& options, BatchFolderSummary* summary,
                            std::string* error) {
  if (!base.IsValid(error) || !options.IsValid(error) ||
      !internal::CheckUnitsAgainstOutputs(units.units, options.output_dir, options.report, error)) {
    return false;
  }
  *summary = BatchFolderSummary();
  summary->output_dir = options.output_dir;
  std::atomic<bool> own_stop{false};
  std::atomic<bool>* stop = options.stop != nullptr ? &options.stop->requested : &own_stop;
  BatchStore store(units, base, options.output_dir, stop);
  if (!store.Prepare(error)) return false;

  BatchOptions batch;
  batch.threads = options.threads;
  batch.keep_calibrations = options.keep_calibrations;
  batch.unit_timeout_seconds = options.unit_timeout_seconds;
  batch.stop = stop;
  batch.stop_grace_seconds = options.stop_grace_seconds;
  batch.progress = options.progress;
  batch.skip = [&store](size_t i, const BatchUnit& unit, const std::string& hash) {
    return store.Skip(i, unit, hash);
  };
  batch.on_result = [&store](size_t i, const BatchResult& r) { store.Store(i, r); };

  const auto start = std::chrono::steady_clock::now();
  if (!CalibrateBatch(units.units, base, batch, &summary->results, error)) return false;
  summary->elapsed_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  summary->stop = StopReason(options.stop, store.write_error());
  CountRun(summary);
  summary->rows = store.Rows(summary->results);
  if (!WriteSummaryFiles(options.output_dir, summary->rows, units.info, options.fleet,
                         &summary->statistics, error)) {
    *error += (summary->stop.empty() ? "" : " (batch " + summary->stop + ")") +
              std::string("; the unit results written are complete: run again to resume");
    return false;
  }
  summary->summary_written = true;
  if (options.report.empty()) return true;
  const BatchThroughput throughput = {summary->elapsed_seconds,
                                      summary->computed,
                                      summary->skipped,
                                      summary->busy.read_seconds,
                                      summary->busy.detect_seconds,
                                      summary->busy.solve_seconds};
  return WriteFileAtomically(options.report,
                             FleetToHtml(summary->statistics, summary->rows, throughput), error);
}

std::string FleetFindingsText(const FleetStatistics& s) {
  std::string text;
  char line[64];
  size_t shown = 0;
  for (const SummaryRow& f : s.failures) {
    if (shown++ == kFailuresShown) {
      std::snprintf(line, sizeof(line), "... and %zu more failed units",
                    s.failures.size() - kFailuresShown);
      text += std::string(line) + " (summary.json lists them)\n";
      break;
    }
    text += "unit " + f.unit + " " + ToString(f.status) + ": " + f.message + "\n";
  }
  for (const FleetOutlier& o : s.outliers) {
    text += "outlier " + o.unit + ": " + o.reasons.front() + "\n";
  }
  return text;
}

std::string BatchFolderSummary::BriefReport() const {
  const double total = busy.read_seconds + busy.detect_seconds + busy.solve_seconds;
  auto percent = [total](double x) { return total > 0 ? 100 * x / total : 0.0; };
  const std::string from = shard_source.empty() ? "" : " from " + shard_source;
  const FleetStatistics& st = statistics;
  char line[1024];
  std::snprintf(
      line, sizeof(line),
      "batch: %zu units (shard %d/%d%s of a fleet of %zu): %zu ok, %zu failed, %zu not "
      "converged, %zu outliers; skipped %zu (stored results up to date); %zu timed out; %.1f "
      "units/s computed; time in read %.0f %%, detect %.0f %%, solve %.0f %%; wrote ",
      units, st.info.shard_index, st.info.shard_count, from.c_str(), st.info.units_in_fleet, st.ok,
      st.failed, st.not_converged, st.outliers.size(), skipped, timed_out,
      elapsed_seconds > 0 ? computed / elapsed_seconds : 0.0, percent(busy.read_seconds),
      percent(busy.detect_seconds), percent(busy.solve_seconds));
  std::string text = line + output_dir + "/summary.csv and summary.json\n";
  if (!stop.empty()) {
    text += "batch " + stop + ": " + std::to_string(not_run) +
            " units not run (summary.csv says which); every result written is complete: run "
            "the same command again to resume\n";
  }
  return text;
}

std::string BatchFolderSummary::FullReport() const {
  return FleetFindingsText(statistics) + BriefReport();
}

}  // namespace gravcal
