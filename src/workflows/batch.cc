#include "gravcal/workflows/batch.h"

#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <string>
#include <thread>

#include "gravcal/io/calibration_io.h"
#include "gravcal/io/log_reader.h"
#include "gravcal/io/long_log.h"
#include "gravcal/io/recording.h"
#include "gravcal/workflows/pipeline.h"
#include "util/content_hash.h"
#include "workflows/batch_run.h"

#ifndef GRAVCAL_VERSION
#error "GRAVCAL_VERSION must be defined by the build (CMakeLists.txt)"
#endif

namespace gravcal {

using internal::ContentHash;

namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double>(to - from).count();
}

// The numbers of an in-memory log as bytes, for the content hash.
std::string LogBytes(const ImuLog& log) {
  std::string bytes;
  auto add = [&bytes](const double* p, size_t count) {
    bytes.append(reinterpret_cast<const char*>(p), count * sizeof(double));
  };
  add(log.t.data(), log.t.size());
  for (const Eigen::Vector3d& a : log.accel) add(a.data(), 3);
  for (const Eigen::Vector3d& w : log.gyro) add(w.data(), 3);
  add(log.temperature.data(), log.temperature.size());
  return bytes;
}

bool SameFileState(const struct stat& a, const struct stat& b) {
  return a.st_ino == b.st_ino && a.st_dev == b.st_dev && a.st_size == b.st_size &&
         a.st_mtim.tv_sec == b.st_mtim.tv_sec && a.st_mtim.tv_nsec == b.st_mtim.tv_nsec;
}

// ReadFileBytes, refusing a regular file that changed while it was read
// (truncated, rewritten, or of another size than the bytes read): the
// bytes would be a mix, and their hash would mark a wrong result as current.
// The message for a unit file whose size changed while it was read.
std::string ChangedWhileRead(const std::string& path) {
  return path +
         ": the file changed while it was read (truncated or rewritten?); the unit is tried "
         "again on the next run";
}

bool ReadUnitFile(const std::string& path, std::string* bytes, std::string* error) {
  struct stat before, after;
  const bool regular = stat(path.c_str(), &before) == 0 && S_ISREG(before.st_mode);
  if (!ReadFileBytes(path, bytes, error)) return false;
  if (regular && (stat(path.c_str(), &after) != 0 || !SameFileState(before, after) ||
                  static_cast<off_t>(bytes->size()) != before.st_size)) {
    *error = ChangedWhileRead(path);
    return false;
  }
  return true;
}

// Units larger than this are hashed block by block and read in bounded
// memory (io/long_log.h), as `calibrate` reads a log, never held whole.
// Smaller ones (at most about 1.5 M rows: read exactly either way) are read
// whole once, for the hash and the samples.
constexpr uint64_t kStreamedUnitBytes = uint64_t{64} << 20;

// Whether `path` is a text log of more than kStreamedUnitBytes.
bool IsLongTextUnit(const std::string& path) {
  struct stat st;
  if (stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode) ||
      static_cast<uint64_t>(st.st_size) <= kStreamedUnitBytes) {
    return false;
  }
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) return false;
  std::string head(4096, '\0');
  head.resize(std::fread(head.data(), 1, head.size(), file));
  std::fclose(file);
  return !IsMessageRecording(head);
}

// UnitContentHash of the log file at `path` (no gyroscope file), its bytes
// read block by block.
bool StreamedUnitHash(const std::string& path, const std::string& attitudes_bytes,
                      const Config& config, std::string* hex, std::string* error) {
  struct stat st;
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr || fstat(fileno(file), &st) != 0) {
    if (file != nullptr) std::fclose(file);
    *error = path + ": cannot open";
    return false;
  }
  const uint64_t size = static_cast<uint64_t>(st.st_size);
  ContentHash hash;
  hash.Add(GravcalVersion());
  hash.Add(ConfigText(config));
  hash.Begin(size);
  std::string block(size_t{1} << 20, '\0');
  uint64_t read = 0;
  for (size_t n; (n = std::fread(block.data(), 1, block.size(), file)) > 0; read += n) {
    hash.Append(std::string_view(block.data(), n));
  }
  std::fclose(file);
  if (read != size) {
    *error = ChangedWhileRead(path);
    return false;
  }
  hash.End();
  hash.Add("");  // no gyroscope file
  hash.Add(attitudes_bytes);
  *hex = hash.Hex();
  return true;
}

}  // namespace

