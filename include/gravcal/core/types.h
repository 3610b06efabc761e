// gravcal/core/types.h: every enum of the library with its string forms, in
// one place (as ceres/types.h does). The names are the ones configs, YAML,
// JSON and command-line flags use; ToString gives "unknown" for a value
// outside the enum, FromString returns false (leaving *value unchanged) on
// a name it does not know or a null output, and AcceptedNames gives every
// name ("a, b or c", for errors and help). All three come from one table per
// enum (src/core/enum_names.h); the enums of other headers
// (ThermalOrderSelection, PoseNoise, ComparisonSpace, ExportTarget,
// ThermalProfile, ThermalQuantity, ThermalSensor) get theirs the same way.
#ifndef GRAVCAL_CORE_TYPES_H_
#define GRAVCAL_CORE_TYPES_H_

#include <string>

namespace gravcal {

// Which accelerometer parameters are free.
enum class AccelParameterization {
  // b and diag(U): 6 parameters, R = I, U diagonal.
  kScale,
  // b and U: 9 parameters, R = I. Gauge-free: the sensor x axis defines the
  // body x axis and the sensor xy plane the body xy plane.
  kScaleMisalignment,
  // b, U and R: 12 parameters. R comes from the nominal axes of the poses.
  kAffine,
};
// "scale", "scale_misalignment", "affine".
const char* ToString(AccelParameterization p);
bool FromString(const std::string& name, AccelParameterization* p);
std::string AcceptedNames(AccelParameterization);

// Which gyroscope parameters are free.
enum class GyroParameterization {
  // No gyroscope calibration.
  kNone,
  // b_g and one common scale factor (M_g = s I): 4 parameters.
  kBias,
  // b_g and diag(M_g): 6 parameters.
  kScale,
  // b_g and the full M_g (scale and misalignment): 12 parameters.
  kFull,
};
// "none", "bias", "scale", "full".
const char* ToString(GyroParameterization p);
bool FromString(const std::string& name, GyroParameterization* p);
std::string AcceptedNames(GyroParameterization);

// The robust loss applied to the whitened residuals.
enum class LossType { kNone, kHuber, kCauchy, kSoftL1, kArctan, kTukey };
// "none", "huber", "cauchy", "soft_l1", "arctan", "tukey".
const char* ToString(LossType loss);
bool FromString(const std::string& name, LossType* loss);
std::string AcceptedNames(LossType);

// How the coarse fit found its model.
enum class CoarseMethod { kSixPosition, kEllipsoid };
// "six_position_least_squares", "ellipsoid_fit".
const char* ToString(CoarseMethod method);
bool FromString(const std::string& name, CoarseMethod* method);
std::string AcceptedNames(CoarseMethod);

// Which solver refines the twelve-position fit.
enum class RefinementSolver { kCeres, kNewton };
// "ceres", "newton".
const char* ToString(RefinementSolver solver);
bool FromString(const std::string& name, RefinementSolver* solver);
std::string AcceptedNames(RefinementSolver);

// The residual the Newton baseline minimises.
enum class NewtonResidual {
  // The seed's f_k = |a_k|^2 - g^2, weighted by 1 / (2 g sigma_k).
  kSquaredMagnitude,
  // (|a_k| - g) / sigma_k, the Ceres refinement's residual.
  kMagnitude,
};
// "squared_magnitude", "magnitude".
const char* ToString(NewtonResidual residual);
bool FromString(const std::string& name, NewtonResidual* residual);
std::string AcceptedNames(NewtonResidual);

// Text layout of a log file.
enum class LogFormat {
  // Comma separated with a header row.
  kCsv,
  // Whitespace separated, no header row; `columns` names the columns.
  kWhitespace,
};
// "csv", "whitespace".
const char* ToString(LogFormat format);
bool FromString(const std::string& name, LogFormat* format);
std::string AcceptedNames(LogFormat);

// The calibration methods, the values of the config key `method`
// (workflows/method_registry.h gives each its help, sections and entry
// point).
enum class Method {
  kTwelvePosition,
  kTenPosition,
  kKnownAttitude,
  kHandheldKalman,
  kRateTable,
  kThermal
};
// "twelve_position", "ten_position", "known_attitude", "handheld_kalman",
// "rate_table", "thermal".
const char* ToString(Method method);
bool FromString(const std::string& name, Method* method);
std::string AcceptedNames(Method);

// The candidate poses of a recording plan (`gravcal plan --pose_set`).
enum class PoseSet {
  // The six faces.
  kFaces,
  // The faces and the twelve 45-degree edges.
  kFacesAnd45,
  // Free directions on the sphere.
  kFree,
};
// "faces", "faces+45", "free".
const char* ToString(PoseSet set);
bool FromString(const std::string& name, PoseSet* set);
std::string AcceptedNames(PoseSet);

// The motion of a simulated handheld or rate-table recording.
enum class MotionProfile { kHandheld, kTurntable, kVertical, kRateTable };
// "handheld", "turntable", "vertical", "rate_table".
const char* ToString(MotionProfile profile);
bool FromString(const std::string& name, MotionProfile* profile);
std::string AcceptedNames(MotionProfile);

// The poses of a simulated multi-position session (the simulator's
// sim_scheme: "six", "twelve", "ten" or "random:N", N uniformly drawn
// attitudes; simulation/simulator.h).
enum class PoseScheme { kSix, kTwelve, kTen, kRandom };
// "six", "twelve", "ten", "random" (written random:N in a scheme).
const char* ToString(PoseScheme scheme);
bool FromString(const std::string& name, PoseScheme* scheme);
std::string AcceptedNames(PoseScheme);

// How a simulated multi-position session turns between poses (the
// simulator's sim_rotation_profile).
enum class RotationProfile {
  // Minimum-jerk about one fixed axis, rotation_seconds each.
  kSmooth,
  // Hand-like: random duration, irregular rate, a wobbling axis.
  kHand,
};
// "smooth", "hand".
const char* ToString(RotationProfile profile);
bool FromString(const std::string& name, RotationProfile* profile);
std::string AcceptedNames(RotationProfile);

// How the plate simulator mounts its IMUs (simulation/plate_simulator.h).
enum class PlateMounting {
  // Every IMU stated aligned with the plate.
  kAligned,
  // IMUs after the first get a random stated rotation.
  kRandom,
};
// "aligned", "random".
const char* ToString(PlateMounting mounting);
bool FromString(const std::string& name, PlateMounting* mounting);
std::string AcceptedNames(PlateMounting);

// FromString for the value of a key (config key or flag): false with a
// one-line `error` (may be null) naming the key, the value and the names
// the enum's table accepts: "key 'pose_set': 'edges' is not one of faces,
// faces+45 or free".
template <typename E>
bool ParseName(const std::string& key, const std::string& name, E* value, std::string* error) {
  if (FromString(name, value)) return true;
  if (error != nullptr) {
    *error = "key '" + key + "': '" + name + "' is not one of " + AcceptedNames(E());
  }
  return false;
}

// The outcome of one unit in a batch.
enum class BatchStatus {
  // Calibrated.
  kOk,
  // Bad input, configuration or too little data (`gravcal calibrate` exit 1).
  kFailed,
  // The solver ran and did not converge (`gravcal calibrate` exit 2).
  kNotConverged,
};
// "ok", "failed", "not_converged".
const char* ToString(BatchStatus status);
bool FromString(const std::string& name, BatchStatus* status);
std::string AcceptedNames(BatchStatus);

// The sensor effects beyond the textbook model: one value per effect of the
// registry (core/effect_registry.h defines the enum; model_effects.h holds
// their catalogue: meaning, parameters, units). Names as the effects'
// definitions give them, e.g. "accel_temperature_bias".
enum class Effect : int;
const char* ToString(Effect effect);
bool FromString(const std::string& name, Effect* effect);
std::string AcceptedNames(Effect);

// The sensor an effect acts on.
enum class EffectSensor { kAccelerometer, kGyroscope };
// "accelerometer", "gyroscope".
const char* ToString(EffectSensor sensor);
bool FromString(const std::string& name, EffectSensor* sensor);
std::string AcceptedNames(EffectSensor);

// What an effect's residual varies with: the regressor plotted in reports.
enum class EffectRegressor { kOrientation, kTemperature, kTime };
// "orientation", "temperature", "time".
const char* ToString(EffectRegressor regressor);
bool FromString(const std::string& name, EffectRegressor* regressor);
std::string AcceptedNames(EffectRegressor);

// Why a stretch of a log that looked like a pose is not a static interval
// (detection/static_detector.h).
enum class RejectionReason {
  // Still, but shorter than min_duration_seconds once settle_seconds is
  // trimmed from each end (or nothing left after trimming).
  kTooShort,
  // Nearly still, but the accelerometer's variance was above its threshold
  // (a disturbed or hand-held pose).
  kTooMuchMotion,
  // The accelerometer was still, but the gyroscope's variance was above its
  // threshold (turning about the gravity direction).
  kRotating,
};
// "too_short", "too_much_motion", "rotating".
const char* ToString(RejectionReason reason);
bool FromString(const std::string& name, RejectionReason* reason);
std::string AcceptedNames(RejectionReason);

// What kind of thing a warning says. Every warning a method adds to a
// result (Calibration::warnings and the results it is built from) has its
// code at the same index of the result's warning_codes, so that a reader
// (the HTML report) can explain it and name the action that fixes it
// without parsing the message. The message is for people and is what the
// calibration JSON holds; the code is not written there.
enum class WarningCode {
  // Added without a code: a bug (the report flags it as unexplained).
  kUnclassified,
  // No local gravity given: standard gravity used.
  kStandardGravity,
  // The poses or the motion do not determine some parameters (named in the
  // message); they are held and reported without a standard deviation.
  kUndetermined,
  // The covariance could not be computed: no standard deviations.
  kNoCovariance,
  // As many equations as unknowns: the fit cannot check itself.
  kExactFit,
  // The residuals are larger than the noise predicts (chi-square test).
  kResidualsAboveNoise,
  // The poses scatter beyond what their samples show (pose variance).
  kPoseScatter,
  // Fewer poses than the procedure recommends.
  kFewPoses,
  // A stretch between poses too long to be used as a gyroscope rotation.
  kRotationSkipped,
  // What the method cannot estimate by design (named in the message).
  kMethodScope,
  // Where some numbers come from (housing rotation, joint fit, ...).
  kParameterSource,
  // The handheld run did not start still.
  kNotStillAtStart,
  // The log has a gap between samples.
  kLogGap,
  // About the noise model used for the poses or the filter.
  kNoiseModel,
  // A self-alignment could not determine roll or heading.
  kAlignment,
  // Discovery: an effect of the catalogue cannot be tested in this session
  // (no gyroscope or temperature column, too few poses, not identified).
  kEffectUntestable,
  // The rotations between poses exceed their noise (a gyroscope
  // g-sensitivity, a turn the gyroscope does not integrate); they are left
  // out of the fits.
  kRotationsAboveNoise,
  // The data break what the model assumes, and the message names how: a
  // saturated axis, a left-handed fitted matrix (a flipped or swapped axis),
  // a detected position that is not one still pose.
  kSensorData,
};
// "unclassified", "standard_gravity", "undetermined", "no_covariance",
// "exact_fit", "residuals_above_noise", "pose_scatter", "few_poses",
// "rotation_skipped", "method_scope", "parameter_source",
// "not_still_at_start", "log_gap", "noise_model", "alignment",
// "effect_untestable", "rotations_above_noise", "sensor_data".
const char* ToString(WarningCode code);
bool FromString(const std::string& name, WarningCode* code);
std::string AcceptedNames(WarningCode);

}  // namespace gravcal

#endif  // GRAVCAL_CORE_TYPES_H_
