// The table of simulator_fields.h: every keyed field of SimulatorOptions.
#include "simulation/simulator_fields.h"

namespace gravcal {
namespace internal {

const std::vector<SimulatorField>& SimulatorFields() {
  // Never destroyed (Google style for static storage).
  static const std::vector<SimulatorField>& fields = *new std::vector<SimulatorField>([] {
    std::vector<SimulatorField> rows = {
        {"sim_scheme", "scheme", AcceptedNames(PoseScheme()), &SimulatorOptions::scheme},
        {"sim_hold", "hold_seconds", "hold per pose, s", &SimulatorOptions::hold_seconds},
        {"sim_initial_still", "initial_still_seconds", "initial still period, s",
         &SimulatorOptions::initial_still_seconds},
        {"sim_rotation_time", "rotation_seconds", "rotation between poses, s",
         &SimulatorOptions::rotation_seconds},
        {"sim_sample_rate", "sample_rate", "Hz", &SimulatorOptions::sample_rate},
        {"sim_gravity", "gravity", "m/s^2", &SimulatorOptions::gravity},
        {"sim_raw_counts", "raw_counts", "raw output in counts (true) or SI units (false)",
         &SimulatorOptions::raw_counts},
        {"sim_accel_counts_per_g", "accel_counts_per_g", "accelerometer counts per g",
         &SimulatorOptions::accel_counts_per_g},
        {"sim_gyro_counts_per_dps", "gyro_counts_per_dps", "gyroscope counts per deg/s",
         &SimulatorOptions::gyro_counts_per_dps},
        {"sim_accel_noise", "accel_noise", "accelerometer white noise per sample, m/s^2",
         &SimulatorOptions::accel_noise},
        {"sim_accel_bias_random_walk", "accel_bias_random_walk", "m/s^2/sqrt(s)",
         &SimulatorOptions::accel_bias_random_walk},
        {"sim_gyro_noise", "gyro_noise", "gyroscope white noise per sample, rad/s",
         &SimulatorOptions::gyro_noise},
        {"sim_gyro_bias_random_walk", "gyro_bias_random_walk", "rad/s/sqrt(s)",
         &SimulatorOptions::gyro_bias_random_walk},
        {"sim_accel_bias", "accel_bias_std", "truth accelerometer bias spread, m/s^2",
         &SimulatorOptions::accel_bias_std},
        {"sim_accel_scale", "accel_scale_std", "truth accelerometer scale error spread (fraction)",
         &SimulatorOptions::accel_scale_std},
        {"sim_accel_misalignment", "accel_misalignment_std",
         "truth accelerometer misalignment spread, rad", &SimulatorOptions::accel_misalignment_std},
        {"sim_gyro_bias", "gyro_bias_std", "truth gyroscope bias spread, rad/s",
         &SimulatorOptions::gyro_bias_std},
        {"sim_gyro_scale", "gyro_scale_std", "truth gyroscope scale error spread (fraction)",
         &SimulatorOptions::gyro_scale_std},
        {"sim_gyro_misalignment", "gyro_misalignment_std",
         "truth gyroscope misalignment spread, rad", &SimulatorOptions::gyro_misalignment_std},
        {"sim_placement_error", "placement_error_deg", "placement error per pose, degrees",
         &SimulatorOptions::placement_error_deg},
        {"sim_tremor", "tremor", "hand tremor while still, m/s^2 rms (0 = table)",
         &SimulatorOptions::tremor},
        {"sim_pose_disturbance", "pose_disturbance",
         "specific-force offset per pose the samples cannot show, m/s^2 per axis (0 = off)",
         &SimulatorOptions::pose_disturbance},
        {"sim_accel_bias_instability", "accel_bias_instability",
         "accelerometer bias instability B, m/s^2 (0 = off)",
         &SimulatorOptions::accel_bias_instability},
        {"sim_gyro_bias_instability", "gyro_bias_instability",
         "gyroscope bias instability B, rad/s (0 = off)", &SimulatorOptions::gyro_bias_instability},
        {"sim_bias_instability_tau_low", "bias_instability_tau_low",
         "bias instability flat from this tau, s", &SimulatorOptions::bias_instability_tau_low},
        {"sim_bias_instability_tau_high", "bias_instability_tau_high",
         "bias instability flat up to this tau, s", &SimulatorOptions::bias_instability_tau_high},
        {"sim_accel_tone", "accel_tone",
         "accelerometer tone amplitude on sim_tone_axis, m/s^2 (0 = off)",
         &SimulatorOptions::accel_tone},
        {"sim_gyro_tone", "gyro_tone", "gyroscope tone amplitude on sim_tone_axis, rad/s (0 = off)",
         &SimulatorOptions::gyro_tone},
        {"sim_tone_frequency", "tone_frequency", "the tones' frequency, Hz",
         &SimulatorOptions::tone_frequency},
        {"sim_tone_axis", "tone_axis", "the raw axes the tones are on: x, y, z or several (xz)",
         &SimulatorOptions::tone_axis},
        {"sim_accel_slow_line", "accel_slow_line",
         "accelerometer low-frequency line amplitude on every axis, m/s^2 (0 = off)",
         &SimulatorOptions::accel_slow_line},
        {"sim_gyro_slow_line", "gyro_slow_line",
         "gyroscope low-frequency line amplitude on every axis, rad/s (0 = off)",
         &SimulatorOptions::gyro_slow_line},
        {"sim_slow_line_period", "slow_line_period", "the low-frequency line's period, s",
         &SimulatorOptions::slow_line_period},
        {"sim_temperature_start", "temperature_start", "deg C",
         &SimulatorOptions::temperature_start},
        {"sim_temperature_end", "temperature_end", "deg C", &SimulatorOptions::temperature_end},
        {"sim_temperature_tau", "temperature_tau", "warm-up time constant, s",
         &SimulatorOptions::temperature_tau},
        {"sim_rotation_profile", "rotation_profile",
         "rotations between poses (smooth: fixed axis; hand: 1-4 s, irregular): " +
             AcceptedNames(RotationProfile()),
         &SimulatorOptions::rotation_profile},
        {"sim_hand_min_rotation", "hand_min_seconds", "hand profile: shortest rotation, s",
         &SimulatorOptions::hand_min_seconds},
        {"sim_hand_max_rotation", "hand_max_seconds", "hand profile: longest rotation, s",
         &SimulatorOptions::hand_max_seconds},
        {"sim_hand_wobble", "hand_wobble_deg",
         "hand profile: axis wobble, degrees (standard deviation)",
         &SimulatorOptions::hand_wobble_deg},
        {"sim_latitude", "latitude_deg",
         "the gyroscope senses Earth rate at this latitude, degrees (null = off)",
         &SimulatorOptions::latitude_deg},
        {"sim_attitude_noise", "fixture_attitude_noise_deg",
         "noise of the fixture attitudes simulate writes (attitudes.csv), degrees",
         &SimulatorOptions::fixture_attitude_noise_deg},
    };
    // The effects' spreads, from their definitions (core/effects/).
    for (const EffectInfo& info : EffectCatalogue()) {
      const EffectSimulation& sim = info.simulation;
      if (sim.key != nullptr) rows.push_back({sim.key, sim.name, sim.help, info.effect});
    }
    rows.push_back({"sim_effect_reference_temperature", "effect_reference_temperature",
                    "temperature at which the simulated temperature terms are zero, degC",
                    &SimulatorOptions::effect_reference_temperature});
    return rows;
  }());
  return fields;
}

}  // namespace internal
}  // namespace gravcal
