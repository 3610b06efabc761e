#include "gravcal/core/types.h"

#include <cstddef>

#include "core/enum_names.h"
#include "gravcal/core/effect_registry.h"

namespace gravcal {
namespace {

using internal::EnumName;

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

const EnumName<RotationProfile> kRotationProfiles[] = {
    {RotationProfile::kSmooth, "smooth"},
    {RotationProfile::kHand, "hand"},
};

const EnumName<PlateMounting> kPlateMountings[] = {
    {PlateMounting::kAligned, "aligned"},
    {PlateMounting::kRandom, "random"},
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

}  // namespace

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
GRAVCAL_ENUM_TO_FROM_STRING(PoseScheme, kPoseSchemes)
GRAVCAL_ENUM_STRINGS(RotationProfile, kRotationProfiles)
GRAVCAL_ENUM_STRINGS(PlateMounting, kPlateMountings)
GRAVCAL_ENUM_STRINGS(BatchStatus, kBatchStatuses)
GRAVCAL_ENUM_STRINGS(Effect, kEffects)
GRAVCAL_ENUM_STRINGS(EffectSensor, kEffectSensors)
GRAVCAL_ENUM_STRINGS(EffectRegressor, kEffectRegressors)
GRAVCAL_ENUM_STRINGS(RejectionReason, kRejectionReasons)
GRAVCAL_ENUM_STRINGS(WarningCode, kWarningCodes)

// random takes its count.
std::string AcceptedNames(PoseScheme) { return internal::NamesOf(kPoseSchemes) + ":N"; }

}  // namespace gravcal
