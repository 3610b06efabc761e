// The command-line flags of the gravcal tool, declared once: GRAVCAL_FLAGS
// below is the one table. flags.cc turns it into the gflags definitions and
// into FindFlag's table (help and validation); main.cc binds each command's
// flags to the fields of its args struct (commands.h) with FlagField.
#ifndef GRAVCAL_SRC_CLI_FLAGS_H_
#define GRAVCAL_SRC_CLI_FLAGS_H_

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <type_traits>

#include "gravcal/estimation/calibration_comparison.h"
#include "gravcal/workflows/fleet_summary.h"
#include "gravcal/workflows/plan.h"

// X(gflags type, name, default, help), one line per flag.
#define GRAVCAL_FLAGS(X)                                                                         \
  X(string, input, "", "raw log to read")                                                        \
  X(string, output, "", "file to write (calibration JSON or corrected CSV)")                     \
  X(string, output_dir, "",                                                                      \
    "folder to write into (simulate: raw.csv, truth.json; batch: results)")                      \
  X(string, config, "", "YAML config file (configs/*.yaml)")                                     \
  X(string, calibration, "", "calibration JSON to apply")                                        \
  X(uint64, seed, 1, "random seed of the simulator")                                             \
  X(string, manifest, "", "batch: CSV with columns unit, path and optional config keys")         \
  X(string, input_dir, "", "batch: every file matching --pattern in this folder is a unit")      \
  X(string, pattern, "*.csv", "batch: file name pattern for --input-dir")                        \
  X(int32, threads, 0, "batch: worker threads, 0 = one per core")                                \
  X(string, shard, "",                                                                           \
    "batch: K/N, calibrate only units i with i mod N = K - 1; auto or auto/N: K and N "          \
    "from the scheduler's job array (Slurm, Kubernetes, AWS Batch)")                             \
  X(double, unit_timeout, 0.0,                                                                   \
    "batch: seconds one unit may take; a unit over it fails with a message and the "             \
    "batch goes on (0 = no limit)")                                                              \
  X(double, outlier_sigmas, gravcal::FleetOptions().outlier_sigmas,                              \
    "batch: outlier threshold, robust standard deviations from the fleet median")                \
  X(int32, outlier_min_units, gravcal::FleetOptions().min_units,                                 \
    "batch: fewest calibrated units for the outlier check")                                      \
  X(string, attitudes, "",                                                                       \
    "CSV of each static position's roll and pitch (methods that need the fixture's "             \
    "attitudes)")                                                                                \
  X(string, segments, "",                                                                        \
    "CSV of the constant-rate segments, t_begin, t_end, rates (methods that need a rate "        \
    "table)")                                                                                    \
  X(string, history, "", "calibrate: write the estimates' time history (CSV) here")              \
  X(string, report, "", "HTML report to write (calibrate, batch, noise, discover, history)")     \
  X(string, kalibr, "", "noise: also write Kalibr's imu.yaml (continuous-time densities) here")  \
  X(string, handheld, "", "noise: also write the handheld filter's hk_* noise keys (YAML) here") \
  X(string, topics, "",                                                                          \
    "batch: 'all' makes one unit per sensor_msgs/Imu topic of the bag --input")                  \
  X(string, noise, "",                                                                           \
    "noise.json from 'gravcal noise': the variance of each pose's mean, and the "                \
    "handheld filter's noise, from the noise model")                                             \
  X(string, target, "",                                                                          \
    "plan, check: targets, e.g. \"accel_bias=0.5mg accel_scale=50ppm "                           \
    "accel_misalignment=0.1mrad\" (or parameter names bias_x ... u_zz)")                         \
  X(string, pose_set, gravcal::ToString(gravcal::PlanRequest().pose_set),                        \
    "plan, check: candidate orientations")                                                       \
  X(int32, candidates, gravcal::PlanRequest().free_candidates,                                   \
    "plan, check: directions of the free pose set (besides faces+45)")                           \
  X(double, max_time, 0.0, "plan: the session may not take longer, seconds (0 = no limit)")      \
  X(double, overhead, gravcal::PlanRequest().overhead_seconds,                                   \
    "plan: seconds to move and settle the housing before each pose")                             \
  X(double, min_hold, gravcal::PlanRequest().min_hold_seconds, "plan: shortest hold, s")         \
  X(double, max_hold, gravcal::PlanRequest().max_hold_seconds, "plan: longest hold, s")          \
  X(double, accel_noise_density, 0.0,                                                            \
    "plan, check: accelerometer white noise N, m/s^2/sqrt(Hz) (datasheet; instead of "           \
    "--noise); noise: the datasheet's, to compare with")                                         \
  X(double, accel_bias_instability, 0.0, "plan, check: accelerometer bias instability B, m/s^2") \
  X(double, accel_random_walk, 0.0, "plan, check: accelerometer random walk K, m/s^3/sqrt(Hz)")  \
  X(double, pose_disturbance, 0.0,                                                               \
    "plan, check: per-pose disturbance of |a|, m/s^2 rms (0 = none)")                            \
  X(double, gyro_noise_density, 0.0,                                                             \
    "plan: gyroscope white noise N, rad/s/sqrt(Hz) (datasheet; instead of --noise): "            \
    "plans the turns between poses for the gyroscope; noise: the datasheet's, to compare with")  \
  X(double, attitude_std, 0.0,                                                                   \
    "plan (method known_attitude): the fixture's roll and pitch standard deviation, "            \
    "degrees")                                                                                   \
  X(bool, check, false,                                                                          \
    "calibrate: add what the session lacks (as gravcal check says it) to the output "            \
    "and the calibration JSON ('check')")                                                        \
  X(double, turn_seconds, gravcal::PlanRequest().turn_seconds,                                   \
    "plan: seconds a half turn takes (shorter turns proportionally less)")                       \
  X(string, plan, "", "simulate: plan.json from gravcal plan (its poses replace sim_scheme)")    \
  X(double, level, 0.01,                                                                         \
    "compare, verify, history, plan --verify: significance level of the test")                   \
  X(string, space, gravcal::ToString(gravcal::ComparisonSpace::kModel),                          \
    "compare: the parameters compared (model: the calibrations' own, same mounting; "            \
    "intrinsic: mount-invariant, Geist and Gaitan)")                                             \
  X(string, limits, "", "calibrate, batch: acceptance limits (YAML); exit 4 when one fails")     \
  X(string, certificate, "",                                                                     \
    "calibrate: write the calibration certificate to <prefix>.json and <prefix>.html; "          \
    "batch: one per unit, <folder>/<unit>.json and .html")                                       \
  X(string, unit, "",                                                                            \
    "calibrate: the unit's name on the certificate and in the store (default: the log's name); " \
    "apply, export: the unit whose stored calibration closest to --at is used")                  \
  X(string, store, "",                                                                           \
    "calibrate, batch: file the calibration in this store (a folder, per unit and date); "       \
    "history: the store to read; apply, export: take the calibration from it (with --unit)")     \
  X(string, at, "",                                                                              \
    "apply, export with --store: the date (ISO 8601 UTC, default now) whose closest "            \
    "calibration is used")                                                                       \
  X(double, max_age_days, 0.0,                                                                   \
    "apply, export with --store: warn when the calibration used is older than this (days; "      \
    "0: never)")                                                                                 \
  X(string, verify, "",                                                                          \
    "plan: design the shortest check session for this stored calibration (JSON) "                \
    "instead: four poses, detecting 10 stored sigmas in any one parameter with power "           \
    "0.9 at --level (needs --accel_noise_density)")                                              \
  X(string, to, "", "export: the target")                                                        \
  X(string, events, "", "record: write the events as JSON lines here (- = standard output)")     \
  X(int32, baud, 0, "record: baud rate of a serial --input (0 = the device's setting)")          \
  X(string, stream, "",                                                                          \
    "simulate: stream a virtual hand's session as CSV lines to - (standard output) or pty "      \
    "(a new pseudo-terminal, its name on stderr)")                                               \
  X(double, rate, 0.0, "simulate --stream: times real time (0 = as fast as possible)")           \
  X(string, follow_events, "",                                                                   \
    "simulate --stream: follow the suggest events gravcal record writes to this file")           \
  X(uint64, accel_device_id, 0,                                                                  \
    "export --to px4: the accelerometer's device id (CAL_ACC0_ID), which TC_A0_ID must match")   \
  X(uint64, gyro_device_id, 0,                                                                   \
    "export --to px4: the gyroscope's device id (CAL_GYRO0_ID), which TC_G0_ID must match")      \
  X(bool, drop_thermal, false,                                                                   \
    "export: leave the thermal model out of a px4 or ardupilot file (said in the file)")         \
  X(int32, ardupilot_imu, 1,                                                                     \
    "export --to ardupilot: the IMU instance n (1-3) the file is for: INS_ACCnOFFS_*, "          \
    "INS_TCALn_*, INS_ACCn_CALTEMP (n = 1 writes INS_ACCOFFS_*)")

