#include "gravcal/simulation/simulator.h"

#include <Eigen/LU>
#include <cmath>
#include <exception>
#include <limits>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "gravcal/core/gravity.h"

namespace gravcal {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Standard gravity: defines the nominal accelerometer scale of "counts per g".
constexpr double kStandardGravity = 9.80665;
// Corner frequency of the first-order low-pass that shapes hand tremor, Hz.
constexpr double kTremorCornerHz = 5.0;
// Limits that keep a typo from asking for gigabytes.
constexpr long kMaxRandomPoses = 100000;
constexpr double kMaxSamples = 1e8;
// Above these the random truth models can become singular.
constexpr double kMaxScaleStd = 0.25;
constexpr double kMaxMisalignmentStd = 0.25;

enum class SchemeKind { kSix, kTwelve, kTen, kRandom };

// Parses "six", "twelve", "ten" or "random:N".
bool ParseScheme(const std::string& scheme, SchemeKind* kind, long* count, std::string* error) {
  auto fail = [&](const std::string& what) {
    if (error) *error = what;
    return false;
  };
  if (scheme == "six") {
    *kind = SchemeKind::kSix;
    *count = 6;
    return true;
  }
  if (scheme == "twelve") {
    *kind = SchemeKind::kTwelve;
    *count = 12;
    return true;
  }
  if (scheme == "ten") {
    *kind = SchemeKind::kTen;
    *count = 10;
    return true;
  }
  const std::string prefix = "random:";
  if (scheme.compare(0, prefix.size(), prefix) == 0) {
    const std::string digits = scheme.substr(prefix.size());
    bool ok = !digits.empty() && digits.size() <= 9;
    for (char c : digits) ok = ok && c >= '0' && c <= '9';
    const long n = ok ? std::stol(digits) : 0;
    if (n < 1 || n > kMaxRandomPoses) {
      std::ostringstream msg;
      msg << "scheme '" << scheme << "': N in random:N must be an integer from 1 to "
          << kMaxRandomPoses;
      return fail(msg.str());
    }
    *kind = SchemeKind::kRandom;
    *count = n;
    return true;
  }
  return fail("unknown scheme '" + scheme + "' (expected six, twelve, ten or random:N)");
}

Eigen::Quaterniond AxisAngle(double angle, const Eigen::Vector3d& axis) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis));
}

// Rotation by the rotation vector v (axis * angle).
Eigen::Quaterniond FromRotationVector(const Eigen::Vector3d& v) {
  const double angle = v.norm();
  if (angle == 0.0) return Eigen::Quaterniond::Identity();
  return AxisAngle(angle, v / angle);
}

// Body-to-navigation attitude from roll (about x) then pitch (about y), zero
// heading: C_bn = R_y(pitch) R_x(roll), so gravity in the body frame reads
// g (-sin(pitch), sin(roll) cos(pitch), cos(roll) cos(pitch)).
Eigen::Quaterniond RollPitch(double roll_deg, double pitch_deg) {
  const double d = kPi / 180.0;
  return AxisAngle(pitch_deg * d, Eigen::Vector3d::UnitY()) *
         AxisAngle(roll_deg * d, Eigen::Vector3d::UnitX());
}

// The smallest rotation taking the body direction up to navigation z (half
// a turn about body x when up points straight down).
Eigen::Quaterniond UpToZenith(const Eigen::Vector3d& up) {
  const Eigen::Vector3d u = up.normalized();
  const Eigen::Vector3d axis = u.cross(Eigen::Vector3d::UnitZ());
  if (axis.norm() < 1e-12) {
    return u.z() > 0.0 ? Eigen::Quaterniond::Identity() : AxisAngle(kPi, Eigen::Vector3d::UnitX());
  }
  return AxisAngle(std::atan2(axis.norm(), u.z()), axis.normalized());
}

// The body axis 0..5 (+x, -x, +y, -y, +z, -z) that points up, or -1.
int UpAxis(const Eigen::Quaterniond& attitude) {
  const Eigen::Vector3d up = attitude.conjugate() * Eigen::Vector3d::UnitZ();
  for (int axis = 0; axis < 3; ++axis) {
    if (up(axis) > 1.0 - 1e-9) return 2 * axis;
    if (up(axis) < -1.0 + 1e-9) return 2 * axis + 1;
  }
  return -1;
}

