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
// files a killed run left behind (io/files.h names them) are removed when
// provably stale; no other file is ever removed. --input-dir may be the
// output folder: the batch's own files there are not units.
#include <dirent.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <system_error>

#include "cli/commands.h"
#include "gravcal/io/calibration_io.h"
#include "gravcal/io/files.h"
#include "gravcal/io/log_reader.h"
#include "gravcal/workflows/batch.h"
#include "gravcal/workflows/batch_manifest.h"
#include "gravcal/workflows/batch_scheduler_shard.h"
#include "gravcal/workflows/fleet_summary.h"
#include "gravcal/workflows/report.h"
#include "util/error.h"

namespace gravcal {
namespace cli {
namespace {

using Json = nlohmann::json;
using internal::SetError;

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

bool FileExists(const std::string& path) {
  struct stat st;
  return stat(path.c_str(), &st) == 0;
}

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

// Set by SIGTERM / SIGINT (once: the second one kills as usual) or by a
// result that cannot be stored; BatchOptions::stop.
std::atomic<bool> g_stop{false};
volatile std::sig_atomic_t g_stop_signal = 0;
static_assert(std::atomic<bool>::is_always_lock_free, "g_stop is set in a signal handler");

void OnStopSignal(int signal) {
  g_stop_signal = signal;
  g_stop.store(true);
}

// Installs OnStopSignal for SIGTERM and SIGINT for the object's lifetime.
class StopSignals {
 public:
  StopSignals() {
    g_stop = false;
    g_stop_signal = 0;
    struct sigaction action = {};
    action.sa_handler = OnStopSignal;
    action.sa_flags = SA_RESETHAND;
    sigemptyset(&action.sa_mask);
    sigaction(SIGTERM, &action, &old_term_);
    sigaction(SIGINT, &action, &old_int_);
  }
  ~StopSignals() {
    sigaction(SIGTERM, &old_term_, nullptr);
    sigaction(SIGINT, &old_int_, nullptr);
  }

