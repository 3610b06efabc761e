// Config sections "pose_noise" (CalibrationOptions::pose_noise, the
// covariance of each static pose's mean; the methods that make static
// positions read it) and "noise" (`gravcal noise`, NoiseOptions; no method
// reads it). The noise command takes its raw units from nominal_scale and
// gyro_nominal_scale and its still-interval search from the detector keys.
#include "workflows/config/config_key.h"

namespace gravcal {
namespace internal {

namespace {

bool ReadNominalOffset(const YAML::Node& n, CalibrationConfig* c, std::string* e) {
  double v = 0.0;
  if (!ReadDouble(n, &v, e)) return false;
  c->noise.accel_offset.setConstant(v);
  return true;
}

}  // namespace

SectionOf<CalibrationConfig> PoseNoiseSection() {
  return {"pose_noise",
          ConfigSectionUse::kSomeMethods,
          {
              GRAVCAL_ENUM("pose_noise", calibration.pose_noise.method,
                           "variance of each pose's mean when no --noise model is given (white: "
                           "sample covariance / n; batch_means: from the pose's own batches, "
                           "counts correlated noise)"),
              GRAVCAL_INT("pose_noise_batches", calibration.pose_noise.batches,
                          "batch_means: batches per pose (>= 5)"),
          }};
}

SectionOf<CalibrationConfig> NoiseSection() {
  return {"noise",
          ConfigSectionUse::kCommand,
          {
              GRAVCAL_BOOL("noise_find_still", noise.find_still,
                           "noise: use the longest still interval the detector finds (false: the "
                           "whole log, which must be still throughout)"),
              GRAVCAL_DOUBLE("noise_max_tau", noise.allan.max_tau,
                             "noise: largest Allan tau asked for, s (0 = as far as "
                             "noise_max_tau_fraction allows); a shorter log is refused"),
              GRAVCAL_DOUBLE("noise_max_tau_fraction", noise.allan.max_tau_fraction,
                             "noise: largest tau as a fraction of the still interval"),
              GRAVCAL_INT("noise_points_per_octave", noise.allan.points_per_octave,
                          "noise: Allan curve points per octave of tau"),
              GRAVCAL_DOUBLE("noise_time_step_tolerance", noise.allan.time_step_tolerance,
                             "noise: largest relative deviation of a time step from the median "
                             "before the log counts as non-uniform"),
              GRAVCAL_DOUBLE("noise_confidence", noise.allan.confidence,
                             "noise: two-sided probability of the Allan confidence intervals"),
              GRAVCAL_DOUBLE("noise_rate", noise.rate_hz,
                             "noise: the sample rate, Hz (0 = from the time stamps: 1 / median "
                             "step, or least squares of time on sample index when they jitter)"),
              GRAVCAL_DOUBLE("noise_max_time_bias", noise.max_time_bias,
                             "noise: jittering time stamps are refused when taking the samples as "
                             "uniform could bias the Allan deviation by more than this (relative) "
                             "at the longest tau"),
              GRAVCAL_KEY("nominal_offset",
                          "noise: raw accelerometer value at zero specific force on every axis "
                          "(32768 for unsigned 16-bit counts, 1.65 for a 3.3 V analog part), to "
                          "check the unit against gravity; 0 = none stated",
                          ReadNominalOffset(n, c, e), DoubleText(c.noise.accel_offset.x())),
              GRAVCAL_DOUBLE("noise_max_tilt", noise.max_tilt_deg,
                             "noise: with noise_find_still false, the log counts as moving when "
                             "gravity turns by more than this between its tenths, degrees"),
          }};
}

}  // namespace internal
}  // namespace gravcal