// A uniformly distributed rotation (Shoemake's method).
Eigen::Quaterniond UniformRotation(std::mt19937_64* rng) {
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const double u1 = u01(*rng);
  const double u2 = u01(*rng);
  const double u3 = u01(*rng);
  const double a = std::sqrt(1.0 - u1);
  const double b = std::sqrt(u1);
  return Eigen::Quaterniond(b * std::cos(2.0 * kPi * u3), a * std::sin(2.0 * kPi * u2),
                            a * std::cos(2.0 * kPi * u2), b * std::sin(2.0 * kPi * u3))
      .normalized();
}

// Minimum-jerk profile s(x) = 10 x^3 - 15 x^4 + 6 x^5 on [0, 1] and its
// derivative ds/dx = 30 x^2 (1 - x)^2: rate and acceleration are zero at both
// ends.
double SmoothStep(double x) { return x * x * x * (10.0 + x * (-15.0 + 6.0 * x)); }
double SmoothStepRate(double x) { return 30.0 * x * x * (1.0 - x) * (1.0 - x); }

long SampleCount(double seconds, double rate) { return std::lround(seconds * rate); }

// A hand-like rotation: random duration, an irregular time warp
// tau(x) = x + sum_j c_j sin(2 pi j x) / (2 pi j) of the minimum-jerk
// profile (tau' = 1 + sum_j c_j cos(2 pi j x) > 0, so it never runs
// backwards), and a wobble beta(x) = 64 A x^3 (1 - x)^3 about a random axis,
// zero at both ends with zero rate and angular acceleration (a jump in the
// angular acceleration would cost any sampled integrator an O(h^2) error).
struct HandProfile {
  double seconds = 1.0;
  double c[3] = {0.0, 0.0, 0.0};
  double amplitude = 0.0;
  Eigen::Vector3d wobble_axis = Eigen::Vector3d::UnitX();

  static HandProfile Random(const SimulatorOptions& options, std::mt19937_64* rng) {
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    std::normal_distribution<double> n01(0.0, 1.0);
    HandProfile p;
    p.seconds = options.hand_min_seconds +
                (options.hand_max_seconds - options.hand_min_seconds) * u01(*rng);
    for (double& cj : p.c) cj = 0.5 * (u01(*rng) - 0.5);
    p.amplitude = options.hand_wobble_deg * kPi / 180.0 * n01(*rng);
    Eigen::Vector3d v(n01(*rng), n01(*rng), n01(*rng));
    if (v.norm() > 0.0) p.wobble_axis = v.normalized();
    return p;
  }
  double Warp(double x) const {
    double tau = x;
    for (int j = 1; j <= 3; ++j) tau += c[j - 1] * std::sin(2.0 * kPi * j * x) / (2.0 * kPi * j);
    return tau;
  }
  double WarpRate(double x) const {
    double rate = 1.0;
    for (int j = 1; j <= 3; ++j) rate += c[j - 1] * std::cos(2.0 * kPi * j * x);
    return rate;
  }
  double Wobble(double x) const { return amplitude * 64.0 * std::pow(x * (1.0 - x), 3); }
  double WobbleRate(double x) const {
    return amplitude * 192.0 * std::pow(x * (1.0 - x), 2) * (1.0 - 2.0 * x);
  }
};

// The effect truths, from a stream of their own (see SimulatorOptions).
void DrawEffects(const SimulatorOptions& o, uint64_t seed, SimulatedSession* s) {
  std::mt19937_64 rng(seed ^ 0x6a09e667f3bcc909ULL);
  std::normal_distribution<double> n01(0.0, 1.0);
  auto draw3 = [&](double std) -> Eigen::Vector3d {
    return Eigen::Vector3d(n01(rng), n01(rng), n01(rng)) * std;
  };
  EffectParameters& e = s->effects;
  e.reference_temperature = o.effect_reference_temperature;
  e.reference_time = 0.0;
  e.accel_quadratic = draw3(o.accel_quadratic_std);
  e.accel_temperature_bias = draw3(o.accel_temperature_bias_std);
  e.accel_temperature_scale = draw3(o.accel_temperature_scale_std);
  e.accel_bias_drift = draw3(o.accel_bias_drift_std);
  for (int r = 0; r < 3; ++r) e.gyro_g_sensitivity.row(r) = draw3(o.gyro_g_sensitivity_std);
  s->gyro_g_sensitivity = e.gyro_g_sensitivity;
  e.gyro_temperature_bias = draw3(o.gyro_temperature_bias_std);
  e.gyro_bias_drift = draw3(o.gyro_bias_drift_std);
}