 private:
  struct sigaction old_term_ = {};
  struct sigaction old_int_ = {};
};

// The options of a batch, checked.
struct BatchSettings {
  FleetOptions fleet;
  BatchOptions batch;
  Shard shard;
  // Where --shard auto found K/N; empty for K/N or no shard.
  std::string shard_source;
};

bool ReadBatchSettings(const CommandArgs& args, BatchSettings* s, std::string* error) {
  if (args.output_dir.empty()) return SetError(error, "batch needs --output-dir <folder>");
  const bool by_topic = !args.topics.empty();
  if (by_topic && (args.topics != "all" || args.input.empty())) {
    return SetError(error, "--topics takes 'all', with --input <bag or MCAP file>");
  }
  if (by_topic ? !args.manifest.empty() || !args.input_dir.empty()
               : args.manifest.empty() == args.input_dir.empty()) {
    return SetError(error,
                    "batch needs either --manifest <units.csv>, --input-dir <folder> or --input "
                    "<bag> --topics all");
  }
  if (!args.config.IsValid(error)) return false;
  s->fleet.outlier_sigmas = args.outlier_sigmas;
  s->fleet.min_units = args.outlier_min_units;
  if (!s->fleet.IsValid(error)) return false;
  s->batch.threads = args.threads;
  s->batch.keep_calibrations = false;
  s->batch.unit_timeout_seconds = args.unit_timeout;
  s->batch.stop = &g_stop;
  // Below the 30 s that Slurm (KillWait), Kubernetes
  // (terminationGracePeriodSeconds) and AWS Batch (the ECS stop timeout) wait
  // by default between SIGTERM and SIGKILL, so that the summary is written.
  s->batch.stop_grace_seconds = 20.0;
  if (!s->batch.IsValid(error)) return false;
  if (IsSchedulerShard(args.shard)) {
    return ShardFromScheduler(args.shard, ProcessEnvironment(), &s->shard, &s->shard_source, error);
  }
  return args.shard.empty() || ParseShard(args.shard, &s->shard, error);
}

// The fleet's units of this shard, with their positions in the fleet.
struct ShardUnits {
  FleetInfo info;
  std::vector<BatchUnit> units;
  std::vector<size_t> positions;
};

// True when `a` and `b` name the same existing file.
bool SameFile(const std::string& a, const std::string& b) {
  struct stat sa, sb;
  return stat(a.c_str(), &sa) == 0 && stat(b.c_str(), &sb) == 0 && sa.st_dev == sb.st_dev &&
         sa.st_ino == sb.st_ino;
}

// The batch's own files (summary.csv, summary.json, the report) that are in
// its input folder (--input-dir equal to --output-dir, or the report written
// there), to leave out of the units. A file there that is not what this
// batch writes is a unit log the batch would overwrite: refused.
bool OwnFilesInInput(const CommandArgs& args, std::vector<std::string>* own, std::string* error) {
  const std::string summary_json = args.output_dir + "/summary.json";
  std::vector<std::pair<std::string, std::function<bool(const std::string&)>>> outputs = {
      {args.output_dir + "/summary.csv",
       [&](const std::string& text) {
         std::vector<SummaryRow> rows;
         std::string why;
         return ParseSummaryCsv(text, "", &rows, &why);
       }},
      {summary_json,
       [&](const std::string& text) {
         FleetInfo info;
         std::string why;
         return ParseFleetInfo(text, "", &info, &why);
       }},
      {args.report, [](const std::string& text) {
         return text.compare(0, 15, "<!DOCTYPE html>") == 0 || text.compare(0, 5, "<html") == 0;
       }}};
  DIR* dir = opendir(args.input_dir.c_str());
  if (dir == nullptr) return true;  // UnitsFromDirectory says why.
  std::vector<std::string> names;
  while (const dirent* entry = readdir(dir)) names.push_back(entry->d_name);
  closedir(dir);
  for (const auto& [path, ours] : outputs) {
    if (path.empty()) continue;
    for (const std::string& name : names) {
      const std::string input = args.input_dir + "/" + name;
      if (name[0] == '.' || !SameFile(path, input)) continue;
      std::string text;
      if (!ReadFileBytes(input, &text, error)) return false;
      if (!ours(text)) {
        return SetError(error, path + ": the batch would overwrite " + input +
                                   ", a file of --input-dir that it did not write; choose "
                                   "another --output-dir or --report");
      }
      own->push_back(name);
    }
  }
  return true;
}

bool ListShardUnits(const CommandArgs& args, const Shard& shard, ShardUnits* out,
                    std::string* error) {
  std::vector<BatchUnit> fleet;
  std::vector<std::string> own;
  std::vector<std::string> hidden;
  if (!args.input_dir.empty() && !OwnFilesInInput(args, &own, error)) return false;
  const bool listed =
      !args.topics.empty() ? UnitsFromTopics(args.input, &fleet, error)
      : args.manifest.empty()
          ? UnitsFromDirectory(args.input_dir, args.pattern, &fleet, error, own, &hidden)
          : ReadBatchManifest(args.manifest, args.config, &fleet, error);
  if (!listed) return false;
  if (!hidden.empty()) {
    std::string names;
    for (size_t i = 0; i < hidden.size() && i < 5; ++i) {
      names += (i == 0 ? "" : ", ") + hidden[i];
    }
    if (hidden.size() > 5) names += ", ...";
    std::fprintf(stderr,
                 "gravcal: note: %s: skipped %zu hidden file%s (%s): hidden and AppleDouble "
                 "'._' files are never units\n",
                 args.input_dir.c_str(), hidden.size(), hidden.size() == 1 ? "" : "s",
                 names.c_str());
  }
  std::vector<std::string> ids;
  for (const BatchUnit& u : fleet) ids.push_back(u.id);
  out->info.fleet = FleetHash(ids);
  out->info.config = ConfigHash(args.config);
  out->info.units_in_fleet = fleet.size();
  out->info.shard_index = shard.index;
  out->info.shard_count = shard.count;
  out->positions = ShardPositions(fleet.size(), shard);
  for (size_t p : out->positions) out->units.push_back(std::move(fleet[p]));
  return true;
}

// No output of the batch (summary.csv, summary.json, the report, each
// unit's result and state file) is the log or side file of one of its units
// (a manifest naming out/u2.json as u1's log or gyro_path, --pattern '*' in
// its own output folder): refused before any unit runs.
bool CheckUnitsAgainstOutputs(const CommandArgs& args, const std::vector<BatchUnit>& units,
                              std::string* error) {
  std::map<std::pair<dev_t, ino_t>, std::pair<const BatchUnit*, std::string>> inputs;
  for (const BatchUnit& u : units) {
    std::vector<std::string> paths = {u.path, u.attitudes_path};
    for (const auto& [key, value] : u.overrides) {
      if (key == "gyro_path") paths.push_back(value);
    }
    for (const std::string& path : paths) {
      struct stat st;
      if (!path.empty() && stat(path.c_str(), &st) == 0) {
        inputs.emplace(std::make_pair(st.st_dev, st.st_ino), std::make_pair(&u, path));
      }
    }
  }
  if (inputs.empty()) return true;
  const std::string& out = args.output_dir;
  std::vector<std::string> outputs = {out + "/summary.csv", out + "/summary.json", args.report};
  for (const BatchUnit& u : units) {
    outputs.push_back(out + "/" + u.id + ".json");
    outputs.push_back(out + "/" + kStateFolder + "/" + u.id + ".json");
  }
  for (const std::string& path : outputs) {
    struct stat st;
    if (path.empty() || stat(path.c_str(), &st) != 0) continue;
    const auto it = inputs.find(std::make_pair(st.st_dev, st.st_ino));
    if (it != inputs.end()) {
      return SetError(error, path + ": the batch would overwrite " + it->second.second +
                                 ", an input of unit " + it->second.first->id +
                                 ": gravcal never overwrites its input");
    }
  }
  return true;
}

// The batch's files: the state of each unit (resume), its calibration JSON,
// and its summary row. A result that cannot be stored (disk full, folder
// unwritable) stops the batch: the units after it would fail the same way.
class BatchStore {
 public:
  BatchStore(const CommandArgs& args, const ShardUnits& shard)
      : args_(args),
        shard_(shard),
        out_(args.output_dir),
        state_folder_(out_ + "/" + kStateFolder),
        rows_(shard.units.size()),
        have_row_(shard.units.size(), 0) {}