namespace internal {

void RunUnit(const BatchUnit& unit, const Config& base, const SkipFunction& skip, BatchResult* r) {
  const Clock::time_point start = Clock::now();
  r->unit = unit.id;
  // Ends the unit before calibration: all of its time was reading.
  auto stop = [&](const std::string& message) {
    r->message = message;
    r->timings.read_seconds = r->timings.total_seconds = Seconds(start, Clock::now());
  };
  std::string error;
  Config config;
  if (!EffectiveConfig(unit, base, &config, &error)) return stop(unit.id + ": " + error);
  std::string log_bytes;
  std::string gyro_bytes;
  std::string attitudes_bytes;
  const bool streamed =
      !unit.path.empty() && config.input.gyro_path.empty() && IsLongTextUnit(unit.path);
  if (unit.path.empty()) {
    log_bytes = LogBytes(unit.log);
  } else if (!streamed && !ReadUnitFile(unit.path, &log_bytes, &error)) {
    return stop(error);
  }
  if ((!config.input.gyro_path.empty() &&
       !ReadUnitFile(config.input.gyro_path, &gyro_bytes, &error)) ||
      (!unit.attitudes_path.empty() &&
       !ReadUnitFile(unit.attitudes_path, &attitudes_bytes, &error))) {
    return stop(error);
  }
  if (!streamed) {
    r->content_hash = UnitContentHash(log_bytes, gyro_bytes, attitudes_bytes, config);
  } else if (!StreamedUnitHash(unit.path, attitudes_bytes, config, &r->content_hash, &error)) {
    return stop(error);
  }
  if (skip && skip(unit, r->content_hash)) {
    r->skipped = true;
    return stop("skipped: the stored result has this content hash");
  }
  SessionFiles files;
  files.attitudes_path = unit.attitudes_path;
  Session session;
  LongLogReading reading;
  reading.max_samples = static_cast<size_t>(config.input.max_log_entries);
  reading.threads = 1;  // The batch runs units on its threads already.
  CalibrationProvenance provenance;
  if (unit.path.empty()) {
    session.log = unit.log;
  } else if (streamed) {
    if (!ReadImuLogBounded(unit.path, config.input, &reading, &session.log, &provenance, &error)) {
      return stop(error);
    }
  } else {
    // Exactly what ReadImuLog does after reading the file.
    // Bags and MCAP files are read from the file, message by message.
    const bool read = IsMessageRecording(std::string_view(log_bytes).substr(0, 4096))
                          ? ReadImuLog(unit.path, config.input, &session.log, &error)
                          : ParseImuLog(log_bytes, unit.path, config.input, &session.log, &error);
    if (!read) return stop(error);
  }
  const Clock::time_point read_end = Clock::now();
  const bool ok = RunCalibration(config, files, &session, &r->calibration);
  // Issue 16: the same provenance as calibrate records.
  if (streamed) {
    r->calibration.provenance = provenance;
    AddLongLogWarning(reading, &r->calibration);
  } else if (!unit.path.empty()) {
    r->calibration.provenance = LogProvenanceOfBytes(unit.path, log_bytes);
  }
  const Clock::time_point end = Clock::now();
  r->message = r->calibration.message;
  r->status = ok                             ? BatchStatus::kOk
              : r->calibration.not_converged ? BatchStatus::kNotConverged
                                             : BatchStatus::kFailed;
  r->timings.read_seconds = Seconds(start, read_end);
  r->timings.solve_seconds = r->calibration.refinement.solve_seconds;
  r->timings.detect_seconds = std::max(0.0, Seconds(read_end, end) - r->timings.solve_seconds);
  r->timings.total_seconds = Seconds(start, end);
}

}  // namespace internal

const char* GravcalVersion() { return GRAVCAL_VERSION; }

bool EffectiveConfig(const BatchUnit& unit, const Config& base, Config* config,
                     std::string* error) {
  Config c = base;
  for (const auto& [key, value] : unit.overrides) {
    if (!SetConfigValue(key, value, &c, error)) return false;
  }
  if (!c.IsValid(error)) return false;
  *config = c;
  return true;
}

std::string ConfigText(const Config& config) {
  std::string text;
  for (const ConfigKey& key : ConfigKeys()) {
    text += key.name + ": " + ConfigValueText(config, key.name) + "\n";
  }
  return text;
}

bool BatchOptions::IsValid(std::string* error) const {
  if (threads < 0) {
    *error = "threads: must be >= 0 (0 = one per core), is " + std::to_string(threads);
    return false;
  }
  if (!(unit_timeout_seconds >= 0.0) || !(stop_grace_seconds >= 0.0)) {
    *error = "unit_timeout_seconds and stop_grace_seconds: must be >= 0 (0 = no time limit)";
    return false;
  }
  return true;
}

std::string UnitContentHash(const std::string& log_bytes, const std::string& gyro_bytes,
                            const std::string& attitudes_bytes, const Config& config) {
  ContentHash hash;
  hash.Add(GravcalVersion());
  hash.Add(ConfigText(config));
  hash.Add(log_bytes);
  hash.Add(gyro_bytes);
  hash.Add(attitudes_bytes);
  return hash.Hex();
}

bool CalibrateBatch(const std::vector<BatchUnit>& units, const Config& base,
                    const BatchOptions& options, std::vector<BatchResult>* results,
                    std::string* error) {
  if (!options.IsValid(error)) return false;
  int threads = options.threads;
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  results->assign(units.size(), BatchResult());
  internal::BatchRun run(units, base, options, results);
  run.Run(threads);
  return true;
}

}  // namespace gravcal
