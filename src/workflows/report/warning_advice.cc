#include "workflows/report/warning_advice.h"

namespace gravcal {
namespace internal {

WarningAdvice AdviceFor(WarningCode code) {
  switch (code) {
    case WarningCode::kUnclassified:
      break;
    case WarningCode::kStandardGravity:
      return {
          "No local gravity was given, so standard gravity was used; local gravity differs "
          "from it by up to 0.3 %, which the scale factors absorb.",
          "Give the local gravity (config key gravity), or latitude and height."};
    case WarningCode::kUndetermined:
      return {
          "The session does not determine the parameters named: they are held (at the "
          "coarse fit's or the prior's value) and reported without a standard deviation.",
          "Record more poses or motion that exercise them, as the message says (other axes "
          "up and down, turns about the named axis), or choose a smaller parameterization."};
    case WarningCode::kNoCovariance:
      return {"The covariance could not be computed: no standard deviation is reported.",
              "Record more poses (or fit fewer parameters) so that every parameter is "
              "determined."};
    case WarningCode::kExactFit:
      return {
          "There are as many equations as unknowns: the fit passes through every pose and "
          "cannot show whether it is right.",
          "Record more poses than the model has parameters."};
    case WarningCode::kResidualsAboveNoise:
      return {
          "The residuals are larger than the noise of the poses predicts: a pose was "
          "disturbed, or the sensor has an effect the model lacks; the standard deviations "
          "are too small by about the factor given.",
          "Look at the poses beyond 3 sigma in the residual plot and re-record a disturbed "
          "one; run `gravcal discover` on this log to name a missing effect."};
    case WarningCode::kPoseScatter:
      return {
          "The poses scatter more than their own samples show; the standard deviations "
          "include that scatter.",
          "Hold the unit more firmly (a stable fixture, no cable pull) and record more "
          "poses; `gravcal discover` tells whether an effect explains the scatter."};
    case WarningCode::kFewPoses:
      return {"Fewer poses than the procedure recommends: less averaging of the noise.",
              "Record the full set of poses."};
    case WarningCode::kRotationSkipped:
      return {"A stretch between two poses was too long to be used as a gyroscope rotation.",
              "Turn from pose to pose without pausing in between, or raise "
              "max_rotation_seconds."};
    case WarningCode::kMethodScope:
      return {
          "This method cannot estimate what the message names, by design; nothing is wrong "
          "with the session.",
          "Use the method the message names (known_attitude, or a static method for the "
          "accelerometer) when those parameters are needed."};
    case WarningCode::kParameterSource:
      return {"Says where some of the numbers come from, and so how far they can be trusted.",
              "Nothing to do unless the accuracy stated is not enough for you."};
    case WarningCode::kNotStillAtStart:
      return {"The run did not start still, so the initial roll and pitch may be off.",
              "Hold the unit still for the first seconds of the recording."};
    case WarningCode::kLogGap:
      return {"The log has a gap; the filter runs blind across it.",
              "Check the logger for dropped samples and record again without gaps."};
    case WarningCode::kNoiseModel:
      return {"About the noise model used to weight the poses or tune the filter.",
              "Run `gravcal noise` on a still recording of this sensor and pass it with "
              "--noise, with the same nominal scales."};
    case WarningCode::kAlignment:
      return {"A self-alignment could not determine roll or heading, as the message says.",
              "Expected near +-90 degrees pitch or without gyrocompassing; give the latitude "
              "(and a gyroscope good enough) when the heading is needed."};
    case WarningCode::kEffectUntestable:
      return {
          "An effect of the catalogue cannot be tested on this session, for the reason the "
          "message gives; the verdict says nothing about it.",
          "Record what the message asks for (a temperature column, a gyroscope, more or "
          "longer poses, a temperature change) when that effect matters."};
    case WarningCode::kRotationsAboveNoise:
      return {
          "The gyroscope's turns between the poses disagree with the accelerometer beyond "
          "their noise even with every accelerometer effect, so they were left out: the "
          "decisions use the magnitudes (and the within-pose trends) only.",
          "Fit the gyroscope's g-sensitivity first (gravcal discover names it), or turn "
          "more slowly and steadily between the poses."};
    case WarningCode::kSensorData:
      return {
          "The data break what the model assumes, as the message names: a saturated axis, "
          "a flipped or swapped axis (a left-handed matrix), or a position that was not "
          "held still; the residuals alone would only say they are large.",
          "Do what the message says: fix the axis convention, record with a larger range, "
          "or hold the named pose still and record it again."};
  }
  return {"", ""};
}

}  // namespace internal
}  // namespace gravcal
