// gravcal/workflows/batch_folder.h: a batch written to an output folder, that
// resumes where a killed or stopped run left off (`gravcal batch`, and the
// Python `gravcal.batch(..., output_dir=...)`).
//
// Output folder of a batch:
//   <unit>.json              the calibration JSON, as `gravcal calibrate` writes it
//   batch_state/<unit>.json  the unit's state (below): its content hash and summary row
//   summary.csv, summary.json
// Every file is written atomically (io/files.h). A unit is skipped when its
// state file has the unit's current content hash (batch.h) and, if it
// calibrated, <unit>.json exists: its summary row is taken from the state
// file. Units whose input could not be read get no state file, so they are
// tried again. Temporary files a killed run left behind are removed when
// provably stale (RemoveStaleTemporaries); no other file is ever removed but
// a calibration JSON of this batch's unit that failed this time. --input-dir
// may be the output folder: the batch's own files there are not units.
//
// State file schema (batch_state/<unit>.json, JSON object):
//   unit             the unit id
//   content_hash     32 hex digits (UnitContentHash)
//   gravcal_version  the version that wrote it (also part of the hash)
//   row              {unit, status ("ok", "failed", "not_converged"),
//                     message, values {column: number or null}}: the unit's
//                     summary row (fleet_summary.h)
// A state file that cannot be read, or of another hash, means: calibrate
// the unit again.
//
// Stopping: a stop request (BatchStop, e.g. from a SIGTERM handler the
// caller installs) starts no further unit; units in flight may finish for
// stop_grace_seconds. The summary is written with the units not run marked
// so, and the same call again resumes. A result that cannot be stored (disk
// full, folder unwritable) stops the batch the same way: the units after it
// would fail alike.
#ifndef GRAVCAL_WORKFLOWS_BATCH_FOLDER_H_
#define GRAVCAL_WORKFLOWS_BATCH_FOLDER_H_

#include <atomic>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "gravcal/workflows/batch.h"
#include "gravcal/workflows/batch_manifest.h"
#include "gravcal/workflows/config.h"
#include "gravcal/workflows/fleet_summary.h"

namespace gravcal {

// The folder of the unit state files inside a batch's output folder.
extern const char kBatchStateFolder[];

// Below the 30 s that Slurm (KillWait), Kubernetes
// (terminationGracePeriodSeconds) and AWS Batch (the ECS stop timeout) wait
// by default between SIGTERM and SIGKILL, so that the summary is written.
constexpr double kBatchStopGraceSeconds = 20.0;

// A request to stop a batch, safe to set from a signal handler (both members
// are lock-free atomics). The caller installs the handler; the library only
// reads it.
struct BatchStop {
  std::atomic<bool> requested{false};
  // The signal that asked (SIGTERM, SIGINT), 0 when none did.
  std::atomic<int> signal{0};

  // Async-signal-safe.
  void RequestBySignal(int signal_number) {
    signal.store(signal_number);
    requested.store(true);
  }
};

// Where the units of a batch come from: a bag / MCAP file `input` whose
// sensor_msgs/Imu topics are the units (`topics` = "all"), else a manifest
// CSV, else a folder (every file matching `pattern`).
struct BatchSource {
  std::string manifest;
  std::string input_dir;
  std::string pattern = "*.csv";
  std::string input;
  std::string topics;
};

struct BatchFolderOptions {
  // The folder to write into (created if missing).
  std::string output_dir;
  // The fleet's HTML report, written after the summary; empty for none.
  std::string report;
  // This run's part of the fleet (batch_manifest.h); 1/1 for all.
  Shard shard;
  FleetOptions fleet;
  int threads = 0;
  double unit_timeout_seconds = 0.0;
  // Keep every computed Calibration in BatchFolderSummary::results. The
  // results are in the folder anyway; false bounds memory on big fleets.
  bool keep_calibrations = true;
  // Not owned; may be null (no stop but a failed store).
  BatchStop* stop = nullptr;
  double stop_grace_seconds = kBatchStopGraceSeconds;
  // Called after each unit, serialised (BatchOptions::progress).
  std::function<void(const BatchProgress& progress)> progress;

  bool IsValid(std::string* error) const;
};

// The fleet's units of this run's shard, with their positions in the fleet.
struct BatchFolderUnits {
  FleetInfo info;
  std::vector<BatchUnit> units;
  std::vector<size_t> positions;
  // Hidden files of --input-dir that were not taken as units (a caller may
  // say so).
  std::vector<std::string> hidden;
};

// Lists the fleet from `source` and picks the shard's units. The batch's own
// files in an input folder that is also its output folder are not units.
bool ListBatchFolderUnits(const BatchSource& source, const Config& base,
                          const BatchFolderOptions& options, BatchFolderUnits* units,
                          std::string* error);

// The units of `shard` among `fleet` (a list the caller made), with the
// fleet's FleetInfo under `base`.
BatchFolderUnits ShardOfFleet(std::vector<BatchUnit> fleet, const Config& base, const Shard& shard);

// What a batch run did.
struct BatchFolderSummary {
  // One per unit of the shard, in order (BatchResult::calibration empty
  // unless keep_calibrations).
  std::vector<BatchResult> results;
  // Every unit's summary row: from its state file (skipped) or this run.
  std::vector<SummaryRow> rows;
  FleetStatistics statistics;
  // Where the shard came from ("" for K/N given or no shard): for the text.
  std::string shard_source;
  size_t units = 0;
  size_t computed = 0;
  size_t skipped = 0;
  size_t timed_out = 0;
  size_t not_run = 0;
  // Summed over the computed units.
  BatchTimings busy;
  double elapsed_seconds = 0.0;
  // Why the batch stopped early, "" when it did not: "stopped by SIGTERM",
  // "stopped: cannot store a result: <why>".
  std::string stop;
  std::string output_dir;
  // True once summary.csv and summary.json are written (the report may
  // still fail).
  bool summary_written = false;

  // One line: the counts, the rate and where the time went; a second line
  // when the batch stopped early.
  std::string BriefReport() const;
  // One line per failed unit (the first 10) and per outlier, then the brief
  // report.
  std::string FullReport() const;
};

// Calibrates `units` into options.output_dir, skipping the units whose
// stored result is current, then writes summary.csv, summary.json and the
// report. A batch one of whose outputs would be the input of one of its
// units (a manifest naming out/u2.json as u1's log, --pattern '*' in its own
// output folder) is refused before any unit runs. False with a one-line
// error for that, for invalid options or a folder that
// cannot be written (when the summary cannot be written the error says the
// unit results written are complete); a unit's failure is in its row.
bool CalibrateBatchToFolder(const BatchFolderUnits& units, const Config& base,
                            const BatchFolderOptions& options, BatchFolderSummary* summary,
                            std::string* error);

// Merges the summaries of a fleet's shards (each folder holding the
// summary.csv and summary.json of one `batch --shard K/N`) into
// output_dir's summary.csv and summary.json. Every shard must be there
// once, of the same fleet (unit list, shard count) and config; false with
// the folder that is not (nothing written).
bool MergeBatchSummaries(const std::vector<std::string>& shard_folders,
                         const std::string& output_dir, const FleetOptions& fleet,
                         FleetStatistics* statistics, std::string* error);

// The lines FullReport starts with: the first failed units and every
// outlier of `statistics`, one line each, each ending in '\n'.
std::string FleetFindingsText(const FleetStatistics& statistics);

}  // namespace gravcal

#endif  // GRAVCAL_WORKFLOWS_BATCH_FOLDER_H_
