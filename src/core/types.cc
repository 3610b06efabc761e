#include "gravcal/core/types.h"

#include <cstddef>

#include "gravcal/core/effect_registry.h"

namespace gravcal {
namespace {

// One row of an enum's table: a value and its string form.
template <typename E>
struct EnumName {
  E value;
  const char* name;
};

template <typename E, std::size_t N>
const char* NameOf(const EnumName<E> (&table)[N], E value) {
  for (const EnumName<E>& row : table) {
    if (row.value == value) return row.name;
  }
  return "unknown";
}

template <typename E, std::size_t N>
bool ValueOf(const EnumName<E> (&table)[N], const std::string& name, E* value) {
  if (value == nullptr) return false;
  for (const EnumName<E>& row : table) {
    if (name == row.name) {
      *value = row.value;
      return true;
    }
  }
  return false;
}

const EnumName<AccelParameterization> kAccelParameterizations[] = {
    {AccelParameterization::kScale, "scale"},
    {AccelParameterization::kScaleMisalignment, "scale_misalignment"},
    {AccelParameterization::kAffine, "affine"},
};

const EnumName<GyroParameterization> kGyroParameterizations[] = {
    {GyroParameterization::kNone, "none"},
    {GyroParameterization::kBias, "bias"},
    {GyroParameterization::kScale, "scale"},
    {GyroParameterization::kFull, "full"},
};

const EnumName<LossType> kLossTypes[] = {
    {LossType::kNone, "none"},      {LossType::kHuber, "huber"},   {LossType::kCauchy, "cauchy"},
    {LossType::kSoftL1, "soft_l1"}, {LossType::kArctan, "arctan"}, {LossType::kTukey, "tukey"},
};

const EnumName<CoarseMethod> kCoarseMethods[] = {
    {CoarseMethod::kSixPosition, "six_position_least_squares"},
    {CoarseMethod::kEllipsoid, "ellipsoid_fit"},
};

const EnumName<RefinementSolver> kRefinementSolvers[] = {
    {RefinementSolver::kCeres, "ceres"},
    {RefinementSolver::kNewton, "newton"},
};

const EnumName<NewtonResidual> kNewtonResiduals[] = {
    {NewtonResidual::kSquaredMagnitude, "squared_magnitude"},
    {NewtonResidual::kMagnitude, "magnitude"},
};

const EnumName<LogFormat> kLogFormats[] = {
    {LogFormat::kCsv, "csv"},
    {LogFormat::kWhitespace, "whitespace"},
};

const EnumName<Method> kMethods[] = {
    {Method::kTwelvePosition, "twelve_position"}, {Method::kTenPosition, "ten_position"},
    {Method::kKnownAttitude, "known_attitude"},   {Method::kHandheldKalman, "handheld_kalman"},
    {Method::kRateTable, "rate_table"},           {Method::kThermal, "thermal"},
};

const EnumName<PoseSet> kPoseSets[] = {
    {PoseSet::kFaces, "faces"},
    {PoseSet::kFacesAnd45, "faces+45"},
    {PoseSet::kFree, "free"},
};

const EnumName<MotionProfile> kMotionProfiles[] = {
    {MotionProfile::kHandheld, "handheld"},
    {MotionProfile::kTurntable, "turntable"},
    {MotionProfile::kVertical, "vertical"},
    {MotionProfile::kRateTable, "rate_table"},
};

const EnumName<PoseScheme> kPoseSchemes[] = {
    {PoseScheme::kSix, "six"},
    {PoseScheme::kTwelve, "twelve"},
    {PoseScheme::kTen, "ten"},
    {PoseScheme::kRandom, "random"},
};

const EnumName<BatchStatus> kBatchStatuses[] = {
    {BatchStatus::kOk, "ok"},
    {BatchStatus::kFailed, "failed"},
    {BatchStatus::kNotConverged, "not_converged"},
};

// The names come from the effects' definitions (core/effect_registry.h).
#define GRAVCAL_EFFECT_NAME(Name) {Effect::k##Name, effects::Name::kName},
const EnumName<Effect> kEffects[] = {GRAVCAL_EFFECTS(GRAVCAL_EFFECT_NAME)};
#undef GRAVCAL_EFFECT_NAME

const EnumName<EffectSensor> kEffectSensors[] = {
    {EffectSensor::kAccelerometer, "accelerometer"},
    {EffectSensor::kGyroscope, "gyroscope"},
};

const EnumName<EffectRegressor> kEffectRegressors[] = {
    {EffectRegressor::kOrientation, "orientation"},
    {EffectRegressor::kTemperature, "temperature"},
    {EffectRegressor::kTime, "time"},
};

const EnumName<RejectionReason> kRejectionReasons[] = {
    {RejectionReason::kTooShort, "too_short"},
    {RejectionReason::kTooMuchMotion, "too_much_motion"},
    {RejectionReason::kRotating, "rotating"},
};

const EnumName<WarningCode> kWarningCodes[] = {
    {WarningCode::kUnclassified, "unclassified"},
    {WarningCode::kStandardGravity, "standard_gravity"},
    {WarningCode::kUndetermined, "undetermined"},
    {WarningCode::kNoCovariance, "no_covariance"},
    {WarningCode::kExactFit, "exact_fit"},
    {WarningCode::kResidualsAboveNoise, "residuals_above_noise"},
    {WarningCode::kPoseScatter, "pose_scatter"},
    {WarningCode::kFewPoses, "few_poses"},
    {WarningCode::kRotationSkipped, "rotation_skipped"},
    {WarningCode::kMethodScope, "method_scope"},
    {WarningCode::kParameterSource, "parameter_source"},
    {WarningCode::kNotStillAtStart, "not_still_at_start"},
    {WarningCode::kLogGap, "log_gap"},
    {WarningCode::kNoiseModel, "noise_model"},
    {WarningCode::kAlignment, "alignment"},
    {WarningCode::kEffectUntestable, "effect_untestable"},
    {WarningCode::kRotationsAboveNoise, "rotations_above_noise"},
    {WarningCode::kSensorData, "sensor_data"},
};

// "a, b or c".
template <typename E, std::size_t N>
std::string NamesOf(const EnumName<E> (&table)[N]) {
  std::string s;
  for (std::size_t i = 0; i < N; ++i) {
    s += std::string(i == 0 ? "" : i + 1 == N ? " or " : ", ") + table[i].name;
  }
  return s;
}

}  // namespace

// Each enum's pair, from its table.
#define GRAVCAL_ENUM_STRINGS(Type, table)                           \
  const char* ToString(Type value) { return NameOf(table, value); } \
  bool FromString(const std::string& name, Type* value) { return ValueOf(table, name, value); }

GRAVCAL_ENUM_STRINGS(AccelParameterization, kAccelParameterizations)
GRAVCAL_ENUM_STRINGS(GyroParameterization, kGyroParameterizations)
GRAVCAL_ENUM_STRINGS(LossType, kLossTypes)
GRAVCAL_ENUM_STRINGS(CoarseMethod, kCoarseMethods)
GRAVCAL_ENUM_STRINGS(RefinementSolver, kRefinementSolvers)
GRAVCAL_ENUM_STRINGS(NewtonResidual, kNewtonResiduals)
GRAVCAL_ENUM_STRINGS(LogFormat, kLogFormats)
GRAVCAL_ENUM_STRINGS(Method, kMethods)
GRAVCAL_ENUM_STRINGS(PoseSet, kPoseSets)
GRAVCAL_ENUM_STRINGS(MotionProfile, kMotionProfiles)
GRAVCAL_ENUM_STRINGS(PoseScheme, kPoseSchemes)
GRAVCAL_ENUM_STRINGS(BatchStatus, kBatchStatuses)
GRAVCAL_ENUM_STRINGS(Effect, kEffects)
GRAVCAL_ENUM_STRINGS(EffectSensor, kEffectSensors)
GRAVCAL_ENUM_STRINGS(EffectRegressor, kEffectRegressors)
GRAVCAL_ENUM_STRINGS(RejectionReason, kRejectionReasons)
GRAVCAL_ENUM_STRINGS(WarningCode, kWarningCodes)

#undef GRAVCAL_ENUM_STRINGS

std::string AcceptedNames(Method) { return NamesOf(kMethods); }
std::string AcceptedNames(PoseSet) { return NamesOf(kPoseSets); }
std::string AcceptedNames(MotionProfile) { return NamesOf(kMotionProfiles); }
// random takes its count.
std::string AcceptedNames(PoseScheme) { return NamesOf(kPoseSchemes) + ":N"; }

}  // namespace gravcal
