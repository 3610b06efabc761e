#include "gravcal/workflows/method_registry.h"

#include <algorithm>

#include "gravcal/core/gravity.h"
#include "gravcal/methods/handheld_kalman.h"
#include "gravcal/methods/known_attitude.h"
#include "gravcal/methods/rate_table.h"
#include "gravcal/methods/ten_position.h"
#include "gravcal/methods/thermal_calibration.h"
#include "gravcal/methods/twelve_position_method.h"

namespace gravcal {
namespace {

// Each run function gives its method the sections of the config it reads
// (the method assembles itself in src/methods/).

bool RunTwelvePosition(const Config& config, const Session& session, Calibration* calibration) {
  return CalibrateTwelvePosition(session, {config.calibration, config.gyro, config.effects},
                                 calibration);
}

bool RunTenPosition(const Config& config, const Session& session, Calibration* calibration) {
  return CalibrateTenPosition(session, {config.calibration, config.ten_position}, calibration);
}

bool RunKnownAttitude(const Config& config, const Session& session, Calibration* calibration) {
  return CalibrateKnownAttitude(session, {config.calibration}, calibration);
}

// The handheld filter takes its gravity and accelerometer nominal scale
// from the shared sections.
HandheldKalmanMethodOptions HandheldOptions(const Config& config) {
  HandheldKalmanMethodOptions options{config.handheld, config.keys_set};
  options.filter.gravity = config.calibration.gravity;
  options.filter.accel_nominal_scale = config.calibration.nominal_scale;
  return options;
}

bool RunHandheldKalman(const Config& config, const Session& session, Calibration* calibration) {
  return CalibrateHandheld(session, HandheldOptions(config), calibration);
}

bool RunRateTable(const Config&, const Session& session, Calibration* calibration) {
  return CalibrateRateTable(session, RateTableMethodOptions(), calibration);
}

// Issue 35: gravity, nominal scales, detector and iterations come from the
// shared sections; the detector's level checks stay off unless set (a pose
// held through a warm-up drifts).
ThermalCalibrationOptions ThermalOptions(const Config& config) {
  ThermalCalibrationOptions options = config.thermal;
  options.accel_nominal_scale = config.calibration.nominal_scale;
  options.gyro_nominal_scale = config.handheld.gyro_nominal_scale;
  options.max_iterations = config.calibration.refinement.solver.max_iterations;
  options.detector = config.calibration.detector;
  const auto set = [&config](const char* key) {
    return std::find(config.keys_set.begin(), config.keys_set.end(), key) != config.keys_set.end();
  };
  if (!set("trend_factor")) options.detector.trend_factor = 0.0;
  if (!set("spread_factor")) options.detector.spread_factor = 0.0;
  return options;
}

bool RunThermal(const Config& config, const Session& session, Calibration* calibration) {
  ThermalCalibrationOptions options = ThermalOptions(config);
  std::string source, error;
  if (!ResolveGravity(config.calibration.gravity, &options.gravity, &source, &error)) {
    calibration->success = false;
    calibration->message = error;
    return false;
  }
  const bool ok = CalibrateThermal(session, options, calibration);
  calibration->gravity_source = source;
  return ok;
}

constexpr char kPoseNoiseUse[] =
    "the variance of each pose's mean (Allan variance at the pose's duration)";

}  // namespace

const std::vector<CalibrationMethod>& CalibrationMethods() {
  // Never destroyed (Google style for static storage): a batch worker abandoned
  // with a hung unit may still read it while the process exits (found by TSan).
  static const std::vector<CalibrationMethod>& methods = *new std::vector<CalibrationMethod>{
      {Method::kTwelvePosition,
       ToString(Method::kTwelvePosition),
       "multi-position magnitude fit",
       {"gravity", "detector", "pose_noise", "model", "solver", "gyro", "effects"},
       {"gyro_nominal_scale"},
       MethodSideInput::kNone,
       nullptr,
       RunTwelvePosition,
       kPoseNoiseUse},
      {Method::kTenPosition,
       ToString(Method::kTenPosition),
       "patent, self-aligned",
       {"gravity", "detector", "pose_noise", "alignment"},
       {"parameterization", "allow_undetermined", "loss", "loss_scale", "covariance",
        "max_iterations", "pose_variance", "max_pose_disturbance", "structure_test_level",
        "pose_disturbance_prior", "pose_disturbance_prior_dof", "prior_conflict_level"},
       MethodSideInput::kNone,
       [](const Config& c, std::string* e) { return c.ten_position.IsValid(e); },
       RunTenPosition,
       kPoseNoiseUse},
      {Method::kKnownAttitude,
       ToString(Method::kKnownAttitude),
       "fixture attitudes, --attitudes",
       {"gravity", "detector", "pose_noise"},
       {"loss", "loss_scale", "covariance", "max_iterations", "pose_variance",
        "max_pose_disturbance", "pose_disturbance_prior", "pose_disturbance_prior_dof",
        "gyro_nominal_scale"},
       MethodSideInput::kAttitudes,
       nullptr,
       RunKnownAttitude,
       kPoseNoiseUse},
      {Method::kHandheldKalman,
       ToString(Method::kHandheldKalman),
       "21-state Kalman filter on a handheld log",
       {"gravity", "handheld_kalman"},
       {"nominal_scale", "gyro_nominal_scale"},
       MethodSideInput::kNone,
       [](const Config& c, std::string* e) { return HandheldOptions(c).IsValid(e); },
       RunHandheldKalman,
       "the filter's process noise Q (hk_*_noise_density, hk_*_bias_walk not set as keys)",
       /*keeps_history=*/true},
      {Method::kRateTable,
       ToString(Method::kRateTable),
       "gyroscope from constant-rate segments, --segments",
       {},
       {},
       MethodSideInput::kSegments,
       nullptr,
       RunRateTable},
      {Method::kThermal,
       ToString(Method::kThermal),
       "bias, scale and misalignment against temperature (issue 35)",
       {"gravity", "detector", "thermal"},
       {"nominal_scale", "gyro_nominal_scale", "max_iterations"},
       MethodSideInput::kNone,
       [](const Config& c, std::string* e) { return ThermalOptions(c).IsValid(e); },
       RunThermal,
       ""},
  };
  return methods;
}

const CalibrationMethod* FindCalibrationMethod(const std::string& name) {
  Method method;
  return FromString(name, &method) ? FindCalibrationMethod(method) : nullptr;
}

const CalibrationMethod* FindCalibrationMethod(Method method) {
  for (const CalibrationMethod& m : CalibrationMethods()) {
    if (m.id == method) return &m;
  }
  return nullptr;
}

std::string CalibrationMethodNames() {
  std::string names;
  for (const CalibrationMethod& m : CalibrationMethods()) {
    names += (names.empty() ? "" : ", ") + m.name;
  }
  return names;
}

std::string CalibrationMethodsHelp() {
  std::string help;
  for (const CalibrationMethod& m : CalibrationMethods()) {
    help += (help.empty() ? "" : ", ") + m.name + " (" + m.help + ")";
  }
  return help;
}

bool MethodReadsKey(const CalibrationMethod& method, const ConfigKey& key) {
  if (key.use != ConfigSectionUse::kSomeMethods) return key.use == ConfigSectionUse::kAllMethods;
  const auto has = [](const std::vector<std::string>& v, const std::string& s) {
    return std::find(v.begin(), v.end(), s) != v.end();
  };
  return has(method.sections, key.section) || has(method.keys, key.name);
}

}  // namespace gravcal