namespace gravcal {
namespace cli {

struct FlagInfo {
  const char* name;
  const char* help;
};

// The flag of GRAVCAL_FLAGS named `name` ("output_dir"); null when none.
const FlagInfo* FindFlag(const std::string& name);

// The flag's value after gflags parsed the command line, as text.
std::string FlagText(const char* name);

// Text to value, for the types of GRAVCAL_FLAGS (gflags checked the text).
void ParseFlagText(const std::string& text, std::string* value);
void ParseFlagText(const std::string& text, bool* value);
void ParseFlagText(const std::string& text, int* value);
void ParseFlagText(const std::string& text, uint64_t* value);
void ParseFlagText(const std::string& text, double* value);

// "--output-dir" for "output_dir".
std::string FlagSpelling(const char* name);

// Whether T is an enum with a string table, or an optional one (a flag that
// may be left empty).
template <typename T>
struct FlagEnum : std::is_enum<T> {};
template <typename T>
struct FlagEnum<std::optional<T>> : std::is_enum<T> {};

// Text to an enum by its one string table (core/types.h): false with a
// one-line error naming the flag and the accepted names ("--space: 'x' is
// not one of model or intrinsic"). An optional enum stays empty for empty
// text.
template <typename E>
bool SetFlagEnum(const char* name, const std::string& text, E* value, std::string* error) {
  if (FromString(text, value)) return true;
  *error = FlagSpelling(name) + ": '" + text + "' is not one of " + AcceptedNames(E());
  return false;
}
template <typename E>
bool SetFlagEnum(const char* name, const std::string& text, std::optional<E>* value,
                 std::string* error) {
  E v{};
  if (text.empty()) {
    value->reset();
  } else if (SetFlagEnum(name, text, &v, error)) {
    *value = v;
  } else {
    return false;
  }
  return true;
}

// Text to the value of flag `name` (an enum by SetFlagEnum).
template <typename T>
bool SetFlagValue(const char* name, const std::string& text, T* value, std::string* error) {
  if constexpr (FlagEnum<T>::value) {
    return SetFlagEnum(name, text, value, error);
  } else {
    ParseFlagText(text, value);
    return true;
  }
}

// The names an enum flag accepts (core/types.h AcceptedNames), empty for
// other flags: help lists them after the flag's own help.
template <typename T>
std::string FlagAcceptedNames() {
  if constexpr (std::is_enum_v<T>) {
    return AcceptedNames(T());
  } else if constexpr (FlagEnum<T>::value) {
    return AcceptedNames(typename T::value_type());
  } else {
    return std::string();
  }
}

// A command's use of one flag: its name, where its value goes in the
// command's args struct (false with a one-line error on a bad value), and
// the names it accepts if it takes an enum (FlagAcceptedNames).
template <typename Args>
struct FlagBinding {
  const char* name;
  std::function<bool(const std::string& text, Args* args, std::string* error)> set;
  std::string accepted;
};

// The flag `name` into the field `field` of Args (or of its base).
template <typename Args, typename Class, typename T>
FlagBinding<Args> FlagField(const char* name, T Class::*field) {
  static_assert(std::is_base_of_v<Class, Args>, "the field is not one of the args struct");
  return {name,
          [name, field](const std::string& text, Args* args, std::string* error) {
            return SetFlagValue(name, text, &(args->*field), error);
          },
          FlagAcceptedNames<T>()};
}

// The flag `name` into the field that `at` returns a pointer to (a field of
// a nested struct: &args->request.targets).
template <typename Args, typename At>
FlagBinding<Args> FlagAt(const char* name, At at) {
  using T = std::remove_pointer_t<std::invoke_result_t<At, Args*>>;
  return {name,
          [name, at](const std::string& text, Args* args, std::string* error) {
            return SetFlagValue(name, text, at(args), error);
          },
          FlagAcceptedNames<T>()};
}

}  // namespace cli
}  // namespace gravcal

#endif  // GRAVCAL_SRC_CLI_FLAGS_H_
