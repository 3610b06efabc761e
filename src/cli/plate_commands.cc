// gravcal batch and gravcal simulate with a multi-IMU config
// (configs/multi_imu.yaml, issue 38): a batch of plates, one summary row
// per IMU; a simulated plate as one table with its truth.
#include <cstdio>
#include <string>

#include "cli/commands.h"
#include "gravcal/io/files.h"
#include "gravcal/simulation/plate_simulator.h"
#include "gravcal/workflows/batch_folder.h"
#include "gravcal/workflows/multi_imu_batch.h"
#include "gravcal/workflows/multi_imu_log.h"

namespace gravcal {
namespace cli {

int RunPlateBatch(const BatchArgs& args) {
  if (args.output_dir.empty()) return Fail("batch needs --output-dir <folder>");
  if (args.manifest.empty() == args.input_dir.empty()) {
    return Fail(
        "a batch of plates (a multi-IMU config) needs either --manifest <plates.csv> or "
        "--input-dir <folder>: each file one plate");
  }
  if (!args.shard.empty() || !args.topics.empty() || args.unit_timeout != 0.0 ||
      !args.report.empty()) {
    return Fail(
        "a batch of plates (a multi-IMU config) takes no --shard, --topics, --unit_timeout "
        "or --report yet");
  }
  std::string error;
  if (!CheckLimitsFile(args.limits, &error)) return Fail(error);
  BatchSource source;
  source.manifest = args.manifest;
  source.input_dir = args.input_dir;
  source.pattern = args.pattern;
  BatchFolderOptions list_options;
  list_options.output_dir = args.output_dir;
  BatchFolderUnits plates;
  if (!ListBatchFolderUnits(source, Config(), list_options, &plates, &error)) return Fail(error);
  PlateBatchOptions options;
  options.output_dir = args.output_dir;
  options.fleet.outlier_sigmas = args.outlier_sigmas;
  options.fleet.min_units = args.outlier_min_units;
  options.threads = args.threads;
  PlateBatchSummary summary;
  if (!CalibratePlateBatch(plates.units, args.config_path, options, &summary, &error)) {
    return Fail(error);
  }
  for (const std::string& w : summary.warnings) {
    std::fprintf(stderr, "gravcal: warning: %s\n", w.c_str());
  }
  const std::string findings = FleetFindingsText(summary.statistics);
  size_t begin = 0;
  while (begin < findings.size()) {
    const size_t end = findings.find('\n', begin);
    std::fprintf(stderr, "gravcal: %s\n", findings.substr(begin, end - begin).c_str());
    if (end == std::string::npos) break;
    begin = end + 1;
  }
  const FleetStatistics& s = summary.statistics;
  std::fprintf(stderr,
               "gravcal: batch of %zu plates (%zu failed): %zu units, %zu ok, %zu failed; wrote "
               "%s/<plate>.<imu>.json, <plate>/assembly.json, summary.csv and summary.json\n",
               summary.plates, summary.failed_plates, s.units, s.ok, s.failed + s.not_converged,
               args.output_dir.c_str());
  const int code = s.failed + s.not_converged > 0
                       ? Fail(std::to_string(s.failed + s.not_converged) + " of " +
                              std::to_string(s.units) + " units failed; summary.json lists them")
                       : 0;
  return FinishBatchAcceptance(args, summary.units, code);
}

int RunPlateSimulate(const SimulateArgs& args) {
  if (args.output_dir.empty()) return Fail("simulate needs --output-dir <folder>");
  if (!args.stream.empty() || !args.plan.empty() || args.rate != 0.0 ||
      !args.follow_events.empty()) {
    return Fail("simulate with a multi-IMU config takes --seed and --output-dir only");
  }
  std::string error;
  MultiImuConfig config;
  if (!LoadMultiImuConfig(args.config_path, &config, &error)) return Fail(error);
  if (!config.auto_imus) {
    return Fail(args.config_path +
                ": simulate writes the columns imu0.ax .. imu<N-1>.gz: give a config with "
                "imus: auto");
  }
  const bool counts = config.simulation.imu.raw_counts;
  if (!counts && (config.default_accel_scale != 1.0 || config.default_gyro_scale != 1.0)) {
    return Fail(args.config_path +
                ": simulate writes raw counts (accel_units and gyro_units: counts) or SI "
                "(m/s^2 and rad/s), not these units");
  }
  SimulatedPlate plate;
  if (!SimulatePlate(config.simulation, args.seed, &plate, &error)) {
    return Fail(args.config_path + ": " + error);
  }
  if (!MakeFolders(args.output_dir, &error)) return Fail(error);
  const std::string table = args.output_dir + "/plate.csv";
  const std::string truth = args.output_dir + "/truth.json";
  if (!WriteFilesAtomically({{table, PlateToCsv(plate)}, {truth, PlateTruthToJson(plate)}},
                            &error)) {
    return Fail(error);
  }
  std::fprintf(stderr, "gravcal: wrote %s (%zu IMUs, %zu samples, %s) and %s\n", table.c_str(),
               plate.logs.size(), plate.logs.empty() ? size_t{0} : plate.logs[0].size(),
               counts ? "raw counts" : "m/s^2 and rad/s", truth.c_str());
  return 0;
}

}  // namespace cli
}  // namespace gravcal
