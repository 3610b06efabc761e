// The gravcal command-line tool's commands. Each returns the process exit
// code: 0 success, 1 bad input or configuration, 2 the calibration failed.
#ifndef GRAVCAL_SRC_CLI_COMMANDS_H_
#define GRAVCAL_SRC_CLI_COMMANDS_H_

#include <string>
#include <vector>

#include "gravcal/io/calibration_io.h"
#include "gravcal/workflows/config.h"
#include "gravcal/workflows/plan.h"

namespace gravcal {
namespace cli {

struct CommandArgs {
  Config config;
  std::string input;
  std::string output;
  std::string output_dir;
  std::string calibration;
  std::string config_path;
  // Side inputs of the methods that need them (method_registry.h): the
  // attitudes CSV, the rate table's segments CSV.
  std::string attitudes;
  std::string segments;
  // calibrate: the time history CSV of recursive methods (--history).
  std::string history;
  // calibrate, batch, noise, discover: the HTML report to write (optional).
  std::string report;
  // noise: Kalibr's imu.yaml and the handheld filter's keys (optional).
  std::string kalibr;
  std::string handheld;
  // calibrate: the noise model from gravcal noise (--noise).
  std::string noise;
  // export: the target (--to).
  std::string to;
  uint64_t seed = 1;
  // batch and merge-summaries.
  std::string manifest;
  std::string input_dir;
  std::string pattern = "*.csv";
  int threads = 0;
  // K/N, auto or auto/N (batch_scheduler_shard.h).
  std::string shard;
  // batch: seconds one unit may take; 0 = no limit.
  double unit_timeout = 0.0;
  double outlier_sigmas = 5.0;
  int outlier_min_units = 5;
  // plan and check: the request from --target, --pose_set, ... (not the
  // noise model, which --noise names); simulate: --plan.
  PlanRequest plan_request;
  std::string plan;
  // calibrate: add the check section (what the session lacks, --check).
  bool check = false;
  // Arguments that are not flags (merge-summaries: the shard folders).
  std::vector<std::string> positional;
  // batch: "all" makes one unit per sensor_msgs/Imu topic of --input.
  std::string topics;
};

int RunDemo(const CommandArgs& args);
int RunCalibrate(const CommandArgs& args);
int RunApply(const CommandArgs& args);
int RunSimulate(const CommandArgs& args);
// batch_command.cc. Exit codes: 0 every unit calibrated; 1 bad invocation
// or manifest (nothing written), or at least one unit failed as calibrate
// would with exit 1; 2 the only failures are units that did not converge.
int RunBatch(const CommandArgs& args);
// 0 merged; 1 bad input (nothing written).
int RunMergeSummaries(const CommandArgs& args);
int RunDiscover(const CommandArgs& args);
// noise_command.cc: 0 written; 1 bad input (nothing written).
int RunNoise(const CommandArgs& args);
// inspect_command.cc: 0 the file was read; 1 it cannot be.
int RunInspect(const CommandArgs& args);
// apply_command.cc: 0 written; 1 bad input (no output file).
// export_command.cc: 0 written; 1 bad input or a target that cannot take the
// calibration (nothing written).
int RunExport(const CommandArgs& args);

// plan_command.cc: 0 written; 1 bad input, unmet targets (nothing written).
int RunPlan(const CommandArgs& args);
// 0 reported; 1 bad input.
int RunCheck(const CommandArgs& args);
// Issue 15: calibrate's "check" section (what the session lacks, as gravcal
// check says it) with --check, for the methods of the magnitude model;
// prints the text on stderr. Empty without --check, when the method has
// none or when the check cannot be made.
JsonSections CalibrationCheckSections(const CommandArgs& args, const Session& session);

// destinations.cc: the command's destinations checked against the
// destination contract (io/files.h) before it runs: false with a one-line
// message naming the destination.
bool CheckCommandDestinations(const std::string& command, const CommandArgs& args,
                              std::string* error);
// Writes `text` to `path` atomically, or to standard output for "-" (the
// outputs CheckCommandDestinations lets stream).
bool WriteOutput(const std::string& path, const std::string& text, std::string* error);

// Prints "gravcal: error: <message>" on stderr and returns `code`.
int Fail(const std::string& message, int code = 1);

}  // namespace cli
}  // namespace gravcal

#endif  // GRAVCAL_SRC_CLI_COMMANDS_H_