bool SimulateImpl(const SimulatorOptions& options, uint64_t seed, SimulatedSession* session,
                  std::string* error) {
  auto fail = [&](const std::string& what) {
    if (error) *error = what;
    return false;
  };
  if (!options.IsValid(error)) return false;
  std::vector<Eigen::Quaterniond> nominal;
  std::vector<int> nominal_up;
  if (options.planned_poses.empty()) {
    if (!SchemeAttitudes(options.scheme, seed, &nominal, &nominal_up, error)) return false;
  }
  std::vector<double> hold_seconds(nominal.size(), options.hold_seconds);
  for (const PlannedHold& p : options.planned_poses) {
    nominal.push_back(UpToZenith(p.up));
    nominal_up.push_back(UpAxis(nominal.back()));
    hold_seconds.push_back(p.hold_seconds);
  }
  const size_t pose_count = nominal.size();

  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::uniform_real_distribution<double> u01(0.0, 1.0);

  // Truth sensors. AccelModel maps raw to SI, so its scale is SI per raw unit.
  const double accel_scale =
      options.raw_counts ? kStandardGravity / options.accel_counts_per_g : 1.0;
  const double gyro_scale = options.raw_counts ? (kPi / 180.0) / options.gyro_counts_per_dps : 1.0;
  SimulatedSession s;
  s.seed = seed;
  s.gravity = options.gravity;
  s.accel_units_per_si = 1.0 / accel_scale;
  s.gyro_units_per_si = 1.0 / gyro_scale;
  s.accel_truth = AccelModel::Random(AccelParameterization::kAffine, accel_scale,
                                     options.accel_scale_std, options.accel_misalignment_std,
                                     options.accel_bias_std / accel_scale, &rng);
  s.gyro_truth =
      GyroModel::Random(gyro_scale, options.gyro_scale_std, options.gyro_misalignment_std,
                        options.gyro_bias_std / gyro_scale, &rng);
  DrawEffects(options, seed, &s);
  const bool accel_effects =
      options.accel_quadratic_std > 0.0 || options.accel_temperature_bias_std > 0.0 ||
      options.accel_temperature_scale_std > 0.0 || options.accel_bias_drift_std > 0.0;
  const bool gyro_effects = options.gyro_g_sensitivity_std > 0.0 ||
                            options.gyro_temperature_bias_std > 0.0 ||
                            options.gyro_bias_drift_std > 0.0;
  const Eigen::Matrix3d upper_inverse = s.accel_truth.upper.inverse();
  const Eigen::Matrix3d accel_inverse = s.accel_truth.matrix().inverse();
  const Eigen::Matrix3d gyro_inverse = s.gyro_truth.matrix.inverse();
  if (s.accel_truth.upper.diagonal().minCoeff() <= 0.0 || !accel_inverse.allFinite() ||
      s.gyro_truth.matrix.determinant() <= 0.0 || !gyro_inverse.allFinite()) {
    return fail(
        "the random truth sensor is singular or reflected: reduce accel_scale_std, "
        "gyro_scale_std or the misalignment standard deviations");
  }

  // Placed attitudes: an arbitrary heading (about navigation z) times the
  // nominal pose times a small placement error (about body axes).
  const double placement_rad = options.placement_error_deg * kPi / 180.0;
  std::vector<Eigen::Quaterniond> attitudes(pose_count);
  for (size_t k = 0; k < pose_count; ++k) {
    const double heading = 2.0 * kPi * u01(rng);
    const Eigen::Vector3d tilt(n01(rng), n01(rng), n01(rng));
    attitudes[k] = (AxisAngle(heading, Eigen::Vector3d::UnitZ()) * nominal[k] *
                    FromRotationVector(placement_rad * tilt))
                       .normalized();
  }

  const double rate = options.sample_rate;
  const double dt = 1.0 / rate;
  std::vector<long> hold(pose_count);
  for (size_t k = 0; k < pose_count; ++k) hold[k] = SampleCount(hold_seconds[k], rate);
  const long first_still = SampleCount(options.initial_still_seconds + hold_seconds[0], rate);
  const bool hand = options.rotation_profile == "hand";
  // The hand profiles draw from a stream of their own (G with the other
  // effects in DrawEffects), so switching them on leaves every other number
  // of a seed unchanged.
  std::mt19937_64 extra_rng(seed ^ 0xc2b2ae3d27d4eb4fULL);
  std::vector<HandProfile> profiles(pose_count > 0 ? pose_count - 1 : 0);
  std::vector<long> rotation(profiles.size(), SampleCount(options.rotation_seconds, rate));
  for (size_t k = 0; k < profiles.size() && hand; ++k) {
    profiles[k] = HandProfile::Random(options, &extra_rng);
    rotation[k] = std::max(1L, SampleCount(profiles[k].seconds, rate));
  }
  size_t total = static_cast<size_t>(first_still);
  for (size_t k = 1; k < pose_count; ++k) total += static_cast<size_t>(hold[k]);
  for (long r : rotation) total += static_cast<size_t>(r);
  if (static_cast<double>(total) > kMaxSamples) {
    return fail("the session is too long (" + std::to_string(total) + " samples)");
  }

  ImuLog& log = s.log;
  log.source = "simulated " + (options.planned_poses.empty() ? options.scheme : "plan") + " seed " +
               std::to_string(seed);
  log.t.resize(total);
  log.accel.resize(total);
  log.gyro.resize(total);
  log.temperature.resize(total);

  const Eigen::Vector3d gravity_nav(0.0, 0.0, options.gravity);
  // Earth rotation in the navigation frame (East-North-Up), when on.
  Eigen::Vector3d earth_rate_nav = Eigen::Vector3d::Zero();
  if (std::isfinite(options.latitude_deg)) {
    const double lat = options.latitude_deg * kPi / 180.0;
    earth_rate_nav = kEarthRate * Eigen::Vector3d(0.0, std::cos(lat), std::sin(lat));
  }
  const double accel_noise = options.accel_noise * s.accel_units_per_si;
  const double gyro_noise = options.gyro_noise * s.gyro_units_per_si;
  const double accel_walk = options.accel_bias_random_walk * std::sqrt(dt) * s.accel_units_per_si;
  const double gyro_walk = options.gyro_bias_random_walk * std::sqrt(dt) * s.gyro_units_per_si;
  // Tremor: first-order low-pass of white noise, stationary rms options.tremor
  // per axis, started in its stationary distribution at each still period.
  const double tremor_pole = std::exp(-2.0 * kPi * kTremorCornerHz * dt);
  const double tremor_drive = options.tremor * std::sqrt(1.0 - tremor_pole * tremor_pole);
  Eigen::Vector3d accel_bias_drift = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_bias_drift = Eigen::Vector3d::Zero();
  Eigen::Vector3d tremor = Eigen::Vector3d::Zero();
  auto normal3 = [&]() { return Eigen::Vector3d(n01(rng), n01(rng), n01(rng)); };

  // Writes sample i from the true specific force and body rate.
  auto emit = [&](size_t i, const Eigen::Vector3d& force, const Eigen::Vector3d& body_rate) {
    const double t = static_cast<double>(i) * dt;
    const double temperature =
        options.temperature_end + (options.temperature_start - options.temperature_end) *
                                      std::exp(-t / options.temperature_tau);
    // The effect terms only when switched on, so that sessions without them
    // stay bit-identical.
    Eigen::Vector3d v;
    if (accel_effects) {
      const Eigen::Vector3d sensed =
          ApplyAccelEffects(s.effects, s.accel_truth.rotation.transpose() * force, temperature, t);
      v = upper_inverse * sensed + s.accel_truth.bias;
    } else {
      v = accel_inverse * force + s.accel_truth.bias;
    }
    Eigen::Vector3d u;
    if (gyro_effects) {
      const double dT = temperature - s.effects.reference_temperature;
      u = gyro_inverse * (body_rate + s.gyro_g_sensitivity * force +
                          s.effects.gyro_temperature_bias * dT + s.effects.gyro_bias_drift * t) +
          s.gyro_truth.bias;
    } else {
      u = gyro_inverse * body_rate + s.gyro_truth.bias;
    }
    if (accel_noise > 0.0) v += accel_noise * normal3();
    if (gyro_noise > 0.0) u += gyro_noise * normal3();
    if (accel_walk > 0.0) {
      v += accel_bias_drift;
      accel_bias_drift += accel_walk * normal3();
    }
    if (gyro_walk > 0.0) {
      u += gyro_bias_drift;
      gyro_bias_drift += gyro_walk * normal3();
    }
    if (options.raw_counts) {
      v = v.array().round();
      u = u.array().round();
    }
    log.t[i] = t;
    log.accel[i] = v;
    log.gyro[i] = u;
    log.temperature[i] = temperature;
  };

  s.poses.resize(pose_count);
  size_t i = 0;
  for (size_t k = 0; k < pose_count; ++k) {
    // Still period.
    const size_t still = static_cast<size_t>(k == 0 ? first_still : hold[k]);
    SimulatedPose& pose = s.poses[k];
    pose.begin = i;
    pose.end = i + still;
    pose.attitude = attitudes[k];
    pose.nominal_up = nominal_up[k];
    const Eigen::Vector3d force = attitudes[k].conjugate() * gravity_nav;
    const Eigen::Vector3d still_rate = attitudes[k].conjugate() * earth_rate_nav;
    if (options.tremor > 0.0) tremor = options.tremor * normal3();
    for (; i < pose.end; ++i) {
      if (options.tremor > 0.0) {
        emit(i, force + tremor, still_rate);
        tremor = tremor_pole * tremor + tremor_drive * normal3();
      } else {
        emit(i, force, still_rate);
      }
    }
    if (k + 1 == pose_count) break;

    // Rotation to the next pose along the shortest great circle:
    // q(t) = q0 exp(s(x) log(q0^-1 q1)), x = (t - t0) / T, whose body rate is
    // w_b = axis * angle * s'(x) / T.
    Eigen::Quaterniond delta = attitudes[k].conjugate() * attitudes[k + 1];
    if (delta.w() < 0.0) delta.coeffs() *= -1.0;
    const Eigen::AngleAxisd step(delta);
    const double duration = static_cast<double>(rotation[k]) * dt;
    for (long j = 0; j < rotation[k]; ++j, ++i) {
      const double x = static_cast<double>(j) / static_cast<double>(rotation[k]);
      if (!hand) {
        const Eigen::Quaterniond q =
            attitudes[k] * AxisAngle(SmoothStep(x) * step.angle(), step.axis());
        emit(i, q.conjugate() * gravity_nav,
             step.axis() * (step.angle() * SmoothStepRate(x) / duration) +
                 q.conjugate() * earth_rate_nav);
        continue;
      }
      // Hand: q(x) = q0 exp(s(tau(x)) angle axis) exp(beta(x) v), whose
      // body rate is R(exp(beta v))^T axis angle s'(tau) tau'(x) / T +
      // v beta'(x) / T.
      const HandProfile& p = profiles[k];
      const double tau = p.Warp(x);
      const Eigen::Quaterniond wobble = AxisAngle(p.Wobble(x), p.wobble_axis);
      const Eigen::Quaterniond q =
          attitudes[k] * AxisAngle(SmoothStep(tau) * step.angle(), step.axis()) * wobble;
      const Eigen::Vector3d main_rate =
          step.axis() * (step.angle() * SmoothStepRate(tau) * p.WarpRate(x) / duration);
      emit(i, q.conjugate() * gravity_nav,
           wobble.conjugate() * main_rate + p.wobble_axis * (p.WobbleRate(x) / duration) +
               q.conjugate() * earth_rate_nav);
    }
  }

  *session = std::move(s);
  return true;
}

