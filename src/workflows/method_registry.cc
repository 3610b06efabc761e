#include "gravcal/workflows/method_registry.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include "core/warnings.h"
#include "gravcal/io/noise_io.h"
#include "gravcal/methods/effect_fit.h"
#include "gravcal/methods/gyro_calibration.h"
#include "gravcal/methods/handheld_kalman.h"
#include "gravcal/methods/known_attitude.h"
#include "gravcal/methods/rate_table.h"
#include "gravcal/methods/ten_position.h"
#include "gravcal/methods/twelve_position.h"

namespace gravcal {
namespace {

// The shared calibration options with the noise model, when given, for
// the covariance of each pose's mean.
CalibrationOptions StaticOptions(const Config& config, const MethodData& data) {
  CalibrationOptions options = config.calibration;
  options.pose_noise.model = data.noise;
  return options;
}

constexpr char kPoseNoiseUse[] =
    "the variance of each pose's mean (Allan variance at the pose's duration)";

// The multi-position magnitude fit, then the effects and the gyroscope
// between the poses on the same static intervals.
bool RunTwelvePosition(const Config& config, const MethodData& data, Calibration* calibration) {
  // accel_misalignment on a scale baseline is the scale_misalignment model.
  CalibrationOptions options = StaticOptions(config, data);
  if (Contains(config.effects, Effect::kAccelMisalignment) &&
      options.refinement.parameterization == AccelParameterization::kScale) {
    options.refinement.parameterization = AccelParameterization::kScaleMisalignment;
  }
  // Detected once; the effect and gyroscope steps reuse the intervals.
  std::vector<StaticInterval> intervals;
  bool ok = CalibrateAccelerometer(*data.log, options, calibration, &intervals);
  if (ok && !config.effects.empty()) {
    ok = FitCalibrationEffects(*data.log, intervals, options, config.effects, calibration);
  }
  if (!ok || config.gyro.parameterization == GyroParameterization::kNone) return ok;
  GyroCalibrationOptions gyro = config.gyro;
  gyro.noise_model = data.noise;
  return AddGyroscopeCalibration(*data.log, intervals, gyro, calibration);
}

bool RunTenPosition(const Config& config, const MethodData& data, Calibration* calibration) {
  return CalibrateTenPosition(*data.log, StaticOptions(config, data), config.ten_position,
                              calibration);
}

bool RunKnownAttitude(const Config& config, const MethodData& data, Calibration* calibration) {
  return CalibrateKnownAttitude(*data.log, data.attitudes, data.side_input_name,
                                StaticOptions(config, data), calibration);
}

// The handheld filter takes its gravity and accelerometer nominal scale
// from the shared sections.
HandheldKalmanOptions HandheldOptions(const Config& config) {
  HandheldKalmanOptions options = config.handheld;
  options.gravity = config.calibration.gravity;
  options.accel_nominal_scale = config.calibration.nominal_scale;
  return options;
}

// The filter's process noise Q from the noise model: each density the user
// did not set as a key is the largest of the three axes' values (as
// `gravcal noise --handheld` writes them; conservative: no axis is trusted
// more than its noise allows). Returns the note saying where Q came from.
std::string NoiseModelQ(const Config& config, const MethodData& data,
                        HandheldKalmanOptions* options) {
  struct Density {
    const char* key;
    const std::array<AxisNoiseModel, 3>* axes;
    NoiseTerm AxisNoiseModel::*term;
    double* field;
  };
  const ImuNoiseModel& m = *data.noise;
  const Density densities[] = {
      {"hk_accel_noise_density", &m.accel, &AxisNoiseModel::white_noise,
       &options->accel_noise_density},
      {"hk_gyro_noise_density", &m.gyro, &AxisNoiseModel::white_noise,
       &options->gyro_noise_density},
      {"hk_accel_bias_walk", &m.accel, &AxisNoiseModel::random_walk, &options->accel_bias_walk},
      {"hk_gyro_bias_walk", &m.gyro, &AxisNoiseModel::random_walk, &options->gyro_bias_walk},
  };
  std::string from_model, from_config, not_shown;
  for (const Density& d : densities) {
    const bool set =
        std::find(config.keys_set.begin(), config.keys_set.end(), d.key) != config.keys_set.end();
    const double v = AxisMaximum(*d.axes, d.term);
    if (set) {
      from_config += (from_config.empty() ? "" : ", ") + std::string(d.key);
    } else if (std::isfinite(v)) {
      *d.field = v;
      std::ostringstream s;
      s.precision(3);
      s << d.key << " " << v;
      from_model += (from_model.empty() ? "" : ", ") + s.str();
    } else {
      not_shown += (not_shown.empty() ? "" : ", ") + std::string(d.key);
    }
  }
  std::string note = "handheld filter Q: ";
  note += from_model.empty() ? "nothing" : from_model + " (largest axis)";
  note += " from the noise model " + data.noise_name;
  if (!from_config.empty()) note += "; " + from_config + " as set in the config";
  if (!not_shown.empty()) note += "; " + not_shown + " at the default (not shown by the model)";
  return note;
}

bool RunHandheldKalman(const Config& config, const MethodData& data, Calibration* calibration) {
  HandheldKalmanOptions options = HandheldOptions(config);
  const std::string note = data.noise != nullptr ? NoiseModelQ(config, data, &options) : "";
  const bool ok = CalibrateHandheld(*data.log, options, calibration);
  if (!note.empty()) {
    internal::AddWarning(WarningCode::kNoiseModel, note, &calibration->warnings,
                         &calibration->warning_codes);
  }
  return ok;
}

// The gyroscope alone; the accelerometer part of the result stays the
// identity, and a warning says so.
bool RunRateTable(const Config&, const MethodData& data, Calibration* calibration) {
  *calibration = Calibration();
  RateTableResult result;
  const bool ok = CalibrateRateTable(*data.log, data.segments, &result);
  calibration->message = result.message;
  if (!ok) return false;
  calibration->success = true;
  calibration->gyro = result.gyro;
  calibration->solver_name = "weighted linear least squares per gyroscope axis";
  internal::AddWarning(WarningCode::kMethodScope,
                       "rate_table calibrates the gyroscope only: the accelerometer model "
                       "written is the identity, not an estimate",
                       &calibration->warnings, &calibration->warning_codes);
  return true;
}

}  // namespace

const std::vector<CalibrationMethod>& CalibrationMethods() {
  // Never destroyed (Google style for static storage): a batch worker abandoned
  // with a hung unit may still read it while the process exits (found by TSan).
  static const std::vector<CalibrationMethod>& methods = *new std::vector<CalibrationMethod>{
      {"twelve_position",
       "multi-position magnitude fit",
       {"gravity", "detector", "pose_noise", "model", "solver", "gyro", "effects"},
       {},
       MethodSideInput::kNone,
       nullptr,
       RunTwelvePosition,
       kPoseNoiseUse},
      {"ten_position",
       "patent, self-aligned",
       {"gravity", "detector", "pose_noise", "alignment"},
       {"parameterization", "allow_undetermined", "loss", "loss_scale", "covariance",
        "max_iterations", "pose_variance", "max_pose_disturbance", "structure_test_level",
        "pose_disturbance_prior", "pose_disturbance_prior_dof", "prior_conflict_level"},
       MethodSideInput::kNone,
       [](const Config& c, std::string* e) { return c.ten_position.IsValid(e); },
       RunTenPosition,
       kPoseNoiseUse},
      {"known_attitude",
       "fixture attitudes, --attitudes",
       {"gravity", "detector", "pose_noise"},
       {"loss", "loss_scale", "covariance", "max_iterations", "pose_variance",
        "max_pose_disturbance", "pose_disturbance_prior", "pose_disturbance_prior_dof"},
       MethodSideInput::kAttitudes,
       nullptr,
       RunKnownAttitude,
       kPoseNoiseUse},
      {"handheld_kalman",
       "21-state Kalman filter on a handheld log",
       {"gravity", "handheld_kalman"},
       {"nominal_scale", "gyro_nominal_scale"},
       MethodSideInput::kNone,
       [](const Config& c, std::string* e) { return HandheldOptions(c).IsValid(e); },
       RunHandheldKalman,
       "the filter's process noise Q (hk_*_noise_density, hk_*_bias_walk not set as keys)"},
      {"rate_table",
       "gyroscope from constant-rate segments, --segments",
       {},
       {},
       MethodSideInput::kSegments,
       nullptr,
       RunRateTable},
  };
  return methods;
}

const CalibrationMethod* FindCalibrationMethod(const std::string& name) {
  for (const CalibrationMethod& m : CalibrationMethods()) {
    if (m.name == name) return &m;
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
