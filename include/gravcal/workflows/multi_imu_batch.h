// gravcal/workflows/multi_imu_batch.h: a batch of plates (issue 38). Each
// unit of the batch (a file of --input-dir or a manifest row) is one
// multi-IMU session, calibrated as `calibrate --config <multi-IMU config>
// --output-dir` does. Each IMU is a unit "<plate>.<imu>" with its
// calibration in <output_dir>/<plate>.<imu>.json (the batch folder's
// <unit>.json, so limits, certificates and the store take it as any unit);
// the plate's assembly.json, Kalibr chain and PX4 rotations are in
// <output_dir>/<plate>/. The summary has one row per IMU, so the fleet
// statistics count units, not plates. Each row also has the IMU's time
// offset to its plate's reference and the rotation's sigma.
//
// A plate that cannot be calibrated fails every IMU the config lists (one
// row each), or one row named after the plate when the IMUs come from the
// table's header (imus: auto) and the table cannot be read.
#ifndef GRAVCAL_WORKFLOWS_MULTI_IMU_BATCH_H_
#define GRAVCAL_WORKFLOWS_MULTI_IMU_BATCH_H_

#include <string>
#include <utility>
#include <vector>

#include "gravcal/workflows/batch.h"
#include "gravcal/workflows/fleet_summary.h"

namespace gravcal {

struct PlateBatchOptions {
  // The folder to write into (created if missing).
  std::string output_dir;
  FleetOptions fleet;
  // Worker threads over the plates; 0 = one per core.
  int threads = 0;

  bool IsValid(std::string* error) const;
};

struct PlateBatchSummary {
  size_t plates = 0;
  size_t failed_plates = 0;
  // One per IMU (or per unreadable plate), in plate order then IMU order.
  std::vector<SummaryRow> rows;
  FleetStatistics statistics;
  // Each calibrated IMU: its unit id "<plate>.<imu>" and its plate's path.
  std::vector<std::pair<std::string, std::string>> units;
  // "<plate>: <warning>" for every named mistake of every plate.
  std::vector<std::string> warnings;
};

// Calibrates every plate in `plates` (BatchUnit::path, ::id; per-unit
// config overrides are refused) with the multi-IMU config at config_path,
// then writes summary.csv and summary.json (fleet_summary.h) into
// options.output_dir. False with one line for a bad config, options or an
// unwritable folder; a plate's failure is in its rows.
bool CalibratePlateBatch(const std::vector<BatchUnit>& plates, const std::string& config_path,
                         const PlateBatchOptions& options, PlateBatchSummary* summary,
                         std::string* error);

}  // namespace gravcal

#endif  // GRAVCAL_WORKFLOWS_MULTI_IMU_BATCH_H_
