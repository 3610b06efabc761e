// A batch of plates (workflows/multi_imu_batch.h): each plate calibrated as
// one multi-IMU session, one summary row per IMU.
#include "gravcal/workflows/multi_imu_batch.h"

#include <chrono>
#include <cmath>
#include <exception>
#include <thread>

#include "gravcal/io/files.h"
#include "gravcal/workflows/multi_imu_log.h"
#include "util/content_hash.h"
#include "util/thread_pool.h"

namespace gravcal {
namespace {

// What one plate gave: its rows (index filled in later), its units and
// files, or why it failed.
struct PlateOutcome {
  std::vector<SummaryRow> rows;
  std::vector<std::pair<std::string, std::string>> units;
  std::vector<std::string> warnings;
  bool failed = false;
};

// Failed rows: one per listed IMU, or one for the plate (imus: auto).
void FailPlate(const BatchUnit& plate, const MultiImuConfig& config, const std::string& why,
               PlateOutcome* out) {
  out->failed = true;
  std::vector<std::string> names;
  if (!config.auto_imus) {
    for (const MultiImuLogSpec& s : config.imus) names.push_back(plate.id + "." + s.name);
  }
  if (names.empty()) names.push_back(plate.id);
  for (const std::string& name : names) {
    SummaryRow row;
    row.unit = name;
    row.status = BatchStatus::kFailed;
    row.message = why;
    out->rows.push_back(row);
  }
}

void RunPlate(const BatchUnit& plate, const MultiImuConfig& base, const std::string& output_dir,
              PlateOutcome* out) {
  const auto start = std::chrono::steady_clock::now();
  MultiImuConfig config = base;
  std::vector<PlateImu> imus;
  CalibrationProvenance provenance;
  std::string error;
  if (!ReadMultiImuLogs(&config, plate.path, &imus, &provenance, &error)) {
    FailPlate(plate, base, error, out);
    return;
  }
  MultiImuResult result;
  if (!CalibrateMultiImu(imus, config.options, &result)) {
    FailPlate(plate, config, result.message, out);
    return;
  }
  const std::string folder = output_dir + "/" + plate.id;
  if (!MakeFolders(folder, &error) ||
      !WriteFilesAtomically(MultiImuSessionFiles(result, config, imus, provenance, folder,
                                                 output_dir + "/" + plate.id + "."),
                            &error)) {
    FailPlate(plate, config, error, out);
    return;
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  for (const std::string& w : result.warnings) out->warnings.push_back(plate.id + ": " + w);
  for (const PlateImuResult& r : result.imus) {
    BatchResult b;
    b.unit = plate.id + "." + r.name;
    b.status = BatchStatus::kOk;
    b.message = r.calibration.message;
    b.calibration = r.calibration;
    // The plate's time, shared by its IMUs.
    b.timings.total_seconds = seconds / static_cast<double>(result.imus.size());
    SummaryRow row = MakeSummaryRow(0, b);
    row.values["time_offset"] = r.time_offset;
    row.values["time_offset_std"] = r.time_offset_std;
    row.values["rotation_sigma_deg"] = r.rotation_std.norm() * 180.0 / M_PI;
    out->rows.push_back(row);
    out->units.emplace_back(b.unit, plate.path);
  }
}

}  // namespace

bool PlateBatchOptions::IsValid(std::string* error) const {
  if (output_dir.empty()) {
    *error = "a batch of plates needs an output folder";
    return false;
  }
  if (threads < 0) {
    *error = "threads must be >= 0";
    return false;
  }
  return fleet.IsValid(error);
}

bool CalibratePlateBatch(const std::vector<BatchUnit>& plates, const std::string& config_path,
                         const PlateBatchOptions& options, PlateBatchSummary* summary,
                         std::string* error) {
  if (!options.IsValid(error)) return false;
  MultiImuConfig config;
  if (!LoadMultiImuConfig(config_path, &config, error)) return false;
  for (const BatchUnit& p : plates) {
    if (!p.overrides.empty()) {
      *error = p.id + ": per-unit config keys are not taken for a plate (set them in " +
               config_path + ")";
      return false;
    }
    if (p.path.empty()) {
      *error = p.id + ": a plate is a file (a table of several IMUs)";
      return false;
    }
  }
  if (!MakeFolders(options.output_dir, error)) return false;
  std::vector<PlateOutcome> outcomes(plates.size());
  const int threads = options.threads > 0
                          ? options.threads
                          : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  internal::ParallelFor(plates.size(), threads, [&](size_t i) {
    try {
      RunPlate(plates[i], config, options.output_dir, &outcomes[i]);
    } catch (const std::exception& e) {
      outcomes[i] = PlateOutcome();
      FailPlate(plates[i], config, std::string("failed: ") + e.what(), &outcomes[i]);
    }
  });
  PlateBatchSummary s;
  s.plates = plates.size();
  std::vector<std::string> ids;
  for (PlateOutcome& o : outcomes) {
    s.failed_plates += o.failed;
    for (SummaryRow& row : o.rows) {
      row.index = s.rows.size();
      ids.push_back(row.unit);
      s.rows.push_back(std::move(row));
    }
    s.units.insert(s.units.end(), o.units.begin(), o.units.end());
    s.warnings.insert(s.warnings.end(), o.warnings.begin(), o.warnings.end());
  }
  FleetInfo info;
  info.fleet = FleetHash(ids);
  std::string config_bytes;
  if (!ReadFileBytes(config_path, &config_bytes, error)) return false;
  internal::ContentHash hash;
  hash.Add(GravcalVersion());
  hash.Add(config_bytes);
  info.config = hash.Hex();
  info.units_in_fleet = s.rows.size();
  if (!ComputeFleetStatistics(s.rows, info, options.fleet, &s.statistics, error)) return false;
  if (!WriteFilesAtomically(
          {{options.output_dir + "/summary.csv", SummaryToCsv(s.rows)},
           {options.output_dir + "/summary.json", FleetStatisticsToJson(s.statistics)}},
          error)) {
    return false;
  }
  *summary = std::move(s);
  return true;
}

}  // namespace gravcal
