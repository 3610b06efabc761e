// The gravcal command-line tool's commands. Each returns the process exit
// code: 0 success, 1 bad input or configuration, 2 the calibration failed.
#ifndef GRAVCAL_SRC_CLI_COMMANDS_H_
#define GRAVCAL_SRC_CLI_COMMANDS_H_

#include <optional>
#include <string>
#include <vector>

#include "gravcal/estimation/calibration_comparison.h"
#include "gravcal/io/calibration_export.h"
#include "gravcal/io/calibration_io.h"
#include "gravcal/methods/session.h"
#include "gravcal/workflows/acceptance.h"
#include "gravcal/workflows/config.h"
#include "gravcal/workflows/plan.h"

namespace gravcal {
namespace cli {

// What every command gets: the config (--config, then config keys given as
// flags) and the arguments that are not flags.
struct CommonArgs {
  Config config;
  std::string config_path;
  // merge-summaries: the shard folders; compare: the two calibrations;
  // history: the unit.
  std::vector<std::string> positional;
};

// Each command's own flags (main.cc binds each flag of the table in flags.h
// to a field here). Paths are empty when the flag is not given.
struct DemoArgs : CommonArgs {
  uint64_t seed = 1;
};

struct CalibrateArgs : CommonArgs {
  std::string input;
  std::string output;
  // Side inputs of the methods that need them (method_registry.h).
  std::string attitudes;
  std::string segments;
  // The time history CSV of recursive methods.
  std::string history;
  // The noise model from gravcal noise.
  std::string noise;
  std::string report;
  // Add the check section (what the session lacks).
  bool check = false;
  // Issue 36: acceptance limits (YAML), the certificate's path prefix
  // (<prefix>.json, <prefix>.html), the unit's name (default: the log's
  // name) and the calibration store to file the result in.
  std::string limits;
  std::string certificate;
  std::string unit;
  std::string store;
  // Issue 38: the folder of a multi-IMU config's outputs.
  std::string output_dir;
};

// apply and export: the calibration by file (--calibration) or, with
// --store and --unit, the unit's stored calibration closest to --at.
struct StoredCalibrationArgs {
  std::string store;
  std::string unit;
  std::string at;
  double max_age_days = 0.0;
};

struct ApplyArgs : CommonArgs {
  std::string calibration;
  std::string input;
  std::string output;
  StoredCalibrationArgs stored;
};

struct SimulateArgs : CommonArgs {
  uint64_t seed = 1;
  std::string output_dir;
  // plan.json from gravcal plan.
  std::string plan;
  // Issue 37: --stream - (standard output) or pty (a new pseudo-terminal)
  // writes a virtual hand's session as contract CSV lines at --rate times
  // real time (0 = as fast as it can), following the suggest events of
  // --follow-events (gravcal record --events) when given.
  std::string stream;
  double rate = 0.0;
  std::string follow_events;
};

// Issue 37: gravcal record (record_command.cc).
struct RecordArgs : CommonArgs {
  std::string input;
  int baud = 0;
  std::string output_dir;
  std::string events;
  std::string noise;
  PlanRequest request;
};

// plan and check: the request from --target, --pose_set, ... (not the noise
// model, which --noise names).
struct PlanArgs : CommonArgs {
  std::string input;
  std::string output;
  std::string noise;
  std::string report;
  PlanRequest request;
  // plan --verify (issue 36): the stored calibration to design a check
  // session for, and the test's significance level.
  std::string verify_calibration;
  double level = 0.01;
};

struct BatchArgs : CommonArgs {
  std::string manifest;
  std::string input_dir;
  std::string pattern = "*.csv";
  // A bag with --topics all: one unit per sensor_msgs/Imu topic.
  std::string input;
  std::string topics;
  std::string output_dir;
  std::string report;
  int threads = 0;
  // K/N, auto or auto/N (batch_scheduler_shard.h).
  std::string shard;
  // Seconds one unit may take; 0 = no limit.
  double unit_timeout = 0.0;
  double outlier_sigmas = 5.0;
  int outlier_min_units = 5;
  // Acceptance limits (YAML, issue 36): each calibrated unit against them;
  // the certificates' folder and the calibration store.
  std::string limits;
  std::string certificate;
  std::string store;
};

// discover and noise.
struct LogReportArgs : CommonArgs {
  std::string input;
  std::string output;
  std::string report;
  // noise: Kalibr's imu.yaml and the handheld filter's keys.
  std::string kalibr;
  std::string handheld;
  // noise: the datasheet's white-noise densities to compare with (0 = none).
  double accel_noise_density = 0.0;
  double gyro_noise_density = 0.0;
};

struct InspectArgs : CommonArgs {
  std::string input;
};

struct ExportArgs : CommonArgs {
  std::string calibration;
  std::string noise;
  // The target (--to; none when not given).
  std::optional<ExportTarget> to;
  std::string output;
  std::string output_dir;
  StoredCalibrationArgs stored;
  // px4 with a thermal model: the device ids TC_A0_ID / TC_G0_ID get.
  uint64_t accel_device_id = 0;
  uint64_t gyro_device_id = 0;
  bool drop_thermal = false;
  int ardupilot_imu = 1;
};

// compare a.json b.json (the two calibrations are the positional
// arguments); --input: the difference in corrected output over that log.
struct CompareArgs : CommonArgs {
  std::string input;
  std::string output;
  // The test's significance level.
  double level = 0.01;
  // The parameters compared.
  ComparisonSpace space = ComparisonSpace::kModel;
};

// verify: a short check session (--input) against a stored calibration.
struct VerifyArgs : CommonArgs {
  std::string calibration;
  std::string input;
  std::string output;
  double level = 0.01;
};

// history UNIT (positional) --store DIR.
struct HistoryArgs : CommonArgs {
  std::string store;
  std::string output;
  // The HTML page: each parameter against the date with its sigma bars.
  std::string report;
  double level = 0.01;
};

int RunDemo(const DemoArgs& args);
int RunCalibrate(const CalibrateArgs& args);
int RunApply(const ApplyArgs& args);
int RunSimulate(const SimulateArgs& args);
// simulate --stream (simulate_stream.cc): 0 streamed, 1 bad input.
int RunSimulateStream(const SimulateArgs& args);
// record_command.cc: 0 written with a calibration, 2 the log and report
// written but the calibration failed, 1 bad input (nothing written).
int RunRecord(const RecordArgs& args);
// batch_command.cc. Exit codes: 0 every unit calibrated; 1 bad invocation
// or manifest (nothing written), or at least one unit failed as calibrate
// would with exit 1; 2 the only failures are units that did not converge.
int RunBatch(const BatchArgs& args);
// 0 merged; 1 bad input (nothing written).
int RunMergeSummaries(const BatchArgs& args);
int RunDiscover(const LogReportArgs& args);
// noise_command.cc: 0 written; 1 bad input (nothing written).
int RunNoise(const LogReportArgs& args);
// inspect_command.cc: 0 the file was read; 1 it cannot be.
int RunInspect(const InspectArgs& args);
// apply_command.cc: 0 written; 1 bad input (no output file).
// export_command.cc: 0 written; 1 bad input or a target that cannot take the
// calibration (nothing written).
int RunExport(const ExportArgs& args);

// compare_command.cc (issue 36): 0 consistent, 3 changed, 1 bad input or
// nothing to test (nothing written).
int RunCompare(const CompareArgs& args);
int RunVerify(const VerifyArgs& args);
// plan --verify cal.json: the shortest check session (0 designed, 1 bad
// input).
int RunPlanVerify(const PlanArgs& args);
// acceptance_command.cc: calibrate's and batch's --limits, and calibrate's
// --certificate and --store. The check before any work (the limits file,
// when given, parses), and after the calibration is written: 0, 4 when a
// limit fails, 1 on an error.
bool CheckLimitsFile(const std::string& limits, std::string* error);
int FinishAcceptance(const CalibrateArgs& args, const Calibration& calibration,
                     const AcceptanceLimits* limits);
// batch --limits: each calibrated unit's <output-dir>/<unit>.json against
// the limits, <output-dir>/limits.csv (unit, verdict, failed), the count and
// the failing units named on stderr; returns `code` when it is not 0, else 4
// when a unit fails.
int FinishBatchAcceptance(const BatchArgs& args,
                          const std::vector<std::pair<std::string, std::string>>& units, int code);
// The calibration file apply and export use: --calibration, or the unit's
// stored calibration closest to --at (said on standard error, with a warning
// when older than --max-age-days). False with a one-line message.
bool ResolveCalibrationPath(const std::string& calibration, const StoredCalibrationArgs& stored,
                            std::string* path, std::string* error);
// history_command.cc: 0 listed; 1 bad input.
int RunHistory(const HistoryArgs& args);

// plan_command.cc: 0 written; 1 bad input, unmet targets (nothing written).
int RunPlan(const PlanArgs& args);
// 0 reported; 1 bad input.
int RunCheck(const PlanArgs& args);
// Issue 15: calibrate's "check" section (what the session lacks, as gravcal
// check says it) with --check, for the methods of the magnitude model;
// prints the text on stderr. Empty without --check, when the method has
// none or when the check cannot be made. pose_disturbance: the per-pose
// scatter the calibration estimated and carried in its sigmas (m/s^2; 0 =
// none), so that the check predicts the sigmas the calibration reports.
JsonSections CalibrationCheckSections(const CalibrateArgs& args, const Session& session,
                                      double pose_disturbance);

// destinations.cc: the command's destinations checked against the
// destination contract (io/files.h) before it runs: false with a one-line
// message naming the destination. The CommonArgs form checks the config
// and the gyroscope file it names (commands that write nothing).
bool CheckCommandDestinations(const CommonArgs& args, std::string* error);
bool CheckCommandDestinations(const CalibrateArgs& args, std::string* error);
bool CheckCommandDestinations(const ApplyArgs& args, std::string* error);
bool CheckCommandDestinations(const SimulateArgs& args, std::string* error);
// plan (check writes nothing: its --output is empty).
bool CheckCommandDestinations(const PlanArgs& args, std::string* error);
// batch, and merge-summaries (positional shard folders).
bool CheckCommandDestinations(const BatchArgs& args, std::string* error);
// discover and noise.
bool CheckCommandDestinations(const LogReportArgs& args, std::string* error);
bool CheckCommandDestinations(const ExportArgs& args, std::string* error);
bool CheckCommandDestinations(const CompareArgs& args, std::string* error);
bool CheckCommandDestinations(const VerifyArgs& args, std::string* error);
bool CheckCommandDestinations(const HistoryArgs& args, std::string* error);
// Writes `text` to `path` atomically, or to standard output for "-" (the
// outputs CheckCommandDestinations lets stream).
bool WriteOutput(const std::string& path, const std::string& text, std::string* error);

// Prints "gravcal: error: <message>" on stderr and returns `code`.
int Fail(const std::string& message, int code = 1);

// calibrate with a multi-IMU config (multi_imu_command.cc; issue 38).
int RunMultiImuCalibrate(const std::string& config_path, const std::string& input,
                         const std::string& output_dir, const std::string& report,
                         bool has_overrides);

// batch and simulate with a multi-IMU config (plate_commands.cc).
int RunPlateBatch(const BatchArgs& args);
int RunPlateSimulate(const SimulateArgs& args);

}  // namespace cli
}  // namespace gravcal

#endif  // GRAVCAL_SRC_CLI_COMMANDS_H_