nlohmann::json ToJson(const Eigen::Vector3d& v) { return {v(0), v(1), v(2)}; }

nlohmann::json ToJson(const Eigen::Matrix3d& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2)});
  return rows;
}

}  // namespace

bool SimulatorOptions::IsValid(std::string* error) const {
  auto fail = [&](const char* field, double value, const std::string& requirement) {
    if (error) {
      std::ostringstream msg;
      msg << "SimulatorOptions." << field << " = " << value << ": " << requirement;
      *error = msg.str();
    }
    return false;
  };
  auto positive = [&](const char* field, double value) {
    return std::isfinite(value) && value > 0.0 ? true : fail(field, value, "must be positive");
  };
  auto non_negative = [&](const char* field, double value) {
    return std::isfinite(value) && value >= 0.0 ? true
                                                : fail(field, value, "must be zero or positive");
  };
  auto at_most = [&](const char* field, double value, double limit) {
    if (!non_negative(field, value)) return false;
    std::ostringstream requirement;
    requirement << "must be at most " << limit;
    return value <= limit ? true : fail(field, value, requirement.str());
  };
  auto finite = [&](const char* field, double value) {
    return std::isfinite(value) ? true : fail(field, value, "must be finite");
  };
  // One sample period, with slack for decimal durations such as 0.01 s.
  auto one_sample = [&](const char* field, double value) {
    if (!std::isfinite(value) || value * sample_rate < 1.0 - 1e-9) {
      return fail(field, value, "must be at least one sample period (1 / sample_rate)");
    }
    return true;
  };

  SchemeKind kind;
  long pose_count = 0;
  std::string scheme_error;
  if (!ParseScheme(scheme, &kind, &pose_count, &scheme_error)) {
    if (error) *error = "SimulatorOptions.scheme: " + scheme_error;
    return false;
  }
  if (!positive("sample_rate", sample_rate)) return false;
  if (!one_sample("hold_seconds", hold_seconds)) return false;
  double planned_seconds = 0.0;
  for (const PlannedHold& p : planned_poses) {
    if (!one_sample("planned_poses.hold_seconds", p.hold_seconds)) return false;
    if (!(p.up.allFinite() && p.up.norm() > 0.5)) {
      if (error) *error = "SimulatorOptions.planned_poses: every up must be a unit vector";
      return false;
    }
    planned_seconds += p.hold_seconds;
  }
  if (!planned_poses.empty()) pose_count = static_cast<long>(planned_poses.size());
  if (!non_negative("initial_still_seconds", initial_still_seconds)) return false;
  if (!one_sample("rotation_seconds", rotation_seconds)) return false;
  if (!positive("gravity", gravity)) return false;
  if (!positive("accel_counts_per_g", accel_counts_per_g)) return false;
  if (!positive("gyro_counts_per_dps", gyro_counts_per_dps)) return false;
  if (!non_negative("accel_noise", accel_noise)) return false;
  if (!non_negative("accel_bias_random_walk", accel_bias_random_walk)) return false;
  if (!non_negative("gyro_noise", gyro_noise)) return false;
  if (!non_negative("gyro_bias_random_walk", gyro_bias_random_walk)) return false;
  if (!non_negative("accel_bias_std", accel_bias_std)) return false;
  if (!at_most("accel_scale_std", accel_scale_std, kMaxScaleStd)) return false;
  if (!at_most("accel_misalignment_std", accel_misalignment_std, kMaxMisalignmentStd)) {
    return false;
  }
  if (!non_negative("gyro_bias_std", gyro_bias_std)) return false;
  if (!at_most("gyro_scale_std", gyro_scale_std, kMaxScaleStd)) return false;
  if (!at_most("gyro_misalignment_std", gyro_misalignment_std, kMaxMisalignmentStd)) return false;
  if (!non_negative("placement_error_deg", placement_error_deg)) return false;
  if (rotation_profile != "smooth" && rotation_profile != "hand") {
    if (error) {
      *error = "SimulatorOptions.rotation_profile: '" + rotation_profile +
               "' is not one of smooth, hand";
    }
    return false;
  }
  if (!one_sample("hand_min_seconds", hand_min_seconds)) return false;
  if (!(hand_max_seconds >= hand_min_seconds) || !std::isfinite(hand_max_seconds)) {
    return fail("hand_max_seconds", hand_max_seconds, "must be at least hand_min_seconds");
  }
  if (!non_negative("hand_wobble_deg", hand_wobble_deg)) return false;
  if (!non_negative("gyro_g_sensitivity_std", gyro_g_sensitivity_std)) return false;
  if (!non_negative("tremor", tremor)) return false;
  if (!finite("temperature_start", temperature_start)) return false;
  if (!finite("temperature_end", temperature_end)) return false;
  if (!positive("temperature_tau", temperature_tau)) return false;
  if (!std::isnan(latitude_deg) && !(std::fabs(latitude_deg) <= 90.0)) {
    return fail("latitude_deg", latitude_deg, "must be NaN (off) or within -90..90");
  }
  if (!non_negative("fixture_attitude_noise_deg", fixture_attitude_noise_deg)) return false;
  if (!non_negative("accel_quadratic_std", accel_quadratic_std)) return false;
  if (!non_negative("accel_temperature_bias_std", accel_temperature_bias_std)) return false;
  if (!at_most("accel_temperature_scale_std", accel_temperature_scale_std, 0.01)) return false;
  if (!non_negative("accel_bias_drift_std", accel_bias_drift_std)) return false;
  if (!non_negative("gyro_temperature_bias_std", gyro_temperature_bias_std)) return false;
  if (!non_negative("gyro_bias_drift_std", gyro_bias_drift_std)) return false;
  if (!finite("effect_reference_temperature", effect_reference_temperature)) return false;

  const double samples =
      (initial_still_seconds +
       (planned_poses.empty() ? hold_seconds * static_cast<double>(pose_count) : planned_seconds) +
       static_cast<double>(pose_count - 1) *
           (rotation_profile == "hand" ? hand_max_seconds : rotation_seconds)) *
      sample_rate;
  if (!(samples <= kMaxSamples)) {
    std::ostringstream msg;
    msg << "SimulatorOptions: the session would have " << samples << " samples (limit "
        << kMaxSamples << "); shorten hold_seconds, rotation_seconds or sample_rate";
    if (error) *error = msg.str();
    return false;
  }
  return true;
}

