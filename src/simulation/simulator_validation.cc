// SimulatorOptions::IsValid: the checks of every field of the simulator's
// options, each error naming the field, its value and what it must be.
#include <cmath>
#include <sstream>
#include <string>

#include "gravcal/simulation/simulator.h"
#include "simulation/sensor_noise.h"
#include "simulation/simulator_schemes.h"
#include "util/units.h"

namespace gravcal {
namespace {

// Above these the random truth models can become singular.
constexpr double kMaxScaleStd = 0.25;
constexpr double kMaxMisalignmentStd = 0.25;

// The field checks of SimulatorOptions::IsValid: each returns true when the
// field is fine, else sets the error ("SimulatorOptions.<field> = <value>:
// <requirement>") and returns false.
class FieldCheck {
 public:
  FieldCheck(double sample_rate, std::string* error) : sample_rate_(sample_rate), error_(error) {}

  bool Fail(const char* field, double value, const std::string& requirement) const {
    if (error_) {
      std::ostringstream msg;
      msg << "SimulatorOptions." << field << " = " << value << ": " << requirement;
      *error_ = msg.str();
    }
    return false;
  }
  bool Positive(const char* field, double value) const {
    return std::isfinite(value) && value > 0.0 ? true : Fail(field, value, "must be positive");
  }
  bool NonNegative(const char* field, double value) const {
    return std::isfinite(value) && value >= 0.0 ? true
                                                : Fail(field, value, "must be zero or positive");
  }
  bool AtMost(const char* field, double value, double limit) const {
    if (!NonNegative(field, value)) return false;
    std::ostringstream requirement;
    requirement << "must be at most " << limit;
    return value <= limit ? true : Fail(field, value, requirement.str());
  }
  bool Finite(const char* field, double value) const {
    return std::isfinite(value) ? true : Fail(field, value, "must be finite");
  }
  // One sample period, with slack for decimal durations such as 0.01 s.
  bool OneSample(const char* field, double value) const {
    if (!std::isfinite(value) || value * sample_rate_ < 1.0 - 1e-9) {
      return Fail(field, value, "must be at least one sample period (1 / sample_rate)");
    }
    return true;
  }
  void Say(const std::string& text) const {
    if (error_) *error_ = text;
  }

