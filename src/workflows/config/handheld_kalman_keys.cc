// Config section "handheld_kalman": the handheld Kalman calibration
// (HandheldKalmanOptions, handheld_kalman.h; its gravity and accelerometer
// nominal scale come from the gravity and model sections).
#include "workflows/config/config_key.h"

namespace gravcal {
namespace internal {

namespace {

bool ReadCrossAxis(const YAML::Node& n, CalibrationConfig* c, std::string* e) {
  bool on = false;
  if (!ReadBool(n, &on, e)) return false;
  c->handheld.accel_terms =
      on ? SensorErrorTerms::ScaleAndUpperCrossAxis() : SensorErrorTerms::ScaleOnly();
  c->handheld.gyro_terms =
      on ? SensorErrorTerms::ScaleAndCrossAxis() : SensorErrorTerms::ScaleOnly();
  return true;
}

}  // namespace

SectionOf<CalibrationConfig> HandheldKalmanSection() {
  return {
      "handheld_kalman",
      ConfigSectionUse::kSomeMethods,
      {
          GRAVCAL_DOUBLE("hk_still_seconds", handheld.still_seconds,
                         "initial still period for roll and pitch, s"),
          GRAVCAL_INT("hk_passes", handheld.passes,
                      "passes over the log; later ones start from the previous estimates"),
          GRAVCAL_DOUBLE(
              "hk_update_interval", handheld.update_interval,
              "time between zero-velocity/position updates, s (~ hand motion correlation)"),
          GRAVCAL_DOUBLE("hk_velocity_noise", handheld.velocity_noise,
                         "how fast the hand moves the unit, m/s (zero-velocity measurement noise)"),
          GRAVCAL_DOUBLE("hk_position_noise", handheld.position_noise,
                         "how far the hand moves the unit, m (zero-position measurement noise)"),
          GRAVCAL_DOUBLE("hk_accel_noise_density", handheld.accel_noise_density,
                         "accelerometer noise density, m/s^2/sqrt(Hz) (Allan deviation at 1 s)"),
          GRAVCAL_DOUBLE("hk_gyro_noise_density", handheld.gyro_noise_density,
                         "gyroscope noise density, rad/s/sqrt(Hz) (Allan deviation at 1 s)"),
          GRAVCAL_DOUBLE("hk_accel_bias_walk", handheld.accel_bias_walk,
                         "accelerometer bias random walk, m/s^2/sqrt(s) (0 = constant)"),
          GRAVCAL_DOUBLE("hk_gyro_bias_walk", handheld.gyro_bias_walk,
                         "gyroscope bias random walk, rad/s/sqrt(s) (0 = constant)"),
          GRAVCAL_DOUBLE("hk_accel_bias_std", handheld.accel_bias_std,
                         "prior accelerometer bias, m/s^2"),
          GRAVCAL_DOUBLE("hk_accel_scale_std", handheld.accel_scale_std,
                         "prior accelerometer scale-factor error (fraction)"),
          GRAVCAL_DOUBLE("hk_gyro_bias_std", handheld.gyro_bias_std, "prior gyroscope bias, rad/s"),
          GRAVCAL_DOUBLE("hk_gyro_scale_std", handheld.gyro_scale_std,
                         "prior gyroscope scale-factor error (fraction)"),
          GRAVCAL_KEY_AT(
              "hk_cross_axis",
              "also estimate cross-axis terms (accelerometer upper-triangular, gyroscope full)",
              ReadCrossAxis(n, c, e),
              std::string(c.handheld.gyro_terms.matrix_entries.size() > 3 ? "true" : "false"),
              &c.handheld.accel_terms, &c.handheld.gyro_terms),
          GRAVCAL_DOUBLE("hk_cross_axis_std", handheld.cross_axis_std,
                         "prior cross-axis term (with hk_cross_axis), rad"),
          GRAVCAL_BOOL("hk_lever_arm", handheld.estimate_lever_arm,
                       "also estimate the sensor's offset from the point the hand turns about"),
          GRAVCAL_DOUBLE("hk_lever_arm_std", handheld.lever_arm_std,
                         "prior lever arm (with hk_lever_arm), m"),
          GRAVCAL_DOUBLE("hk_initial_attitude_std", handheld.initial_attitude_std,
                         "initial roll/pitch error beyond the accelerometer's, rad"),
          GRAVCAL_BOOL("hk_earth_rate", handheld.earth_rate,
                       "include the Earth rate (needs latitude)"),
          GRAVCAL_DOUBLE(
              "hk_convergence_fraction", handheld.convergence_fraction,
              "converged once estimate (vs final) and sigma stay below this x prior sigma; "
              "not determined when the final sigma is above it"),
      }};
}

}  // namespace internal
}  // namespace gravcal
