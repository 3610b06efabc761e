#include "gravcal/workflows/method_registry.h"

#include <algorithm>
#include <functional>
#include <utility>

#include "gravcal/core/gravity.h"
#include "gravcal/methods/handheld_kalman.h"
#include "gravcal/methods/known_attitude.h"
#include "gravcal/methods/rate_table.h"
#include "gravcal/methods/ten_position.h"
#include "gravcal/methods/thermal_calibration.h"
#include "gravcal/methods/twelve_position_method.h"
#include "workflows/config/config_key.h"

namespace gravcal {
namespace {

// Where a method's options come from: each part of its options struct is
// copied from one part of the Config. The same list fills the options (run,
// validate) and says which keys the method reads (a key is read when a
// field it sets lies in a part copied), so the keys a method accepts are
// derived from what its options embed and cannot drift from it.
template <typename Options>
struct OptionsSource {
  // The part of `config` copied: its address and size (size 0 = none).
  std::function<std::pair<const char*, size_t>(const Config&)> part;
  std::function<void(const Config&, Options*)> copy;
};

template <typename T>
std::pair<const char*, size_t> PartOf(const T& part) {
  return {reinterpret_cast<const char*>(&part), sizeof(T)};
}

// options.to = config.from (a section, or a field of one).
#define GRAVCAL_FROM(to, from)                           \
  {                                                      \
    [](const Config& c) { return PartOf(c.from); },      \
        [](const Config& c, auto* o) { o->to = c.from; } \
  }
// The Base section (fit_settings.h) of options.to from that of config.from,
// alone (the struct's other fields are not read).
#define GRAVCAL_FROM_BASE(Base, to, from)                                     \
  {                                                                           \
    [](const Config& c) { return PartOf(static_cast<const Base&>(c.from)); }, \
        [](const Config& c, auto* o) { static_cast<Base&>(o->to) = c.from; }  \
  }
// Read by the pipeline for this method's result rather than by the method
// (RunCalibration: the holds' gyroscope noise in raw units, issue 36).
#define GRAVCAL_FOR_RESULT(from)                                                \
  {                                                                             \
    [](const Config& c) { return PartOf(c.from); }, [](const Config&, auto*) {} \
  }

// A step after the copies that reads no key's field (e.g. the keys set, for
// defaults that depend on whether a key was given).
template <typename Options>
OptionsSource<Options> Adjust(void (*adjust)(const Config&, Options*)) {
  return {[](const Config&) { return std::pair<const char*, size_t>(nullptr, 0); }, adjust};
}

template <typename Options>
CalibrationMethod MakeMethod(Method id, std::string help, MethodSideInput side_input,
                             std::vector<OptionsSource<Options>> sources,
                             bool (*calibrate)(const Session&, const Options&, Calibration*),
                             bool (*validate)(const Options&, std::string*),
                             std::string noise_model, bool keeps_history = false) {
  const auto fill = [sources](const Config& config) {
    Options options;
    for (const OptionsSource<Options>& s : sources) s.copy(config, &options);
    return options;
  };
  CalibrationMethod m;
  m.id = id;
  m.name = ToString(id);
  m.help = std::move(help);
  m.side_input = side_input;
  m.reads = [sources](const Config& config, const void* field) {
    const char* p = static_cast<const char*>(field);
    for (const OptionsSource<Options>& s : sources) {
      const auto [begin, size] = s.part(config);
      if (size > 0 && !std::less<const char*>()(p, begin) &&
          std::less<const char*>()(p, begin + size)) {
        return true;
      }
    }
    return false;
  };
  if (validate != nullptr) {
    m.validate = [fill, validate](const Config& c, std::string* e) { return validate(fill(c), e); };
  }
  m.run = [fill, calibrate](const Config& c, const Session& s, Calibration* calibration) {
    return calibrate(s, fill(c), calibration);
  };
  m.noise_model = std::move(noise_model);
  m.keeps_history = keeps_history;
  return m;
}

// The thermal method's options: its section, with gravity, nominal scales,
// detector and iterations from the shared sections (issue 35), and the
// gravity it resolves.
struct ThermalMethodOptions {
  ThermalCalibrationOptions thermal;
  GravityOptions gravity;
};

// The detector's level checks stay off unless set (a pose held through a
// warm-up drifts).
void ThermalDetectorDefaults(const Config& config, ThermalMethodOptions* options) {
  const auto set = [&config](const char* key) {
    return std::find(config.keys_set.begin(), config.keys_set.end(), key) != config.keys_set.end();
  };
  if (!set("trend_factor")) options->thermal.detector.trend_factor = 0.0;
  if (!set("spread_factor")) options->thermal.detector.spread_factor = 0.0;
}

bool CalibrateThermalMethod(const Session& session, const ThermalMethodOptions& method,
                            Calibration* calibration) {
  ThermalCalibrationOptions options = method.thermal;
  std::string source, error;
  if (!ResolveGravity(method.gravity, &options.gravity, &source, &error)) {
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
      MakeMethod<TwelvePositionMethodOptions>(
          Method::kTwelvePosition, "multi-position magnitude fit", MethodSideInput::kNone,
          {GRAVCAL_FROM(accel, calibration), GRAVCAL_FROM(gyro, gyro),
           GRAVCAL_FROM(effects, effects), GRAVCAL_FOR_RESULT(handheld.gyro_nominal_scale)},
          CalibrateTwelvePosition, nullptr, kPoseNoiseUse),
      MakeMethod<TenPositionMethodOptions>(
          Method::kTenPosition, "patent, self-aligned", MethodSideInput::kNone,
          {GRAVCAL_FROM(accel.gravity, calibration.gravity),
           GRAVCAL_FROM(accel.detector, calibration.detector),
           GRAVCAL_FROM(accel.pose_noise, calibration.pose_noise),
           GRAVCAL_FROM(accel.refinement, calibration.refinement),
           GRAVCAL_FROM(accel.allow_undetermined, calibration.allow_undetermined),
           GRAVCAL_FROM(alignment, ten_position)},
          CalibrateTenPosition,
          [](const TenPositionMethodOptions& o, std::string* e) { return o.alignment.IsValid(e); },
          kPoseNoiseUse),
      MakeMethod<KnownAttitudeMethodOptions>(
          Method::kKnownAttitude, "fixture attitudes, --attitudes", MethodSideInput::kAttitudes,
          {GRAVCAL_FROM(accel.gravity, calibration.gravity),
           GRAVCAL_FROM(accel.detector, calibration.detector),
           GRAVCAL_FROM(accel.pose_noise, calibration.pose_noise),
           GRAVCAL_FROM_BASE(RobustLossOptions, accel.refinement, calibration.refinement),
           GRAVCAL_FROM_BASE(PoseVarianceOptions, accel.refinement, calibration.refinement),
           GRAVCAL_FROM(accel.refinement.compute_covariance,
                        calibration.refinement.compute_covariance),
           GRAVCAL_FROM(accel.refinement.max_pose_disturbance,
                        calibration.refinement.max_pose_disturbance),
           GRAVCAL_FROM(accel.refinement.solver, calibration.refinement.solver),
           GRAVCAL_FOR_RESULT(handheld.gyro_nominal_scale)},
          CalibrateKnownAttitude, nullptr, kPoseNoiseUse),
      MakeMethod<HandheldKalmanMethodOptions>(
          Method::kHandheldKalman, "21-state Kalman filter on a handheld log",
          MethodSideInput::kNone,
          {GRAVCAL_FROM(filter, handheld), GRAVCAL_FROM(filter.gravity, calibration.gravity),
           GRAVCAL_FROM(filter.accel_nominal_scale, calibration.nominal_scale),
           Adjust<HandheldKalmanMethodOptions>([](const Config& c, HandheldKalmanMethodOptions* o) {
             o->noise_keys_set = c.keys_set;
           })},
          CalibrateHandheld,
          [](const HandheldKalmanMethodOptions& o, std::string* e) { return o.IsValid(e); },
          "the filter's process noise Q (hk_*_noise_density, hk_*_bias_walk not set as keys)",
          /*keeps_history=*/true),
      MakeMethod<RateTableMethodOptions>(
          Method::kRateTable, "gyroscope from constant-rate segments, --segments",
          MethodSideInput::kSegments, {}, CalibrateRateTable, nullptr, ""),
      MakeMethod<ThermalMethodOptions>(
          Method::kThermal, "bias, scale and misalignment against temperature (issue 35)",
          MethodSideInput::kNone,
          {GRAVCAL_FROM(thermal, thermal),
           GRAVCAL_FROM(thermal.accel_nominal_scale, calibration.nominal_scale),
           GRAVCAL_FROM(thermal.gyro_nominal_scale, handheld.gyro_nominal_scale),
           GRAVCAL_FROM(thermal.max_iterations, calibration.refinement.solver.max_iterations),
           GRAVCAL_FROM(thermal.detector, calibration.detector),
           Adjust<ThermalMethodOptions>(ThermalDetectorDefaults),
           GRAVCAL_FROM(gravity, calibration.gravity)},
          CalibrateThermalMethod,
          [](const ThermalMethodOptions& o, std::string* e) { return o.thermal.IsValid(e); }, ""),
  };
  return methods;
}

#undef GRAVCAL_FROM
#undef GRAVCAL_FROM_BASE
#undef GRAVCAL_FOR_RESULT

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
  // Never destroyed (as the registry): any Config shows where each key is kept.
  static const Config& probe = *new Config;
  for (const void* field : internal::ConfigKeyFields(probe, key.name)) {
    if (method.reads(probe, field)) return true;
  }
  return false;
}

}  // namespace gravcal