bool SchemeAttitudes(const std::string& scheme, uint64_t seed,
                     std::vector<Eigen::Quaterniond>* attitudes, std::vector<int>* nominal_up,
                     std::string* error) {
  if (attitudes == nullptr || nominal_up == nullptr) {
    if (error) *error = "SchemeAttitudes: null output";
    return false;
  }
  SchemeKind kind;
  long count = 0;
  if (!ParseScheme(scheme, &kind, &count, error)) return false;
  attitudes->clear();
  nominal_up->clear();
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX();
  const Eigen::Vector3d y = Eigen::Vector3d::UnitY();
  const double h = kPi / 2.0;
  switch (kind) {
    case SchemeKind::kTwelve:
    case SchemeKind::kSix:
      // +x, -x, +y, -y, +z, -z up (the body axis that points up).
      attitudes->push_back(AxisAngle(-h, y));
      attitudes->push_back(AxisAngle(h, y));
      attitudes->push_back(AxisAngle(h, x));
      attitudes->push_back(AxisAngle(-h, x));
      attitudes->push_back(Eigen::Quaterniond::Identity());
      attitudes->push_back(AxisAngle(kPi, x));
      if (kind == SchemeKind::kTwelve) {
        // Chen 2012: the YZ, XZ and XY planes tilted to about 45 and 135
        // degrees. Up directions (body frame) are six of the twelve cube edge
        // midpoints, one from each opposite pair.
        const Eigen::Vector3d ups[6] = {{0, 1, 1},   {0, 1, -1}, {-1, 0, 1},
                                        {-1, 0, -1}, {1, 1, 0},  {1, -1, 0}};
        for (const Eigen::Vector3d& up : ups) {
          attitudes->push_back(UpToZenith(up));
        }
      }
      break;
    case SchemeKind::kTen: {
      // CN101907638B: ten poses of differing roll and pitch (degrees).
      const double roll_pitch[10][2] = {{0, 0},   {180, 0}, {90, 0},   {-90, 0},  {0, 90},
                                        {0, -90}, {45, 45}, {-45, 45}, {45, -45}, {135, -45}};
      for (const auto& rp : roll_pitch) attitudes->push_back(RollPitch(rp[0], rp[1]));
      break;
    }
    case SchemeKind::kRandom: {
      // A stream of its own, so the poses do not share numbers with the
      // simulator's other draws from the same seed.
      std::mt19937_64 rng(seed ^ 0x9e3779b97f4a7c15ULL);
      for (long k = 0; k < count; ++k) attitudes->push_back(UniformRotation(&rng));
      break;
    }
  }
  for (const Eigen::Quaterniond& q : *attitudes) nominal_up->push_back(UpAxis(q));
  return true;
}

