// gravcal/workflows/batch.h: calibrates many units (one session each) in parallel.
//
// Every unit goes through RunCalibration (pipeline.h) with its own effective
// configuration (the base Config with the unit's overrides applied by
// SetConfigValue), so a unit's result in a batch is exactly what `gravcal
// calibrate` gives for it alone. Units run on a pool of worker threads that
// share no mutable state; a unit that fails (unreadable file, too few poses,
// no convergence, even an exception) is recorded with its message and never
// stops the others. Results come back in input order.
//
// Each unit also gets a content hash: 128 bits over the input bytes (the log
// file, the gyroscope file, the attitudes file; or the in-memory log's
// numbers), the effective configuration as text (every key with its value)
// and the gravcal version. The same hash means the same result, so a caller
// can skip units whose stored result has it (BatchOptions::skip). The hash is
// not cryptographic: it detects changed input, not deliberate forgery.
#ifndef GRAVCAL_WORKFLOWS_BATCH_H_
#define GRAVCAL_WORKFLOWS_BATCH_H_

#include <atomic>
#include <cstddef>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "gravcal/core/calibration.h"
#include "gravcal/core/imu_log.h"
#include "gravcal/core/types.h"
#include "gravcal/workflows/config.h"

namespace gravcal {

// The library version ("0.1.0"), part of every content hash.
const char* GravcalVersion();

// One unit to calibrate: a log file (path) or a log already in memory.
struct BatchUnit {
  // Unit id, used in messages and by callers as a file name.
  std::string id;
  // The raw log file, read with the effective config's reader options
  // (`format`, `columns`, `gyro_path`, ...). When empty, `log` is used.
  std::string path;
  ImuLog log;
  // Method side input (PipelineInput::attitudes_path); empty when unused.
  std::string attitudes_path;
  // Config keys for this unit only, applied in order on top of the base
  // config, e.g. {"gravity", "9.81744"}.
  std::vector<std::pair<std::string, std::string>> overrides;
};

// The base config with the unit's overrides; false with an error naming the
// key when an override is unknown, malformed, or leaves the config invalid.
bool EffectiveConfig(const BatchUnit& unit, const Config& base, Config* config, std::string* error);

// Every key with its value, one "key: value" line each, in ConfigKeys()
// order: the configuration part of the content hash.
std::string ConfigText(const Config& config);

// Wall-clock seconds spent on one unit.
struct BatchTimings {
  // Reading the file(s), hashing and parsing.
  double read_seconds = 0.0;
  // RunCalibration apart from the solver: static detection, positions, coarse
  // fit and uncertainty (detection dominates).
  double detect_seconds = 0.0;
  // The refinement solve (RefinementResult::solve_seconds).
  double solve_seconds = 0.0;
  double total_seconds = 0.0;
};

struct BatchResult {
  std::string unit;
  BatchStatus status = BatchStatus::kFailed;
  // True when BatchOptions::skip reused a stored result: calibration is
  // empty and status / message are not known here.
  bool skipped = false;
  // Calibration::message, or why the unit could not be run.
  std::string message = "not run";
  // Empty when the input could not be read.
  std::string content_hash;
  // Over BatchOptions::unit_timeout_seconds: the unit was abandoned
  // (status kFailed, message says so).
  bool timed_out = false;
  // Not started, or abandoned in flight, because BatchOptions::stop was set
  // (status kFailed, message says so).
  bool not_run = false;
  Calibration calibration;
  BatchTimings timings;
};

// How far a batch has got; passed to BatchOptions::progress.
struct BatchProgress {
  size_t done = 0;
  size_t total = 0;
  size_t failed = 0;
  size_t skipped = 0;
  double elapsed_seconds = 0.0;
};

struct BatchOptions {
  // Worker threads; 0 = one per core (std::thread::hardware_concurrency).
  int threads = 0;
  // Keep each result's Calibration in the returned vector. A caller that
  // stores results in on_result can set false to bound memory on big fleets.
  bool keep_calibrations = true;
  // Called once per unit, after its content hash is known and before it is
  // calibrated; returning true skips the unit (BatchResult::skipped). Called
  // concurrently from worker threads: must be thread-safe.
  std::function<bool(size_t index, const BatchUnit& unit, const std::string& content_hash)> skip;
  // Called once per unit as soon as it is finished (also for skipped
  // units), concurrently from worker threads: must be thread-safe. An
  // exception it throws fails that unit ("<unit>: the result could not be
  // stored: <what>"), not the batch.
  std::function<void(size_t index, const BatchResult& result)> on_result;
  // Called after each unit, one call at a time (serialised), from the
  // worker that finished it.
  std::function<void(const BatchProgress& progress)> progress;
  // Seconds one unit may take (reading, detection, solve); 0 = no limit. A
  // unit over it fails with a message and the batch goes on: its worker is
  // asked to stop (the solver and the log reader check between iterations
  // and lines) and is abandoned, not killed; its late result is dropped and
  // no callback is called for it after that. A fresh worker takes its
  // place.
  double unit_timeout_seconds = 0.0;
  // When it becomes true (e.g. set by a SIGTERM handler), no further unit is
  // started; units in flight may finish for up to stop_grace_seconds, then
  // are abandoned. Units not run get BatchResult::not_run. Not owned.
  const std::atomic<bool>* stop = nullptr;
  double stop_grace_seconds = 30.0;

  bool IsValid(std::string* error) const;
};

// Calibrates every unit with the pipeline of base.method; results in input
// order. Returns false (and no results) only for invalid options; a unit's
// failure is in its BatchResult.
bool CalibrateBatch(const std::vector<BatchUnit>& units, const Config& base,
                    const BatchOptions& options, std::vector<BatchResult>* results,
                    std::string* error);

// The 128-bit content hash (32 hex digits) of a unit whose inputs are
// already in memory: the log file's bytes (or, for an in-memory log, its
// numbers), the gyroscope and attitudes files' bytes (empty when unused),
// and the effective config.
std::string UnitContentHash(const std::string& log_bytes, const std::string& gyro_bytes,
                            const std::string& attitudes_bytes, const Config& config);

}  // namespace gravcal

#endif  // GRAVCAL_WORKFLOWS_BATCH_H_
