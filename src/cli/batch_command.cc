// gravcal batch and gravcal merge-summaries: the flags, the signal handler
// and the text. The batch itself, its folder, resume and the shard merge
// are the library's (workflows/batch_folder.h).
#include <signal.h>
#include <unistd.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <cstdio>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "gravcal/workflows/batch_folder.h"
#include "gravcal/workflows/multi_imu_log.h"
#include "util/error.h"
#include "workflows/batch_scheduler_shard.h"

namespace gravcal {

using internal::IsSchedulerShard;
using internal::ProcessEnvironment;
using internal::ShardFromScheduler;
namespace cli {
namespace {

using internal::SetError;

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

// Set by SIGTERM / SIGINT (once: the second one kills as usual).
BatchStop g_stop;
static_assert(std::atomic<bool>::is_always_lock_free && std::atomic<int>::is_always_lock_free,
              "g_stop is set in a signal handler");

void OnStopSignal(int signal) { g_stop.RequestBySignal(signal); }

// Installs OnStopSignal for SIGTERM and SIGINT for the object's lifetime.
class StopSignals {
 public:
  StopSignals() {
    g_stop.requested = false;
    g_stop.signal = 0;
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

// Each line of `text` on stderr as "gravcal: <line>".
void PrintLines(const std::string& text) {
  size_t begin = 0;
  while (begin < text.size()) {
    const size_t end = text.find('\n', begin);
    std::fprintf(stderr, "gravcal: %s\n", text.substr(begin, end - begin).c_str());
    if (end == std::string::npos) break;
    begin = end + 1;
  }
}

// The flags as the library's source and options, checked.
bool ReadBatchFlags(const BatchArgs& args, BatchSource* source, BatchFolderOptions* options,
                    std::string* shard_source, std::string* error) {
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
  *source = {args.manifest, args.input_dir, args.pattern, args.input, args.topics};
  options->output_dir = args.output_dir;
  options->report = args.report;
  options->fleet.outlier_sigmas = args.outlier_sigmas;
  options->fleet.min_units = args.outlier_min_units;
  options->threads = args.threads;
  options->keep_calibrations = false;
  options->unit_timeout_seconds = args.unit_timeout;
  options->stop = &g_stop;
  if (!options->IsValid(error)) return false;
  if (IsSchedulerShard(args.shard)) {
    return ShardFromScheduler(args.shard, ProcessEnvironment(), &options->shard, shard_source,
                              error);
  }
  return args.shard.empty() || ParseShard(args.shard, &options->shard, error);
}

void PrintHiddenNote(const std::string& folder, const std::vector<std::string>& hidden) {
  if (hidden.empty()) return;
  std::string names;
  for (size_t i = 0; i < hidden.size() && i < 5; ++i) names += (i == 0 ? "" : ", ") + hidden[i];
  if (hidden.size() > 5) names += ", ...";
  std::fprintf(stderr,
               "gravcal: note: %s: skipped %zu hidden file%s (%s): hidden and AppleDouble "
               "'._' files are never units\n",
               folder.c_str(), hidden.size(), hidden.size() == 1 ? "" : "s", names.c_str());
}

}  // namespace

namespace {

// A unit's file and samples (a few MB each) taken from memory the process
// keeps, not mapped fresh from the kernel and zeroed for every unit
// (glibc's default for blocks of 128 kB or more: 1-2 ms of a 1.6 MB unit's
// 10 went to page faults). What is freed is still given back above 256 MB.
void KeepUnitMemory() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_THRESHOLD, 64 << 20);
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
#endif
}

}  // namespace

int RunBatch(const BatchArgs& args) {
  if (IsMultiImuConfigFile(args.config_path)) return RunPlateBatch(args);
  KeepUnitMemory();
  BatchSource source;
  BatchFolderOptions options;
  std::string shard_source;
  std::string error;
  if (!ReadBatchFlags(args, &source, &options, &shard_source, &error)) return Fail(error);
  if (!CheckLimitsFile(args.limits, &error)) return Fail(error);
  BatchFolderUnits units;
  if (!ListBatchFolderUnits(source, args.config, options, &units, &error)) return Fail(error);
  PrintHiddenNote(args.input_dir, units.hidden);

  StopSignals signals;
  ProgressDisplay display;
  options.progress = [&display](const BatchProgress& p) { display.Update(p); };
  BatchFolderSummary summary;
  const bool ok = CalibrateBatchToFolder(units, args.config, options, &summary, &error);
  if (summary.summary_written) PrintLines(FleetFindingsText(summary.statistics));
  if (!ok) return Fail(error);
  summary.shard_source = shard_source;
  PrintLines(summary.BriefReport());
  if (!summary.stop.empty()) return Fail("batch " + summary.stop);
  std::vector<std::pair<std::string, std::string>> ids;
  for (const BatchUnit& u : units.units) ids.emplace_back(u.id, u.path);
  return FinishBatchAcceptance(args, ids, ExitCode(summary.statistics));
}

int RunMergeSummaries(const BatchArgs& args) {
  if (args.output_dir.empty()) return Fail("merge-summaries needs --output-dir <folder>");
  if (args.positional.empty()) {
    return Fail("merge-summaries needs the folders of the shards' summaries");
  }
  FleetOptions fleet;
  fleet.outlier_sigmas = args.outlier_sigmas;
  fleet.min_units = args.outlier_min_units;
  FleetStatistics statistics;
  std::string error;
  if (!MergeBatchSummaries(args.positional, args.output_dir, fleet, &statistics, &error)) {
    return Fail(error);
  }
  PrintLines(FleetFindingsText(statistics));
  std::fprintf(stderr,
               "gravcal: merged %zu shards, %zu units: %zu ok, %zu failed, %zu not converged, %zu "
               "outliers; wrote %s/summary.csv and summary.json\n",
               args.positional.size(), statistics.units, statistics.ok, statistics.failed,
               statistics.not_converged, statistics.outliers.size(), args.output_dir.c_str());
  return 0;
}

}  // namespace cli
}  // namespace gravcal
