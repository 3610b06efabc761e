#include "gravcal/workflows/method_registry.h"

#include <algorithm>

#include "gravcal/methods/effect_fit.h"
#include "gravcal/methods/gyro_calibration.h"
#include "gravcal/methods/handheld_kalman.h"
#include "gravcal/methods/known_attitude.h"
#include "gravcal/methods/rate_table.h"
#include "gravcal/methods/ten_position.h"
#include "gravcal/methods/twelve_position.h"

namespace gravcal {
namespace {

// The multi-position magnitude fit, then the effects and the gyroscope
// between the poses on the same static intervals.
bool RunTwelvePosition(const Config& config, const MethodData& data, Calibration* calibration) {
  // accel_misalignment on a scale baseline is the scale_misalignment model.
  CalibrationOptions options = config.calibration;
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
  return AddGyroscopeCalibration(*data.log, intervals, config.gyro, calibration);
}

bool RunTenPosition(const Config& config, const MethodData& data, Calibration* calibration) {
  return CalibrateTenPosition(*data.log, config.calibration, config.ten_position, calibration);
}

bool RunKnownAttitude(const Config& config, const MethodData& data, Calibration* calibration) {
  return CalibrateKnownAttitude(*data.log, data.attitudes, data.side_input_name, config.calibration,
                                calibration);
}

// The handheld filter takes its gravity and accelerometer nominal scale
// from the shared sections.
HandheldKalmanOptions HandheldOptions(const Config& config) {
  HandheldKalmanOptions options = config.handheld;
  options.gravity = config.calibration.gravity;
  options.accel_nominal_scale = config.calibration.nominal_scale;
  return options;
}

bool RunHandheldKalman(const Config& config, const MethodData& data, Calibration* calibration) {
  return CalibrateHandheld(*data.log, HandheldOptions(config), calibration);
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
  calibration->warnings.push_back(
      "rate_table calibrates the gyroscope only: the accelerometer model written is the "
      "identity, not an estimate");
  return true;
}

}  // namespace

const std::vector<CalibrationMethod>& CalibrationMethods() {
  static const std::vector<CalibrationMethod> methods = {
      {"twelve_position",
       "multi-position magnitude fit",
       {"gravity", "detector", "model", "solver", "gyro", "effects"},
       {},
       MethodSideInput::kNone,
       nullptr,
       RunTwelvePosition},
      {"ten_position",
       "patent, self-aligned",
       {"gravity", "detector", "alignment"},
       {"parameterization", "allow_undetermined", "loss", "loss_scale", "covariance",
        "max_iterations"},
       MethodSideInput::kNone,
       [](const Config& c, std::string* e) { return c.ten_position.IsValid(e); },
       RunTenPosition},
      {"known_attitude",
       "fixture attitudes, --attitudes",
       {"gravity", "detector"},
       {"loss", "loss_scale", "covariance", "max_iterations"},
       MethodSideInput::kAttitudes,
       nullptr,
       RunKnownAttitude},
      {"handheld_kalman",
       "21-state Kalman filter on a handheld log",
       {"gravity", "handheld_kalman"},
       {"nominal_scale", "gyro_nominal_scale"},
       MethodSideInput::kNone,
       [](const Config& c, std::string* e) { return HandheldOptions(c).IsValid(e); },
       RunHandheldKalman},
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
