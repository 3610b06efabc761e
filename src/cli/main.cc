// gravcal: command-line front end. The only place with gflags and
// InitGoogleLogging.
//
// Config keys (config.h) can be given as flags of the same name; they are
// taken out of argv here and applied on top of --config, and the rest goes to
// gflags.
#include <ceres/version.h>
#include <gflags/gflags.h>
#include <glog/logging.h>

#include <Eigen/Core>
#include <cstdio>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "cli/flags.h"
#include "gravcal/workflows/batch.h"
#include "gravcal/workflows/config.h"
#include "gravcal/workflows/fleet_summary.h"
#include "gravcal/workflows/method_registry.h"
#include "gravcal/workflows/multi_imu_log.h"

namespace gravcal {
namespace cli {
namespace {

struct CommandInfo {
  const char* name;
  const char* summary;
  // The flags it takes, in help's order.
  std::vector<const char*> flags;
  // Fills the command's args from the parsed flags and `common`, checks its
  // destinations and runs it. Empty for help, which main handles before
  // parsing flags.
  std::function<int(CommonArgs common)> run;
  // Takes arguments that are not flags (merge-summaries: the shard folders).
  bool positional = false;
  // Reads the config: takes config keys as flags (--gravity 9.81).
  bool config_keys = true;
  // For each flag, the names it accepts (an enum flag's,
  // FlagBinding::accepted; empty for others).
  std::vector<std::string> accepted;
};

// A command whose flags fill Args (commands.h) and that runs as `run`.
template <typename Args>
CommandInfo Command(const char* name, const char* summary, std::vector<FlagBinding<Args>> bindings,
                    int (*run)(const Args&), bool positional = false, bool config_keys = true) {
  CommandInfo info{name, summary, {}, nullptr, positional, config_keys, {}};
  for (const FlagBinding<Args>& b : bindings) {
    info.flags.push_back(b.name);
    info.accepted.push_back(b.accepted);
  }
  info.run = [bindings, run](CommonArgs common) {
    Args args;
    static_cast<CommonArgs&>(args) = std::move(common);
    std::string error;
    for (const FlagBinding<Args>& b : bindings) {
      if (!b.set(FlagText(b.name), &args, &error)) return Fail(error);
    }
    if (!CheckCommandDestinations(args, &error)) return Fail(error);
    return run(args);
  };
  return info;
}

// --config, for every command that reads a config file.
template <typename Args>
FlagBinding<Args> ConfigFlag() {
  return FlagField<Args>("config", &CommonArgs::config_path);
}

// apply's and export's --store, --unit, --at, --max-age-days.
template <typename Args, typename T>
FlagBinding<Args> StoredFlag(const char* name, T StoredCalibrationArgs::*field) {
  return FlagAt<Args>(name, [field](Args* a) { return &(a->stored.*field); });
}

// The flags of plan and check that fill the plan request.
template <typename T>
FlagBinding<PlanArgs> RequestFlag(const char* name, T gravcal::PlanRequest::*field) {
  return FlagAt<PlanArgs>(name, [field](PlanArgs* a) { return &(a->request.*field); });
}

const std::vector<CommandInfo>& Commands() {
  using gravcal::PlanRequest;
  static const std::vector<CommandInfo> commands = {
      Command<DemoArgs>(
          "demo",
          "simulate a twelve-position session in raw counts, calibrate it, print estimate vs "
          "truth",
          {ConfigFlag<DemoArgs>(), FlagField<DemoArgs>("seed", &DemoArgs::seed)}, RunDemo),
      Command<CalibrateArgs>(
          "calibrate",
          "calibrate the sensors from a log with the config's method (the config key 'method' "
          "lists them)",
          {FlagField<CalibrateArgs>("input", &CalibrateArgs::input), ConfigFlag<CalibrateArgs>(),
           FlagField<CalibrateArgs>("output", &CalibrateArgs::output),
           FlagField<CalibrateArgs>("attitudes", &CalibrateArgs::attitudes),
           FlagField<CalibrateArgs>("segments", &CalibrateArgs::segments),
           FlagField<CalibrateArgs>("history", &CalibrateArgs::history),
           FlagField<CalibrateArgs>("noise", &CalibrateArgs::noise),
           FlagField<CalibrateArgs>("report", &CalibrateArgs::report),
           FlagField<CalibrateArgs>("check", &CalibrateArgs::check),
           FlagField<CalibrateArgs>("limits", &CalibrateArgs::limits),
           FlagField<CalibrateArgs>("certificate", &CalibrateArgs::certificate),
           FlagField<CalibrateArgs>("unit", &CalibrateArgs::unit),
           FlagField<CalibrateArgs>("store", &CalibrateArgs::store),
           FlagField<CalibrateArgs>("output_dir", &CalibrateArgs::output_dir)},
          RunCalibrate),
      Command<ApplyArgs>(
          "apply",
          "apply every term of a calibration to a contract CSV log (streaming; - for standard "
          "input/output), writing SI units",
          {FlagField<ApplyArgs>("calibration", &ApplyArgs::calibration),
           FlagField<ApplyArgs>("input", &ApplyArgs::input),
           FlagField<ApplyArgs>("output", &ApplyArgs::output), ConfigFlag<ApplyArgs>(),
           StoredFlag<ApplyArgs>("store", &StoredCalibrationArgs::store),
           StoredFlag<ApplyArgs>("unit", &StoredCalibrationArgs::unit),
           StoredFlag<ApplyArgs>("at", &StoredCalibrationArgs::at),
           StoredFlag<ApplyArgs>("max_age_days", &StoredCalibrationArgs::max_age_days)},
          RunApply),
      Command<SimulateArgs>(
          "simulate",
          "simulate a session: raw.csv, truth.json, the fixture's attitudes.csv (and, for "
          "sim_motion rate_table, segments.csv)",
          {ConfigFlag<SimulateArgs>(), FlagField<SimulateArgs>("seed", &SimulateArgs::seed),
           FlagField<SimulateArgs>("output_dir", &SimulateArgs::output_dir),
           FlagField<SimulateArgs>("plan", &SimulateArgs::plan),
           FlagField<SimulateArgs>("stream", &SimulateArgs::stream),
           FlagField<SimulateArgs>("rate", &SimulateArgs::rate),
           FlagField<SimulateArgs>("follow_events", &SimulateArgs::follow_events)},
          RunSimulate),
      Command<RecordArgs>(
          "record",
          "guided live calibration: reads a sensor's text lines (-, serial device, udp://:PORT, "
          "tcp://HOST:PORT), says which pose to take next, stops when --target is met; writes "
          "record.csv, calibration.json and report.html to --output-dir",
          {FlagField<RecordArgs>("input", &RecordArgs::input),
           FlagField<RecordArgs>("baud", &RecordArgs::baud), ConfigFlag<RecordArgs>(),
           FlagField<RecordArgs>("output_dir", &RecordArgs::output_dir),
           FlagField<RecordArgs>("events", &RecordArgs::events),
           FlagField<RecordArgs>("noise", &RecordArgs::noise),
           FlagAt<RecordArgs>("target", [](RecordArgs* a) { return &a->request.targets; }),
           FlagAt<RecordArgs>("pose_set", [](RecordArgs* a) { return &a->request.pose_set; }),
           FlagAt<RecordArgs>("max_time",
                              [](RecordArgs* a) { return &a->request.max_time_seconds; }),
           FlagAt<RecordArgs>("accel_noise_density",
                              [](RecordArgs* a) { return &a->request.accel_noise_density; }),
           FlagAt<RecordArgs>("pose_disturbance",
                              [](RecordArgs* a) { return &a->request.pose_disturbance; })},
          RunRecord),
      Command<PlanArgs>(
          "plan",
          "plan a recording before it is made: plan.json with the poses, holds and predicted "
          "sigmas (least time meeting --target, or best within --max_time)",
          {ConfigFlag<PlanArgs>(),
           FlagField<PlanArgs>("output", &PlanArgs::output),
           FlagField<PlanArgs>("noise", &PlanArgs::noise),
           RequestFlag("target", &PlanRequest::targets),
           RequestFlag("pose_set", &PlanRequest::pose_set),
           RequestFlag("candidates", &PlanRequest::free_candidates),
           RequestFlag("max_time", &PlanRequest::max_time_seconds),
           RequestFlag("overhead", &PlanRequest::overhead_seconds),
           RequestFlag("min_hold", &PlanRequest::min_hold_seconds),
           RequestFlag("max_hold", &PlanRequest::max_hold_seconds),
           RequestFlag("accel_noise_density", &PlanRequest::accel_noise_density),
           RequestFlag("accel_bias_instability", &PlanRequest::accel_bias_instability),
           RequestFlag("accel_random_walk", &PlanRequest::accel_random_walk),
           RequestFlag("pose_disturbance", &PlanRequest::pose_disturbance),
           FlagField<PlanArgs>("report", &PlanArgs::report),
           RequestFlag("gyro_noise_density", &PlanRequest::gyro_noise_density),
           RequestFlag("turn_seconds", &PlanRequest::turn_seconds),
           RequestFlag("attitude_std", &PlanRequest::attitude_std_deg),
           FlagField<PlanArgs>("verify", &PlanArgs::verify_calibration),
           FlagField<PlanArgs>("level", &PlanArgs::level)},
          RunPlan),
      Command<PlanArgs>(
          "check",
          "what a recorded session determines: predicted sigma per parameter, what is "
          "undetermined or short of --target, and the extra poses that would help most",
          {FlagField<PlanArgs>("input", &PlanArgs::input), ConfigFlag<PlanArgs>(),
           FlagField<PlanArgs>("noise", &PlanArgs::noise),
           RequestFlag("target", &PlanRequest::targets),
           RequestFlag("pose_set", &PlanRequest::pose_set),
           RequestFlag("candidates", &PlanRequest::free_candidates),
           RequestFlag("accel_noise_density", &PlanRequest::accel_noise_density),
           RequestFlag("accel_bias_instability", &PlanRequest::accel_bias_instability),
           RequestFlag("accel_random_walk", &PlanRequest::accel_random_walk),
           RequestFlag("pose_disturbance", &PlanRequest::pose_disturbance)},
          RunCheck),
      Command<BatchArgs>(
          "batch",
          "calibrate many units in parallel: <unit>.json, summary.csv, summary.json (fleet "
          "statistics)",
          {FlagField<BatchArgs>("manifest", &BatchArgs::manifest),
           FlagField<BatchArgs>("input_dir", &BatchArgs::input_dir),
           FlagField<BatchArgs>("pattern", &BatchArgs::pattern), ConfigFlag<BatchArgs>(),
           FlagField<BatchArgs>("output_dir", &BatchArgs::output_dir),
           FlagField<BatchArgs>("threads", &BatchArgs::threads),
           FlagField<BatchArgs>("shard", &BatchArgs::shard),
           FlagField<BatchArgs>("outlier_sigmas", &BatchArgs::outlier_sigmas),
           FlagField<BatchArgs>("outlier_min_units", &BatchArgs::outlier_min_units),
           FlagField<BatchArgs>("input", &BatchArgs::input),
           FlagField<BatchArgs>("topics", &BatchArgs::topics),
           FlagField<BatchArgs>("report", &BatchArgs::report),
           FlagField<BatchArgs>("unit_timeout", &BatchArgs::unit_timeout),
           FlagField<BatchArgs>("limits", &BatchArgs::limits),
           FlagField<BatchArgs>("certificate", &BatchArgs::certificate),
           FlagField<BatchArgs>("store", &BatchArgs::store)},
          RunBatch),
      Command<BatchArgs>(
          "merge-summaries",
          "merge the summaries of a batch's shards: gravcal merge-summaries --output-dir merged/ "
          "shard1/ shard2/ ...",
          {FlagField<BatchArgs>("output_dir", &BatchArgs::output_dir),
           FlagField<BatchArgs>("outlier_sigmas", &BatchArgs::outlier_sigmas),
           FlagField<BatchArgs>("outlier_min_units", &BatchArgs::outlier_min_units)},
          RunMergeSummaries, true, false),
      Command<LogReportArgs>(
          "discover", "find the effects the model misses: discovery.json and an HTML report",
          {FlagField<LogReportArgs>("input", &LogReportArgs::input), ConfigFlag<LogReportArgs>(),
           FlagField<LogReportArgs>("output", &LogReportArgs::output),
           FlagField<LogReportArgs>("report", &LogReportArgs::report)},
          RunDiscover),
      Command<LogReportArgs>(
          "noise",
          "the noise model of a still log (Allan deviation: N, B, K per axis): noise.json, and "
          "Kalibr's imu.yaml",
          {FlagField<LogReportArgs>("input", &LogReportArgs::input), ConfigFlag<LogReportArgs>(),
           FlagField<LogReportArgs>("output", &LogReportArgs::output),
           FlagField<LogReportArgs>("kalibr", &LogReportArgs::kalibr),
           FlagField<LogReportArgs>("handheld", &LogReportArgs::handheld),
           FlagField<LogReportArgs>("report", &LogReportArgs::report),
           FlagField<LogReportArgs>("accel_noise_density", &LogReportArgs::accel_noise_density),
           FlagField<LogReportArgs>("gyro_noise_density", &LogReportArgs::gyro_noise_density)},
          RunNoise),
      Command<InspectArgs>(
          "inspect",
          "what a log file holds: format, topics and types, message counts, rates, time span, "
          "gaps",
          {FlagField<InspectArgs>("input", &InspectArgs::input), ConfigFlag<InspectArgs>()},
          RunInspect),
      Command<ExportArgs>(
          "export",
          "write a calibration for kalibr, openvins, ros, px4, ardupilot or as C source (c)",
          {FlagField<ExportArgs>("calibration", &ExportArgs::calibration),
           FlagField<ExportArgs>("noise", &ExportArgs::noise),
           FlagField<ExportArgs>("to", &ExportArgs::to),
           FlagField<ExportArgs>("output", &ExportArgs::output),
           FlagField<ExportArgs>("output_dir", &ExportArgs::output_dir),
           StoredFlag<ExportArgs>("store", &StoredCalibrationArgs::store),
           StoredFlag<ExportArgs>("unit", &StoredCalibrationArgs::unit),
           StoredFlag<ExportArgs>("at", &StoredCalibrationArgs::at),
           StoredFlag<ExportArgs>("max_age_days", &StoredCalibrationArgs::max_age_days),
           FlagField<ExportArgs>("accel_device_id", &ExportArgs::accel_device_id),
           FlagField<ExportArgs>("gyro_device_id", &ExportArgs::gyro_device_id),
           FlagField<ExportArgs>("drop_thermal", &ExportArgs::drop_thermal),
           FlagField<ExportArgs>("ardupilot_imu", &ExportArgs::ardupilot_imu)},
          RunExport),
      Command<CompareArgs>(
          "compare",
          "are two calibrations of the same unchanged unit? per-parameter z, joint test; exit 3 "
          "when not: gravcal compare a.json b.json",
          {FlagField<CompareArgs>("level", &CompareArgs::level),
           FlagField<CompareArgs>("space", &CompareArgs::space),
           FlagField<CompareArgs>("output", &CompareArgs::output),
           FlagField<CompareArgs>("input", &CompareArgs::input), ConfigFlag<CompareArgs>()},
          RunCompare, true),
      Command<VerifyArgs>(
          "verify",
          "test a short check session against a stored calibration: consistent, or which term "
          "changed; exit 3 when changed",
          {FlagField<VerifyArgs>("calibration", &VerifyArgs::calibration),
           FlagField<VerifyArgs>("input", &VerifyArgs::input), ConfigFlag<VerifyArgs>(),
           FlagField<VerifyArgs>("level", &VerifyArgs::level),
           FlagField<VerifyArgs>("output", &VerifyArgs::output)},
          RunVerify),
      Command<HistoryArgs>(
          "history",
          "a unit's calibrations in a store: each parameter's trend, a drift test, compare "
          "between consecutive ones: gravcal history UNIT --store DIR",
          {FlagField<HistoryArgs>("store", &HistoryArgs::store),
           FlagField<HistoryArgs>("level", &HistoryArgs::level),
           FlagField<HistoryArgs>("output", &HistoryArgs::output),
           FlagField<HistoryArgs>("report", &HistoryArgs::report)},
          RunHistory, true, false),
      {"help",
       "list commands, or the flags and config keys of one: gravcal help <command>",
       {},
       nullptr},
  };
  return commands;
}

// Who reads the keys of `section` (help's section headers): "every method",
// "not a method key", or the methods, with the keys when a method reads only
// some of them.
std::string SectionReaders(const std::string& section) {
  std::vector<const gravcal::ConfigKey*> keys;
  for (const gravcal::ConfigKey& k : gravcal::ConfigKeys()) {
    if (k.section == section) keys.push_back(&k);
  }
  if (keys.empty()) return "";
  if (keys[0]->use == gravcal::ConfigSectionUse::kAllMethods) return "every method";
  if (keys[0]->use == gravcal::ConfigSectionUse::kCommand) return "commands, not methods";
  std::string text;
  for (const gravcal::CalibrationMethod& m : gravcal::CalibrationMethods()) {
    std::string read;
    size_t count = 0;
    for (const gravcal::ConfigKey* k : keys) {
      if (!gravcal::MethodReadsKey(m, *k)) continue;
      read += (count++ ? ", " : "") + k->name;
    }
    if (count == 0) continue;
    text += (text.empty() ? "" : "; ") + m.name + (count < keys.size() ? " (" + read + ")" : "");
  }
  return text;
}

// False for a command that does not exist (nothing printed then).
bool PrintHelp(const std::string& command) {
  gravcal::Config defaults;
  if (command.empty()) {
    std::printf("gravcal: IMU calibration with gravity as the only reference\n\n");
    std::printf("usage: gravcal <command> [--flag value ...]\n\ncommands:\n");
    for (const CommandInfo& c : Commands()) std::printf("  %-10s %s\n", c.name, c.summary);
    std::printf(
        "\n'gravcal <command> --help' lists that command's flags and the config keys;\n"
        "'gravcal --version' prints the versions of gravcal, Ceres and Eigen.\n");
    return true;
  }
  if (command == "version" || command == "--version") {
    std::printf("gravcal version (or --version): the versions of gravcal, Ceres and Eigen\n");
    return true;
  }
  for (const CommandInfo& c : Commands()) {
    if (command != c.name) continue;
    std::printf("gravcal %s: %s\n\nflags:\n", c.name, c.summary);
    for (size_t i = 0; i < c.flags.size(); ++i) {
      const std::string& accepted = c.accepted[i];
      std::printf("  %-24s %s%s\n", FlagSpelling(c.flags[i]).c_str(), FindFlag(c.flags[i])->help,
                  accepted.empty() ? "" : (": " + accepted).c_str());
    }
    if (!c.config_keys) {
      std::printf("\nconfig keys: none (this command reads no config)\n");
      return true;
    }
    std::printf("\nconfig keys (in the YAML file, or as --key value; default in brackets):\n");
    std::string section;
    for (const gravcal::ConfigKey& k : gravcal::ConfigKeys()) {
      if (k.section != section) {
        section = k.section;
        std::printf("  %s (read by %s):\n", section.c_str(), SectionReaders(section).c_str());
      }
      std::printf("    --%-26s %s [%s]\n", k.name.c_str(), k.help.c_str(),
                  gravcal::ConfigValueText(defaults, k.name).c_str());
    }
    return true;
  }
  return false;
}

// gravcal's version and the versions of Ceres and Eigen it was built with.
void PrintVersion() {
  std::printf("gravcal %s\nCeres Solver %s\nEigen %d.%d.%d\n", gravcal::GravcalVersion(),
              CERES_VERSION_STRING, EIGEN_WORLD_VERSION, EIGEN_MAJOR_VERSION, EIGEN_MINOR_VERSION);
}

// The command line split: config keys (--key value) become overrides, the
// gflags flags are copied as "--name=value" for gflags, the rest is
// positional.
struct SplitArguments {
  std::vector<std::pair<std::string, std::string>> overrides;
  std::vector<std::string> flags;
  std::vector<std::string> positional;
  bool help = false;
};

// "--output-dir" -> "output_dir".
std::string FlagName(std::string name) {
  for (char& ch : name) {
    if (ch == '-') ch = '_';
  }
  return name;
}

std::string DashedName(std::string name) {
  for (char& ch : name) {
    if (ch == '_') ch = '-';
  }
  return name;
}

bool SplitCommandLine(int argc, char** argv, const CommandInfo& command, SplitArguments* split,
                      std::string* error) {
  for (int i = 2; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      split->help = true;
      return true;
    }
    if (arg.rfind("--", 0) != 0) {
      if (!command.positional) {
        *error = "unexpected argument '" + arg + "'";
        return false;
      }
      split->positional.push_back(arg);
      continue;
    }
    std::string name = arg.substr(2);
    std::string value;
    const size_t eq = name.find('=');
    const bool has_value = eq != std::string::npos;
    if (has_value) {
      value = name.substr(eq + 1);
      name = name.substr(0, eq);
    }
    name = FlagName(name);
    // Every flag here, config key or gflags flag, takes a value.
    if (!has_value) {
      if (i + 1 >= argc) {
        *error = "flag --" + DashedName(name) + " needs a value";
        return false;
      }
      value = argv[++i];
    }
    if (gravcal::IsConfigKey(name)) {
      split->overrides.emplace_back(name, value);
    } else {
      split->flags.push_back("--" + name + "=" + value);
    }
  }
  return true;
}

// Every flag must be one of gravcal's and one that `command` uses: a flag the
// command ignores (calibrate --report) is an error, not silently dropped.
bool CheckFlagsOfCommand(const CommandInfo& command, const SplitArguments& split,
                         std::string* error) {
  const std::string listed = std::string("('gravcal ") + command.name + " --help' lists its flags)";
  // A flag or config key given twice: which one was meant is not known.
  std::vector<std::string> names;
  for (const auto& [key, value] : split.overrides) names.push_back(key);
  for (const std::string& flag : split.flags) names.push_back(flag.substr(2, flag.find('=') - 2));
  for (size_t i = 0; i < names.size(); ++i) {
    for (size_t j = 0; j < i; ++j) {
      if (names[i] == names[j]) {
        *error = "flag --" + DashedName(names[i]) + " is given twice";
        return false;
      }
    }
  }
  for (const std::string& flag : split.flags) {
    const std::string name = flag.substr(2, flag.find('=') - 2);
    if (FindFlag(name) == nullptr) {
      *error = "unknown flag --" + DashedName(name) + " " + listed;
      return false;
    }
    bool used = false;
    for (const char* f : command.flags) used = used || name == f;
    if (!used) {
      *error = "flag --" + DashedName(name) + " is not used by '" + command.name + "' " + listed;
      return false;
    }
  }
  if (!command.config_keys && !split.overrides.empty()) {
    *error = "config key --" + DashedName(split.overrides.front().first) + " is not used by '" +
             command.name + "' " + listed;
    return false;
  }
  return true;
}

// --config, then the config keys given as flags on top of it.
bool LoadCommandConfig(const SplitArguments& split, gravcal::Config* config, std::string* error) {
  const std::string path = FlagText("config");
  if (!path.empty() && !gravcal::LoadConfigFile(path, config, error)) return false;
  for (const auto& [key, value] : split.overrides) {
    if (!gravcal::SetConfigValue(key, value, config, error)) {
      *error = "command line: " + *error;
      return false;
    }
  }
  return true;
}

const CommandInfo* FindCommand(const std::string& name) {
  for (const CommandInfo& c : Commands()) {
    if (name == c.name) return &c;
  }
  return nullptr;
}

}  // namespace
}  // namespace cli
}  // namespace gravcal