bool Simulate(const SimulatorOptions& options, uint64_t seed, SimulatedSession* session,
              std::string* error) {
  if (session == nullptr) {
    if (error) *error = "Simulate: null session";
    return false;
  }
  try {
    return SimulateImpl(options, seed, session, error);
  } catch (const std::exception& e) {
    if (error) *error = std::string("simulation failed: ") + e.what();
    return false;
  }
}

std::string TruthToJson(const SimulatedSession& session, const SimulatorOptions& options) {
  try {
    nlohmann::json j;
    j["seed"] = session.seed;
    j["gravity"] = session.gravity;
    const AccelModel& a = session.accel_truth;
    j["accel"] = {{"model", ToString(a.parameterization)},
                  {"bias", ToJson(a.bias)},
                  {"matrix", ToJson(a.matrix())},
                  {"upper", ToJson(a.upper)},
                  {"rotation", ToJson(a.rotation)}};
    j["gyro"] = {{"bias", ToJson(session.gyro_truth.bias)},
                 {"matrix", ToJson(session.gyro_truth.matrix)},
                 {"g_sensitivity", ToJson(session.gyro_g_sensitivity)}};
    j["accel_units_per_si"] = session.accel_units_per_si;
    j["gyro_units_per_si"] = session.gyro_units_per_si;
    nlohmann::json poses = nlohmann::json::array();
    const std::vector<double>& t = session.log.t;
    for (const SimulatedPose& p : session.poses) {
      const Eigen::Quaterniond& q = p.attitude;
      const bool inside = p.begin < p.end && p.end <= t.size();
      poses.push_back({{"begin", p.begin},
                       {"end", p.end},
                       {"t_begin", inside ? t[p.begin] : 0.0},
                       {"t_end", inside ? t[p.end - 1] : 0.0},
                       {"nominal_up", p.nominal_up},
                       {"quaternion", {q.w(), q.x(), q.y(), q.z()}}});
    }
    j["poses"] = poses;
    const SimulatorOptions& o = options;
    j["options"] = {{"scheme", o.scheme},
                    {"hold_seconds", o.hold_seconds},
                    {"initial_still_seconds", o.initial_still_seconds},
                    {"rotation_seconds", o.rotation_seconds},
                    {"sample_rate", o.sample_rate},
                    {"gravity", o.gravity},
                    {"raw_counts", o.raw_counts},
                    {"accel_counts_per_g", o.accel_counts_per_g},
                    {"gyro_counts_per_dps", o.gyro_counts_per_dps},
                    {"accel_noise", o.accel_noise},
                    {"accel_bias_random_walk", o.accel_bias_random_walk},
                    {"gyro_noise", o.gyro_noise},
                    {"gyro_bias_random_walk", o.gyro_bias_random_walk},
                    {"accel_bias_std", o.accel_bias_std},
                    {"accel_scale_std", o.accel_scale_std},
                    {"accel_misalignment_std", o.accel_misalignment_std},
                    {"gyro_bias_std", o.gyro_bias_std},
                    {"gyro_scale_std", o.gyro_scale_std},
                    {"gyro_misalignment_std", o.gyro_misalignment_std},
                    {"placement_error_deg", o.placement_error_deg},
                    {"tremor", o.tremor},
                    {"rotation_profile", o.rotation_profile},
                    {"hand_min_seconds", o.hand_min_seconds},
                    {"hand_max_seconds", o.hand_max_seconds},
                    {"hand_wobble_deg", o.hand_wobble_deg},
                    {"gyro_g_sensitivity_std", o.gyro_g_sensitivity_std},
                    {"temperature_start", o.temperature_start},
                    {"temperature_end", o.temperature_end},
                    {"temperature_tau", o.temperature_tau},
                    {"latitude_deg", std::isfinite(o.latitude_deg) ? nlohmann::json(o.latitude_deg)
                                                                   : nlohmann::json(nullptr)},
                    {"fixture_attitude_noise_deg", o.fixture_attitude_noise_deg},
                    {"accel_quadratic_std", o.accel_quadratic_std},
                    {"accel_temperature_bias_std", o.accel_temperature_bias_std},
                    {"accel_temperature_scale_std", o.accel_temperature_scale_std},
                    {"accel_bias_drift_std", o.accel_bias_drift_std},
                    {"gyro_temperature_bias_std", o.gyro_temperature_bias_std},
                    {"gyro_bias_drift_std", o.gyro_bias_drift_std},
                    {"effect_reference_temperature", o.effect_reference_temperature}};
    const EffectParameters& e = session.effects;
    j["effects"] = {{"reference_temperature", e.reference_temperature},
                    {"accel_quadratic_nonlinearity", ToJson(e.accel_quadratic)},
                    {"accel_temperature_bias", ToJson(e.accel_temperature_bias)},
                    {"accel_temperature_scale", ToJson(e.accel_temperature_scale)},
                    {"accel_bias_drift", ToJson(e.accel_bias_drift)},
                    {"gyro_g_sensitivity", ToJson(session.gyro_g_sensitivity)},
                    {"gyro_temperature_bias", ToJson(e.gyro_temperature_bias)},
                    {"gyro_bias_drift", ToJson(e.gyro_bias_drift)}};
    return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
  } catch (const std::exception&) {
    return "{}";
  }
}

}  // namespace gravcal