 private:
  double sample_rate_;
  std::string* error_;
};

// Scheme, rates, durations and units.
bool CheckTiming(const SimulatorOptions& o, const FieldCheck& c, long* pose_count) {
  std::string scheme_error;
  if (!o.scheme.PoseCount(pose_count, &scheme_error)) {
    c.Say("SimulatorOptions.scheme: " + scheme_error);
    return false;
  }
  if (!c.Positive("sample_rate", o.sample_rate) || !c.OneSample("hold_seconds", o.hold_seconds)) {
    return false;
  }
  Eigen::Vector3d previous_up = Eigen::Vector3d::Zero();
  for (const PlannedHold& p : o.planned_poses) {
    if (!c.OneSample("planned_poses.hold_seconds", p.hold_seconds)) return false;
    if (!(p.up.allFinite() && p.up.norm() > 0.5)) {
      c.Say("SimulatorOptions.planned_poses: every up must be a unit vector");
      return false;
    }
    if (!p.turn_axis.allFinite() || !(p.turn_angle_deg >= 0.0 && p.turn_angle_deg <= 180.0) ||
        !(p.turn_seconds >= 0.0 && std::isfinite(p.turn_seconds))) {
      c.Say(
          "SimulatorOptions.planned_poses: a turn has a finite axis, an angle in [0, 180] "
          "degrees and a duration >= 0");
      return false;
    }
    if (internal::PlannedTurns(o) && previous_up.norm() > 0.5) {
      const Eigen::Vector3d moved =
          Eigen::AngleAxisd(-p.turn_angle_deg * M_PI / 180.0, p.turn_axis.normalized()) *
          previous_up;
      if (moved.dot(p.up.normalized()) < std::cos(internal::kDegToRad)) {
        c.Say(
            "SimulatorOptions.planned_poses: a turn does not take the previous pose's up "
            "direction to the next one's");
        return false;
      }
    }
    previous_up = p.up.normalized();
  }
  if (!o.planned_poses.empty()) *pose_count = static_cast<long>(o.planned_poses.size());
  return c.NonNegative("initial_still_seconds", o.initial_still_seconds) &&
         c.OneSample("rotation_seconds", o.rotation_seconds) && c.Positive("gravity", o.gravity) &&
         c.Positive("accel_counts_per_g", o.accel_counts_per_g) &&
         c.Positive("gyro_counts_per_dps", o.gyro_counts_per_dps);
}

// Noise: white, random walks, bias instability.
bool CheckNoise(const SimulatorOptions& o, const FieldCheck& c) {
  if (!c.NonNegative("accel_noise", o.accel_noise) ||
      !c.NonNegative("accel_bias_random_walk", o.accel_bias_random_walk) ||
      !c.NonNegative("gyro_noise", o.gyro_noise) ||
      !c.NonNegative("gyro_bias_random_walk", o.gyro_bias_random_walk) ||
      !c.NonNegative("accel_bias_instability", o.accel_bias_instability) ||
      !c.NonNegative("gyro_bias_instability", o.gyro_bias_instability)) {
    return false;
  }
  if ((o.accel_bias_instability > 0.0 || o.gyro_bias_instability > 0.0) &&
      !(o.bias_instability_tau_low >= 10.0 / o.sample_rate)) {
    return c.Fail("bias_instability_tau_low", o.bias_instability_tau_low,
                  "must be at least 10 sample periods");
  }
  if (!(o.bias_instability_tau_high > o.bias_instability_tau_low) ||
      !std::isfinite(o.bias_instability_tau_high)) {
    return c.Fail("bias_instability_tau_high", o.bias_instability_tau_high,
                  "must be finite and above bias_instability_tau_low");
  }
  if (!c.NonNegative("accel_tone", o.accel_tone) || !c.NonNegative("gyro_tone", o.gyro_tone)) {
    return false;
  }
  if ((o.accel_tone > 0.0 || o.gyro_tone > 0.0) &&
      !(o.tone_frequency > 0.0 && o.tone_frequency < 0.5 * o.sample_rate)) {
    return c.Fail("tone_frequency", o.tone_frequency,
                  "must be positive and below half the sample rate");
  }
  if (o.tone_axis.empty() || o.tone_axis.size() > 3 ||
      o.tone_axis.find_first_not_of("xyz") != std::string::npos) {
    return c.Fail("tone_axis", NAN,
                  "must be x, y, z or several of them (not '" + o.tone_axis + "')");
  }
  if (!c.NonNegative("accel_slow_line", o.accel_slow_line) ||
      !c.NonNegative("gyro_slow_line", o.gyro_slow_line)) {
    return false;
  }
  if ((o.accel_slow_line > 0.0 || o.gyro_slow_line > 0.0) &&
      !(o.slow_line_period > 2.0 / o.sample_rate && std::isfinite(o.slow_line_period))) {
    return c.Fail("slow_line_period", o.slow_line_period,
                  "must be finite and longer than two sample periods");
  }
  return true;
}

// The spreads of the random truth sensor.
bool CheckTruthSpreads(const SimulatorOptions& o, const FieldCheck& c) {
  return c.NonNegative("accel_bias_std", o.accel_bias_std) &&
         c.AtMost("accel_scale_std", o.accel_scale_std, kMaxScaleStd) &&
         c.AtMost("accel_misalignment_std", o.accel_misalignment_std, kMaxMisalignmentStd) &&
         c.NonNegative("gyro_bias_std", o.gyro_bias_std) &&
         c.AtMost("gyro_scale_std", o.gyro_scale_std, kMaxScaleStd) &&
         c.AtMost("gyro_misalignment_std", o.gyro_misalignment_std, kMaxMisalignmentStd);
}

// Placement, rotations between poses, tremor and per-pose disturbances.
bool CheckPlacement(const SimulatorOptions& o, const FieldCheck& c) {
  if (!c.NonNegative("placement_error_deg", o.placement_error_deg)) return false;
  if (!c.OneSample("hand_min_seconds", o.hand_min_seconds)) return false;
  if (!(o.hand_max_seconds >= o.hand_min_seconds) || !std::isfinite(o.hand_max_seconds)) {
    return c.Fail("hand_max_seconds", o.hand_max_seconds, "must be at least hand_min_seconds");
  }
  return c.NonNegative("hand_wobble_deg", o.hand_wobble_deg) && c.NonNegative("tremor", o.tremor) &&
         c.NonNegative("pose_disturbance", o.pose_disturbance);
}

// Temperature, Earth rate, fixture attitudes and the effect terms.
bool CheckEnvironmentAndEffects(const SimulatorOptions& o, const FieldCheck& c) {
  if (!c.Finite("temperature_start", o.temperature_start) ||
      !c.Finite("temperature_end", o.temperature_end) ||
      !c.Positive("temperature_tau", o.temperature_tau)) {
    return false;
  }
  if (!std::isnan(o.latitude_deg) && !(std::fabs(o.latitude_deg) <= 90.0)) {
    return c.Fail("latitude_deg", o.latitude_deg, "must be NaN (off) or within -90..90");
  }
  if (!c.NonNegative("fixture_attitude_noise_deg", o.fixture_attitude_noise_deg)) return false;
  for (const EffectInfo& info : EffectCatalogue()) {
    const EffectSimulation& sim = info.simulation;
    if (sim.key == nullptr) continue;
    const double v = o.effect_std[info.effect];
    if (!(sim.max > 0.0 ? c.AtMost(sim.name, v, sim.max) : c.NonNegative(sim.name, v))) {
      return false;
    }
  }
  return c.Finite("effect_reference_temperature", o.effect_reference_temperature);
}

// The session's length against internal::kMaxSimulatedSamples.
bool CheckLength(const SimulatorOptions& o, long pose_count, const FieldCheck& c) {
  double hold_total = o.hold_seconds * static_cast<double>(pose_count);
  if (!o.planned_poses.empty()) {
    hold_total = 0.0;
    for (const PlannedHold& p : o.planned_poses) hold_total += p.hold_seconds;
  }
  const double samples = (o.initial_still_seconds + hold_total +
                          static_cast<double>(pose_count - 1) *
                              (o.rotation_profile == RotationProfile::kHand ? o.hand_max_seconds
                                                                            : o.rotation_seconds)) *
                         o.sample_rate;
  if (samples <= internal::kMaxSimulatedSamples) return true;
  std::ostringstream msg;
  msg << "SimulatorOptions: the session would have " << samples << " samples (limit "
      << internal::kMaxSimulatedSamples
      << "); shorten hold_seconds, rotation_seconds or sample_rate";
  c.Say(msg.str());
  return false;
}

}  // namespace

bool SimulatorOptions::IsValid(std::string* error) const {
  const FieldCheck check(sample_rate, error);
  long pose_count = 0;
  return CheckTiming(*this, check, &pose_count) && CheckNoise(*this, check) &&
         CheckTruthSpreads(*this, check) && CheckPlacement(*this, check) &&
         CheckEnvironmentAndEffects(*this, check) && CheckLength(*this, pose_count, check);
}

}  // namespace gravcal