int main(int argc, char** argv) {
  namespace cli = gravcal::cli;
  google::InitGoogleLogging(argv[0]);
  FLAGS_logtostderr = true;
  FLAGS_minloglevel = google::GLOG_WARNING;
  if (argc < 2) {
    cli::PrintHelp("");
    return 1;
  }
  const std::string command = argv[1];
  if (command == "help" || command == "--help" || command == "-h") {
    const std::string topic = argc > 2 ? argv[2] : "";
    if (!cli::PrintHelp(topic))
      return cli::Fail("unknown command '" + topic + "' (gravcal help lists them)");
    return 0;
  }
  if (command == "--version" || command == "version") {
    cli::PrintVersion();
    return 0;
  }
  const cli::CommandInfo* info = cli::FindCommand(command);
  if (info == nullptr)
    return cli::Fail("unknown command '" + command + "' (gravcal help lists them)");

  cli::SplitArguments split;
  std::string error;
  if (!cli::SplitCommandLine(argc, argv, *info, &split, &error)) return cli::Fail(error);
  if (split.help) {
    cli::PrintHelp(command);
    return 0;
  }
  if (!cli::CheckFlagsOfCommand(*info, split, &error)) return cli::Fail(error);
  std::vector<char*> gflags_argv = {argv[0]};
  for (std::string& f : split.flags) gflags_argv.push_back(f.data());
  int gflags_argc = static_cast<int>(gflags_argv.size());
  char** gflags_args = gflags_argv.data();
  gflags::ParseCommandLineNonHelpFlags(&gflags_argc, &gflags_args, false);

  cli::CommonArgs common;
  if (command == "calibrate" && gravcal::IsMultiImuConfigFile(cli::FlagText("config"))) {
    return cli::RunMultiImuCalibrate(cli::FlagText("config"), cli::FlagText("input"),
                                     cli::FlagText("output_dir"), cli::FlagText("report"),
                                     !split.overrides.empty());
  }
  // batch and simulate with a multi-IMU config: it is read by their plate
  // variants (plate_commands.cc), not as a single-IMU config.
  const bool plates = (command == "batch" || command == "simulate") &&
                      gravcal::IsMultiImuConfigFile(cli::FlagText("config"));
  if (plates && !split.overrides.empty()) {
    return cli::Fail("a multi-IMU config's keys are not taken as flags; set them in " +
                     cli::FlagText("config"));
  }
  if (!plates && !cli::LoadCommandConfig(split, &common.config, &error)) return cli::Fail(error);
  common.config_path = cli::FlagText("config");
  common.positional = split.positional;
  return info->run(std::move(common));
}