  bool Prepare(std::string* error) {
    if (!MakeFolders(state_folder_, error)) return false;
    RemoveStaleTemporaries(out_);
    RemoveStaleTemporaries(state_folder_);
    return true;
  }

  bool Skip(size_t i, const BatchUnit& unit, const std::string& hash) {
    SummaryRow row;
    if (!ReadState(state_folder_ + "/" + unit.id + ".json", hash, shard_.positions[i], &row)) {
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
      g_stop = true;
      throw std::runtime_error(why);
    }
  }

  // Every unit's row: from its state or this run's result.
  const std::vector<SummaryRow>& Rows(const std::vector<BatchResult>& results) {
    for (size_t i = 0; i < rows_.size(); ++i) {
      if (!have_row_[i]) rows_[i] = MakeSummaryRow(shard_.positions[i], results[i]);
    }
    return rows_;
  }

  // The first result that could not be stored ("" when none).
  std::string write_error() const { return write_error_; }
  const std::string& out() const { return out_; }

 private:
  bool WriteResult(size_t i, const BatchResult& r, std::string* why) {
    const std::string result_path = out_ + "/" + r.unit + ".json";
    if (r.status == BatchStatus::kOk) {
      Config config;
      if (!EffectiveConfig(shard_.units[i], args_.config, &config, why) ||
          !WriteCalibrationJson(r.calibration, config.output_covariance, result_path, why)) {
        return false;
      }
    } else if (IsOwnResult(result_path) && unlink(result_path.c_str()) != 0 && errno != ENOENT) {
      *why = result_path +
             ": cannot remove the stale result: " + std::generic_category().message(errno);
      return false;
    }
    SummaryRow row = MakeSummaryRow(shard_.positions[i], r);
    if (!r.content_hash.empty()) {
      const Json state = {{"unit", r.unit},
                          {"content_hash", r.content_hash},
                          {"gravcal_version", GravcalVersion()},
                          {"row", RowToJson(row)}};
      if (!WriteFileAtomically(state_folder_ + "/" + r.unit + ".json", state.dump(2) + "\n", why)) {
        return false;
      }
    }
    rows_[i] = std::move(row);
    have_row_[i] = 1;
    return true;
  }

