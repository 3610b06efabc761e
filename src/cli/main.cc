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
#include <string>
#include <vector>

#include "cli/commands.h"
#include "gravcal/workflows/batch.h"
#include "gravcal/workflows/config.h"
#include "gravcal/workflows/fleet_summary.h"
#include "gravcal/workflows/method_registry.h"

DEFINE_string(input, "", "raw log to read");
DEFINE_string(output, "", "file to write (calibration JSON or corrected CSV)");
DEFINE_string(output_dir, "",
              "folder to write into (simulate: raw.csv, truth.json; batch: results)");
DEFINE_string(config, "", "YAML config file (configs/*.yaml)");
DEFINE_string(calibration, "", "calibration JSON to apply");
DEFINE_uint64(seed, 1, "random seed of the simulator");
DEFINE_string(manifest, "", "batch: CSV with columns unit, path and optional config keys");
DEFINE_string(input_dir, "", "batch: every file matching --pattern in this folder is a unit");
DEFINE_string(pattern, "*.csv", "batch: file name pattern for --input-dir");
DEFINE_int32(threads, 0, "batch: worker threads, 0 = one per core");
DEFINE_string(shard, "",
              "batch: K/N, calibrate only units i with i mod N = K - 1; auto or auto/N: K and N "
              "from the scheduler's job array (Slurm, Kubernetes, AWS Batch)");
DEFINE_double(unit_timeout, 0.0,
              "batch: seconds one unit may take; a unit over it fails with a message and the "
              "batch goes on (0 = no limit)");
DEFINE_double(outlier_sigmas, gravcal::FleetOptions().outlier_sigmas,
              "batch: outlier threshold, robust standard deviations from the fleet median");
DEFINE_int32(outlier_min_units, gravcal::FleetOptions().min_units,
             "batch: fewest calibrated units for the outlier check");
DEFINE_string(attitudes, "",
              "CSV of each static position's roll and pitch (methods that need the fixture's "
              "attitudes)");
DEFINE_string(segments, "",
              "CSV of the constant-rate segments, t_begin, t_end, rates (methods that need a rate "
              "table)");
DEFINE_string(history, "", "calibrate: write the estimates' time history (CSV) here");
DEFINE_string(report, "", "HTML report to write (calibrate, batch, noise, discover)");
DEFINE_string(kalibr, "", "noise: also write Kalibr's imu.yaml (continuous-time densities) here");
DEFINE_string(handheld, "", "noise: also write the handheld filter's hk_* noise keys (YAML) here");
DEFINE_string(topics, "",
              "batch: 'all' makes one unit per sensor_msgs/Imu topic of the bag --input");
DEFINE_string(noise, "",
              "noise.json from 'gravcal noise': the variance of each pose's mean, and the "
              "handheld filter's noise, from the noise model");
// Issue 15: gravcal plan / check / simulate --plan.
DEFINE_string(target, "",
              "plan, check: targets, e.g. \"accel_bias=0.5mg accel_scale=50ppm "
              "accel_misalignment=0.1mrad\" (or parameter names bias_x ... u_zz)");
DEFINE_string(pose_set, gravcal::PlanRequest().pose_set,
              "plan, check: candidate orientations: faces, faces+45 or free");
DEFINE_int32(candidates, gravcal::PlanRequest().free_candidates,
             "plan, check: directions of the free pose set (besides faces+45)");
DEFINE_double(max_time, 0.0, "plan: the session may not take longer, seconds (0 = no limit)");
DEFINE_double(overhead, gravcal::PlanRequest().overhead_seconds,
              "plan: seconds to move and settle the housing before each pose");
DEFINE_double(min_hold, gravcal::PlanRequest().min_hold_seconds, "plan: shortest hold, s");
DEFINE_double(max_hold, gravcal::PlanRequest().max_hold_seconds, "plan: longest hold, s");
DEFINE_double(accel_noise_density, 0.0,
              "plan, check: accelerometer white noise N, m/s^2/sqrt(Hz) (datasheet; instead of "
              "--noise)");
