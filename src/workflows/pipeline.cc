#include "gravcal/workflows/pipeline.h"

#include <algorithm>
#include <cmath>

#include "core/sensor_checks.h"
#include "core/warnings.h"
#include "gravcal/io/noise_io.h"
#include "gravcal/workflows/method_registry.h"
#include "gravcal/workflows/rate_table_segments.h"
#include "methods/static_positions.h"
#include "util/source_prefix.h"

namespace gravcal {
namespace {

// Reads the side input `method` needs into `session`.
bool ReadSideInput(const CalibrationMethod& method, const SessionFiles& files, Session* session,
                   std::string* error) {
  switch (method.side_input) {
    case MethodSideInput::kNone:
      return true;
    case MethodSideInput::kAttitudes:
      session->attitudes_name = files.attitudes_path;
      if (files.attitudes_path.empty()) {
        *error = method.name + " needs the attitudes file (--attitudes fixture.csv)";
        return false;
      }
      return ReadFixtureAttitudes(files.attitudes_path, &session->attitudes, error);
    case MethodSideInput::kSegments:
      session->segments_name = files.segments_path;
      if (files.segments_path.empty()) {
        *error = method.name + " needs the segments file (--segments segments.csv)";
        return false;
      }
      return ReadRateTableSegments(files.segments_path, session->log, &session->segments, error);
  }
  return true;
}

// Reads the noise model, when given, for a method that uses one.
bool ReadNoiseModel(const CalibrationMethod& method, const SessionFiles& files, Session* session,
                    std::string* error) {
  if (files.noise_path.empty()) return true;
  if (method.noise_model.empty()) {
    *error = "method '" + method.name + "' uses no noise model (remove --noise " +
             files.noise_path + ")";
    return false;
  }
  ImuNoise noise;
  if (!ReadNoiseJson(files.noise_path, &noise, error)) return false;
  session->noise = noise.model;
  session->noise_name = files.noise_path;
  return true;
}

}  // namespace

bool RunCalibration(const Config& config, const PipelineInput& input, Calibration* calibration) {
  Session session;
  session.log = input.log;
  return RunCalibration(config, input, &session, calibration);
}

bool RunCalibration(const Config& config, const SessionFiles& files, Session* session,
                    Calibration* calibration) {
  *calibration = Calibration();
  std::string error;
  if (!config.IsValid(&error)) {
    calibration->message = error;
    return false;
  }
  const CalibrationMethod& method = *FindCalibrationMethod(config.method);
  if (!ReadNoiseModel(method, files, session, &error) ||
      !ReadSideInput(method, files, session, &error)) {
    calibration->method = method.name;
    calibration->message = error;
    return false;
  }
  // Detected once here (for a method whose options embed the detector); the
  // method, the report and the check read it. A failed detection is the
  // method's to report, at its own step.
  if (method.reads(config, &config.calibration.detector)) {
    DetectSessionPoses(config.calibration.detector, session);
  }
  const bool ok = method.run(config, *session, calibration);
  calibration->method = method.name;
  // Issue 36: the gyroscope's noise in each hold (the acceptance limits'
  // gyro_noise_density); without a gyroscope model only a stated raw unit.
  const bool scale_set = std::find(config.keys_set.begin(), config.keys_set.end(),
                                   "gyro_nominal_scale") != config.keys_set.end();
  internal::MeasureGyroHoldNoise(session->log, scale_set ? config.handheld.gyro_nominal_scale : NAN,
                                 calibration);
  // Issue 33: a gyroscope whose axes disagree with the accelerometer's
  // convention (a flipped or swapped axis), named for every method.
  const std::string convention = internal::GyroAxisConventionWarning(session->log);
  if (!convention.empty()) {
    internal::AddWarning(WarningCode::kSensorData,
                         internal::PrefixSource(session->log.source, convention),
                         &calibration->warnings, &calibration->warning_codes);
    // A filter that ran away on such a log did so for that reason first.
    if (!ok && calibration->not_converged) {
      calibration->message +=
          "; first fix the gyroscope's axis convention (the warning above names it): "
          "integrated with the wrong signs, the turns diverge";
    }
  }
  return ok;
}

}  // namespace gravcal
