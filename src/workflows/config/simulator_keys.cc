// Config sections of `gravcal simulate` and `gravcal demo`, never of a
// calibration method: "simulator" (SimulatorOptions, every sim_* key) and
// "motion simulator" (sim_motion and MotionOptions, the hh_* keys).
#include "workflows/config/config_key.h"

namespace gravcal {
namespace internal {

ConfigSection SimulatorSection() {
  return {
      "simulator",
      ConfigSectionUse::kCommand,
      {
          GRAVCAL_STRING("sim_scheme", simulation.scheme, "six, twelve, ten or random:N"),
          GRAVCAL_DOUBLE("sim_hold", simulation.hold_seconds, "hold per pose, s"),
          GRAVCAL_DOUBLE("sim_initial_still", simulation.initial_still_seconds,
                         "initial still period, s"),
          GRAVCAL_DOUBLE("sim_rotation_time", simulation.rotation_seconds,
                         "rotation between poses, s"),
          GRAVCAL_DOUBLE("sim_sample_rate", simulation.sample_rate, "Hz"),
          GRAVCAL_DOUBLE("sim_gravity", simulation.gravity, "m/s^2"),
          GRAVCAL_BOOL("sim_raw_counts", simulation.raw_counts,
                       "raw output in counts (true) or SI units (false)"),
          GRAVCAL_DOUBLE("sim_accel_counts_per_g", simulation.accel_counts_per_g,
                         "accelerometer counts per g"),
          GRAVCAL_DOUBLE("sim_gyro_counts_per_dps", simulation.gyro_counts_per_dps,
                         "gyroscope counts per deg/s"),
          GRAVCAL_DOUBLE("sim_accel_noise", simulation.accel_noise,
                         "accelerometer white noise per sample, m/s^2"),
          GRAVCAL_DOUBLE("sim_accel_bias_random_walk", simulation.accel_bias_random_walk,
                         "m/s^2/sqrt(s)"),
          GRAVCAL_DOUBLE("sim_gyro_noise", simulation.gyro_noise,
                         "gyroscope white noise per sample, rad/s"),
          GRAVCAL_DOUBLE("sim_gyro_bias_random_walk", simulation.gyro_bias_random_walk,
                         "rad/s/sqrt(s)"),
          GRAVCAL_DOUBLE("sim_accel_bias", simulation.accel_bias_std,
                         "truth accelerometer bias spread, m/s^2"),
          GRAVCAL_DOUBLE("sim_accel_scale", simulation.accel_scale_std,
                         "truth accelerometer scale error spread (fraction)"),
          GRAVCAL_DOUBLE("sim_accel_misalignment", simulation.accel_misalignment_std,
                         "truth accelerometer misalignment spread, rad"),
          GRAVCAL_DOUBLE("sim_gyro_bias", simulation.gyro_bias_std,
                         "truth gyroscope bias spread, rad/s"),
          GRAVCAL_DOUBLE("sim_gyro_scale", simulation.gyro_scale_std,
                         "truth gyroscope scale error spread (fraction)"),
          GRAVCAL_DOUBLE("sim_gyro_misalignment", simulation.gyro_misalignment_std,
                         "truth gyroscope misalignment spread, rad"),
          GRAVCAL_DOUBLE("sim_placement_error", simulation.placement_error_deg,
                         "placement error per pose, degrees"),
          GRAVCAL_DOUBLE("sim_tremor", simulation.tremor,
                         "hand tremor while still, m/s^2 rms (0 = table)"),
          GRAVCAL_DOUBLE("sim_temperature_start", simulation.temperature_start, "deg C"),
          GRAVCAL_DOUBLE("sim_temperature_end", simulation.temperature_end, "deg C"),
          GRAVCAL_DOUBLE("sim_temperature_tau", simulation.temperature_tau,
                         "warm-up time constant, s"),
          GRAVCAL_STRING("sim_rotation_profile", simulation.rotation_profile,
                         "rotations between poses: smooth (fixed axis) or hand (1-4 s, irregular)"),
          GRAVCAL_DOUBLE("sim_hand_min_rotation", simulation.hand_min_seconds,
                         "hand profile: shortest rotation, s"),
          GRAVCAL_DOUBLE("sim_hand_max_rotation", simulation.hand_max_seconds,
                         "hand profile: longest rotation, s"),
          GRAVCAL_DOUBLE("sim_hand_wobble", simulation.hand_wobble_deg,
                         "hand profile: axis wobble, degrees (standard deviation)"),
          GRAVCAL_DOUBLE("sim_gyro_g_sensitivity", simulation.gyro_g_sensitivity_std,
                         "truth gyroscope g-sensitivity spread, rad/s per m/s^2"),
          GRAVCAL_DOUBLE("sim_latitude", simulation.latitude_deg,
                         "the gyroscope senses Earth rate at this latitude, degrees (null = off)"),
          GRAVCAL_DOUBLE("sim_attitude_noise", simulation.fixture_attitude_noise_deg,
                         "noise of the fixture attitudes simulate writes (attitudes.csv), degrees"),
          GRAVCAL_DOUBLE("sim_accel_quadratic", simulation.accel_quadratic_std,
                         "truth k2 spread per axis, 1/(m/s^2)"),
          GRAVCAL_DOUBLE("sim_accel_temperature_bias", simulation.accel_temperature_bias_std,
                         "truth accelerometer bias tempco spread, m/s^2/degC"),
          GRAVCAL_DOUBLE("sim_accel_temperature_scale", simulation.accel_temperature_scale_std,
                         "truth accelerometer scale tempco spread, 1/degC"),
          GRAVCAL_DOUBLE("sim_accel_bias_drift", simulation.accel_bias_drift_std,
                         "truth accelerometer bias drift spread, m/s^2/s"),
          GRAVCAL_DOUBLE("sim_gyro_temperature_bias", simulation.gyro_temperature_bias_std,
                         "truth gyroscope bias tempco spread, rad/s/degC"),
          GRAVCAL_DOUBLE("sim_gyro_bias_drift", simulation.gyro_bias_drift_std,
                         "truth gyroscope bias drift spread, rad/s/s"),
          GRAVCAL_DOUBLE("sim_effect_reference_temperature",
                         simulation.effect_reference_temperature,
                         "temperature at which the simulated temperature terms are zero, degC"),
      }};
}

ConfigSection MotionSimulatorSection() {
  return {
      "motion simulator",
      ConfigSectionUse::kCommand,
      {
          GRAVCAL_STRING(
              "sim_motion", sim_motion,
              "simulate: handheld, turntable, vertical or rate_table (empty = sim_scheme)"),
          GRAVCAL_DOUBLE("hh_initial_still", motion.initial_still_seconds, "still at the start, s"),
          GRAVCAL_DOUBLE("hh_final_still", motion.final_still_seconds, "still at the end, s"),
          GRAVCAL_DOUBLE("hh_seconds_per_axis", motion.seconds_per_axis,
                         "turning time per axis (rate table: per direction), s"),
          GRAVCAL_DOUBLE("hh_rate", motion.rate_dps, "mean turning rate, deg/s"),
          GRAVCAL_DOUBLE("hh_rate_variation", motion.rate_variation,
                         "handheld: relative variation of the hand's rate"),
          GRAVCAL_DOUBLE("hh_axis_wobble", motion.axis_wobble_deg,
                         "handheld: rms wobble of the turning axis, deg"),
          GRAVCAL_DOUBLE("hh_sway", motion.sway, "hand sway, m rms per axis"),
          GRAVCAL_DOUBLE("hh_sway_hz", motion.sway_hz, "highest hand sway frequency, Hz"),
          GRAVCAL_DOUBLE("hh_tremor", motion.tremor, "hand tremor (8-12 Hz), m/s^2 rms per axis"),
          GRAVCAL_DOUBLE("hh_angular_tremor", motion.angular_tremor,
                         "hand tremor (8-12 Hz), rad/s rms per axis"),
          GRAVCAL_INT("hh_rounds", motion.rounds, "times through the x, y, z turns"),
          GRAVCAL_DOUBLE("hh_lever_arm", motion.lever_arm,
                         "sensor distance from the point the hand turns about, m"),
      }};
}

}  // namespace internal
}  // namespace gravcal