DEFINE_double(accel_bias_instability, 0.0, "plan, check: accelerometer bias instability B, m/s^2");
DEFINE_double(accel_random_walk, 0.0, "plan, check: accelerometer random walk K, m/s^3/sqrt(Hz)");
DEFINE_double(pose_disturbance, 0.0,
              "plan, check: per-pose disturbance of |a|, m/s^2 rms (0 = none)");
DEFINE_double(gyro_noise_density, 0.0,
              "plan: gyroscope white noise N, rad/s/sqrt(Hz) (datasheet; instead of --noise): "
              "plans the turns between poses for the gyroscope");
DEFINE_double(attitude_std, 0.0,
              "plan (method known_attitude): the fixture's roll and pitch standard deviation, "
              "degrees");
DEFINE_bool(check, false,
            "calibrate: add what the session lacks (as gravcal check says it) to the output "
            "and the calibration JSON ('check')");
DEFINE_double(turn_seconds, gravcal::PlanRequest().turn_seconds,
              "plan: seconds a half turn takes (shorter turns proportionally less)");
DEFINE_string(plan, "", "simulate: plan.json from gravcal plan (its poses replace sim_scheme)");

DEFINE_double(level, 0.01, "compare, verify: significance level of the test");
DEFINE_string(space, "model",
              "compare: model (the calibrations' own parameters, same mounting) or intrinsic "
              "(mount-invariant, Geist and Gaitan)");
DEFINE_string(limits, "", "calibrate: acceptance limits (YAML); exit 4 when one fails");
DEFINE_string(certificate, "",
              "calibrate: write the calibration certificate to <prefix>.json and <prefix>.html");
DEFINE_string(unit, "", "calibrate: the unit's name on the certificate (default: the log's name)");
DEFINE_string(store, "",
              "calibrate: file the calibration in this store (a folder, per unit and date); "
              "history: the store to read");
DEFINE_string(verify, "",
              "plan: design the shortest check session for this stored calibration (JSON) "
              "instead: four poses, detecting 10 stored sigmas in any one parameter with power "
              "0.9 at --level (needs --accel_noise_density)");
DEFINE_string(to, "", "export: the target (kalibr, openvins, ros, px4, ardupilot, c)");