  const CommandArgs& args_;
  const ShardUnits& shard_;
  const std::string out_;
  const std::string state_folder_;
  std::vector<SummaryRow> rows_;
  std::vector<char> have_row_;
  std::mutex mutex_;
  std::string write_error_;
};

// What happened to the units of this run, beyond the fleet statistics.
struct RunCounts {
  size_t skipped = 0;
  size_t timed_out = 0;
  size_t not_run = 0;
  BatchTimings sum;
};

RunCounts CountRun(const std::vector<BatchResult>& results) {
  RunCounts c;
  for (const BatchResult& r : results) {
    if (r.skipped) ++c.skipped;
    if (r.timed_out) ++c.timed_out;
    if (r.not_run) ++c.not_run;
    if (r.skipped || r.not_run) continue;
    c.sum.read_seconds += r.timings.read_seconds;
    c.sum.detect_seconds += r.timings.detect_seconds;
    c.sum.solve_seconds += r.timings.solve_seconds;
  }
  return c;
}

// Why the batch stopped early ("" when it did not).
std::string StopReason(const BatchStore& store) {
  if (g_stop_signal != 0)
    return std::string("stopped by ") + (g_stop_signal == SIGINT ? "SIGINT" : "SIGTERM");
  if (!store.write_error().empty()) return "stopped: cannot store a result: " + store.write_error();
  return "";
}

void PrintBatchLine(const BatchSettings& s, const ShardUnits& shard, const FleetStatistics& st,
                    const RunCounts& c, double elapsed, const std::string& stop,
                    const std::string& out) {
  const size_t computed = shard.units.size() - c.skipped - c.not_run;
  const double busy = c.sum.read_seconds + c.sum.detect_seconds + c.sum.solve_seconds;
  auto percent = [busy](double x) { return busy > 0 ? 100 * x / busy : 0.0; };
  const std::string from = s.shard_source.empty() ? "" : " from " + s.shard_source;
  std::fprintf(
      stderr,
      "gravcal: batch: %zu units (shard %d/%d%s of a fleet of %zu): %zu ok, %zu failed, %zu not "
      "converged, %zu outliers; skipped %zu (stored results up to date); %zu timed out; %.1f "
      "units/s computed; time in read %.0f %%, detect %.0f %%, solve %.0f %%; wrote "
      "%s/summary.csv and summary.json\n",
      shard.units.size(), s.shard.index, s.shard.count, from.c_str(),
      static_cast<size_t>(shard.info.units_in_fleet), st.ok, st.failed, st.not_converged,
      st.outliers.size(), c.skipped, c.timed_out, elapsed > 0 ? computed / elapsed : 0.0,
      percent(c.sum.read_seconds), percent(c.sum.detect_seconds), percent(c.sum.solve_seconds),
      out.c_str());
  if (!stop.empty()) {
    std::fprintf(stderr,
                 "gravcal: batch %s: %zu units not run (summary.csv says which); every result "
                 "written is complete: run the same command again to resume\n",
                 stop.c_str(), c.not_run);
  }
}

}  // namespace

int RunBatch(const CommandArgs& args) {
  BatchSettings settings;
  std::string error;
  if (!ReadBatchSettings(args, &settings, &error)) return Fail(error);
  if (!CheckAcceptanceArgs(args, &error)) return Fail(error);
  ShardUnits shard;
  if (!ListShardUnits(args, settings.shard, &shard, &error)) return Fail(error);
  if (!CheckUnitsAgainstOutputs(args, shard.units, &error)) return Fail(error);
  BatchStore store(args, shard);
  if (!store.Prepare(&error)) return Fail(error);

  StopSignals signals;
  BatchOptions& options = settings.batch;
  options.skip = [&store](size_t i, const BatchUnit& unit, const std::string& hash) {
    return store.Skip(i, unit, hash);
  };
  options.on_result = [&store](size_t i, const BatchResult& r) { store.Store(i, r); };
  ProgressDisplay display;
  options.progress = [&display](const BatchProgress& p) { display.Update(p); };

  const auto start = std::chrono::steady_clock::now();
  std::vector<BatchResult> results;
  if (!CalibrateBatch(shard.units, args.config, options, &results, &error)) return Fail(error);
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  const std::string stop = StopReason(store);
  const RunCounts counts = CountRun(results);
  FleetStatistics statistics;
  if (!WriteSummary(store.out(), store.Rows(results), shard.info, settings.fleet, &statistics,
                    &error)) {
    return Fail(error + (stop.empty() ? "" : " (batch " + stop + ")") +
                "; the unit results written are complete: run again to resume");
  }
  ReportFleet(statistics);
  if (!args.report.empty()) {
    const size_t computed = shard.units.size() - counts.skipped - counts.not_run;
    const BatchThroughput throughput = {elapsed,
                                        computed,
                                        counts.skipped,
                                        counts.sum.read_seconds,
                                        counts.sum.detect_seconds,
                                        counts.sum.solve_seconds};
    if (!WriteFileAtomically(args.report, FleetToHtml(statistics, store.Rows(results), throughput),
                             &error)) {
      return Fail(error);
    }
  }
  PrintBatchLine(settings, shard, statistics, counts, elapsed, stop, store.out());
  if (!stop.empty()) return Fail("batch " + stop);
  std::vector<std::string> ids;
  for (const BatchUnit& u : shard.units) ids.push_back(u.id);
  return FinishBatchAcceptance(args, ids, ExitCode(statistics));
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