namespace {

struct CommandInfo {
  const char* name;
  const char* summary;
  std::vector<const char*> flags;
  // nullptr for help, which main handles before parsing flags.
  int (*run)(const gravcal::cli::CommandArgs&);
  // Takes arguments that are not flags (merge-summaries: the shard folders).
  bool positional = false;
  // Reads the config: takes config keys as flags (--gravity 9.81).
  bool config_keys = true;
};

const std::vector<CommandInfo>& Commands() {
  static const std::vector<CommandInfo> commands = {
      {"demo",
       "simulate a twelve-position session in raw counts, calibrate it, print estimate vs truth",
       {"config", "seed"},
       gravcal::cli::RunDemo},
      {"calibrate",
       "calibrate the sensors from a log with the config's method (the config key 'method' "
       "lists them)",
       {"input", "config", "output", "attitudes", "segments", "history", "noise", "report", "check",
        "limits", "certificate", "unit", "store"},
       gravcal::cli::RunCalibrate},
      {"apply",
       "apply every term of a calibration to a contract CSV log (streaming; - for standard "
       "input/output), writing SI units",
       {"calibration", "input", "output", "config"},
       gravcal::cli::RunApply},
      {"simulate",
       "simulate a session: raw.csv, truth.json, the fixture's attitudes.csv (and, for "
       "sim_motion rate_table, segments.csv)",
       {"config", "seed", "output_dir", "plan"},
       gravcal::cli::RunSimulate},
      {"plan",
       "plan a recording before it is made: plan.json with the poses, holds and predicted "
       "sigmas (least time meeting --target, or best within --max_time)",
       {"config",
        "output",
        "noise",
        "target",
        "pose_set",
        "candidates",
        "max_time",
        "overhead",
        "min_hold",
        "max_hold",
        "accel_noise_density",
        "accel_bias_instability",
        "accel_random_walk",
        "pose_disturbance",
        "report",
        "gyro_noise_density",
        "turn_seconds",
        "attitude_std",
        "verify",
        "level"},
       gravcal::cli::RunPlan},
      {"check",
       "what a recorded session determines: predicted sigma per parameter, what is "
       "undetermined or short of --target, and the extra poses that would help most",
       {"input", "config", "noise", "target", "pose_set", "candidates", "accel_noise_density",
        "accel_bias_instability", "accel_random_walk", "pose_disturbance"},
       gravcal::cli::RunCheck},
      {"batch",
       "calibrate many units in parallel: <unit>.json, summary.csv, summary.json (fleet "
       "statistics)",
       {"manifest", "input_dir", "pattern", "config", "output_dir", "threads", "shard",
        "outlier_sigmas", "outlier_min_units", "input", "topics", "report", "unit_timeout",
        "limits"},
       gravcal::cli::RunBatch},
      {"merge-summaries",
       "merge the summaries of a batch's shards: gravcal merge-summaries --output-dir merged/ "
       "shard1/ shard2/ ...",
       {"output_dir", "outlier_sigmas", "outlier_min_units"},
       gravcal::cli::RunMergeSummaries,
       true,
       false},
      {"discover",
       "find the effects the model misses: discovery.json and an HTML report",
       {"input", "config", "output", "report"},
       gravcal::cli::RunDiscover},
      {"noise",
       "the noise model of a still log (Allan deviation: N, B, K per axis): noise.json, and "
       "Kalibr's imu.yaml",
       {"input", "config", "output", "kalibr", "handheld", "report"},
       gravcal::cli::RunNoise},
      {"inspect",
       "what a log file holds: format, topics and types, message counts, rates, time span, gaps",
       {"input", "config"},
       gravcal::cli::RunInspect},
      {"export",
       "write a calibration for kalibr, openvins, ros, px4, ardupilot or as C source (c)",
       {"calibration", "noise", "to", "output", "output_dir"},
       gravcal::cli::RunExport},
      {"compare",
       "are two calibrations of the same unchanged unit? per-parameter z, joint test; exit 3 "
       "when not: gravcal compare a.json b.json",
       {"level", "space", "output", "input", "config"},
       gravcal::cli::RunCompare,
       true},
      {"verify",
       "test a short check session against a stored calibration: consistent, or which term "
       "changed; exit 3 when changed",
       {"calibration", "input", "config", "level", "output"},
       gravcal::cli::RunVerify},
      {"history",
       "a unit's calibrations in a store: each parameter's trend, a drift test, compare "
       "between consecutive ones: gravcal history UNIT --store DIR",
       {"store", "level", "output"},
       gravcal::cli::RunHistory,
       true,
       false},
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
    for (const char* f : c.flags) {
      gflags::CommandLineFlagInfo info;
      gflags::GetCommandLineFlagInfo(f, &info);
      std::string name = f;
      for (char& ch : name) {
        if (ch == '_') ch = '-';
      }
      std::printf("  --%-22s %s\n", name.c_str(), info.description.c_str());
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
    gflags::CommandLineFlagInfo info;
    if (!gflags::GetCommandLineFlagInfo(name.c_str(), &info) ||
        info.filename.find("cli/main.cc") == std::string::npos) {
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
  if (!FLAGS_config.empty() && !gravcal::LoadConfigFile(FLAGS_config, config, error)) return false;
  for (const auto& [key, value] : split.overrides) {
    if (!gravcal::SetConfigValue(key, value, config, error)) {
      *error = "command line: " + *error;
      return false;
    }
  }
  return true;
}

// The parsed gflags values, copied into the command's arguments.
void CopyFlags(gravcal::cli::CommandArgs* args) {
  args->config_path = FLAGS_config;
  args->input = FLAGS_input;
  args->output = FLAGS_output;
  args->output_dir = FLAGS_output_dir;
  args->calibration = FLAGS_calibration;
  args->seed = FLAGS_seed;
  args->manifest = FLAGS_manifest;
  args->input_dir = FLAGS_input_dir;
  args->pattern = FLAGS_pattern;
  args->threads = FLAGS_threads;
  args->shard = FLAGS_shard;
  args->unit_timeout = FLAGS_unit_timeout;
  args->outlier_sigmas = FLAGS_outlier_sigmas;
  args->outlier_min_units = FLAGS_outlier_min_units;
  args->attitudes = FLAGS_attitudes;
  args->segments = FLAGS_segments;
  args->history = FLAGS_history;
  args->report = FLAGS_report;
  args->check = FLAGS_check;
  args->kalibr = FLAGS_kalibr;
  args->handheld = FLAGS_handheld;
  args->noise = FLAGS_noise;
  args->topics = FLAGS_topics;
  args->to = FLAGS_to;
  args->plan = FLAGS_plan;
  args->level = FLAGS_level;
  args->space = FLAGS_space;
  args->limits = FLAGS_limits;
  args->certificate = FLAGS_certificate;
  args->unit = FLAGS_unit;
  args->store = FLAGS_store;
  args->verify_calibration = FLAGS_verify;
  args->plan_request.targets = FLAGS_target;
  args->plan_request.pose_set = FLAGS_pose_set;
  args->plan_request.free_candidates = FLAGS_candidates;
  args->plan_request.max_time_seconds = FLAGS_max_time;
  args->plan_request.overhead_seconds = FLAGS_overhead;
  args->plan_request.min_hold_seconds = FLAGS_min_hold;
  args->plan_request.max_hold_seconds = FLAGS_max_hold;
  args->plan_request.accel_noise_density = FLAGS_accel_noise_density;
  args->plan_request.accel_bias_instability = FLAGS_accel_bias_instability;
  args->plan_request.accel_random_walk = FLAGS_accel_random_walk;
  args->plan_request.pose_disturbance = FLAGS_pose_disturbance;
  args->plan_request.gyro_noise_density = FLAGS_gyro_noise_density;
  args->plan_request.turn_seconds = FLAGS_turn_seconds;
  args->plan_request.attitude_std_deg = FLAGS_attitude_std;
}

const CommandInfo* FindCommand(const std::string& name) {
  for (const CommandInfo& c : Commands()) {
    if (name == c.name) return &c;
  }
  return nullptr;
}

}  // namespace

int main(int argc, char** argv) {
  google::InitGoogleLogging(argv[0]);
  FLAGS_logtostderr = true;
  FLAGS_minloglevel = google::GLOG_WARNING;
  using gravcal::cli::Fail;
  if (argc < 2) {
    PrintHelp("");
    return 1;
  }
  const std::string command = argv[1];
  if (command == "help" || command == "--help" || command == "-h") {
    const std::string topic = argc > 2 ? argv[2] : "";
    if (!PrintHelp(topic)) return Fail("unknown command '" + topic + "' (gravcal help lists them)");
    return 0;
  }
  if (command == "--version" || command == "version") {
    PrintVersion();
    return 0;
  }
  const CommandInfo* info = FindCommand(command);
  if (info == nullptr) return Fail("unknown command '" + command + "' (gravcal help lists them)");

  SplitArguments split;
  std::string error;
  if (!SplitCommandLine(argc, argv, *info, &split, &error)) return Fail(error);
  if (split.help) {
    PrintHelp(command);
    return 0;
  }
  if (!CheckFlagsOfCommand(*info, split, &error)) return Fail(error);
  std::vector<char*> gflags_argv = {argv[0]};
  for (std::string& f : split.flags) gflags_argv.push_back(f.data());
  int gflags_argc = static_cast<int>(gflags_argv.size());
  char** gflags_args = gflags_argv.data();
  gflags::ParseCommandLineNonHelpFlags(&gflags_argc, &gflags_args, false);

  gravcal::cli::CommandArgs args;
  if (!LoadCommandConfig(split, &args.config, &error)) return Fail(error);
  CopyFlags(&args);
  args.positional = split.positional;
  if (!gravcal::cli::CheckCommandDestinations(command, args, &error)) return Fail(error);
  return info->run(args);
}
