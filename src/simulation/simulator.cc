#include "gravcal/simulation/simulator.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "gravcal/core/gravity.h"
#include "simulation/sensor_noise.h"
#include "util/random_vector.h"

namespace gravcal {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Corner frequency of the first-order low-pass that shapes hand tremor, Hz.
constexpr double kTremorCornerHz = 5.0;
// Limit that keeps a typo from asking for gigabytes of poses.
constexpr long kMaxRandomPoses = 100000;
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
    const Eigen::Vector3d v = internal::DrawVector3([&] { return n01(*rng); });
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
    return internal::DrawVector3([&] { return n01(rng); }) * std;
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

// The session's main random stream. One normal distribution serves every
// draw from it: the distribution caches every other value, so sharing it is
// part of what makes a seed's session what it is.
struct MainStream {
  explicit MainStream(uint64_t seed) : rng(seed) {}
  std::mt19937_64 rng;
  std::normal_distribution<double> n01{0.0, 1.0};
  Eigen::Vector3d Normal3() {
    return internal::DrawVector3([this] { return n01(rng); });
  }
};

// The truth sensors, from the session's main stream `rng`, and the effect
// truths from a stream of their own. False when the random truth is singular.
bool DrawTruth(const SimulatorOptions& options, uint64_t seed, std::mt19937_64* rng,
               SimulatedSession* s, std::string* error) {
  // AccelModel maps raw to SI, so its scale is SI per raw unit.
  const double accel_scale =
      options.raw_counts ? kStandardGravity / options.accel_counts_per_g : 1.0;
  const double gyro_scale = options.raw_counts ? (kPi / 180.0) / options.gyro_counts_per_dps : 1.0;
  s->seed = seed;
  s->gravity = options.gravity;
  s->accel_units_per_si = 1.0 / accel_scale;
  s->gyro_units_per_si = 1.0 / gyro_scale;
  s->accel_truth =
      AccelModel::Random(AccelParameterization::kAffine, accel_scale, options.accel_scale_std,
                         options.accel_misalignment_std, options.accel_bias_std / accel_scale, rng);
  s->gyro_truth =
      GyroModel::Random(gyro_scale, options.gyro_scale_std, options.gyro_misalignment_std,
                        options.gyro_bias_std / gyro_scale, rng);
  DrawEffects(options, seed, s);
  if (s->accel_truth.upper.diagonal().minCoeff() <= 0.0 ||
      !s->accel_truth.matrix().inverse().allFinite() || s->gyro_truth.matrix.determinant() <= 0.0 ||
      !s->gyro_truth.matrix.inverse().allFinite()) {
    if (error) {
      *error =
          "the random truth sensor is singular or reflected: reduce accel_scale_std, "
          "gyro_scale_std or the misalignment standard deviations";
    }
    return false;
  }
  return true;
}

// Placed attitudes: an arbitrary heading (about navigation z) times the
// nominal pose times a small placement error (about body axes).
// True when the planned poses carry their turns (PlannedHold).
bool PlannedTurns(const SimulatorOptions& options) {
  return options.planned_poses.size() > 1 &&
         std::all_of(options.planned_poses.begin() + 1, options.planned_poses.end(),
                     [](const PlannedHold& p) { return p.turn_axis.norm() > 0.5; });
}

// With planned turns every pose keeps the first pose's heading (its
// nominal attitude already follows the turns).
std::vector<Eigen::Quaterniond> PlaceAttitudes(const SimulatorOptions& options,
                                               const std::vector<Eigen::Quaterniond>& nominal,
                                               MainStream* stream) {
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const double placement_rad = options.placement_error_deg * kPi / 180.0;
  const bool chained = PlannedTurns(options);
  double first_heading = 0.0;
  std::vector<Eigen::Quaterniond> attitudes(nominal.size());
  for (size_t k = 0; k < nominal.size(); ++k) {
    double heading = 2.0 * kPi * u01(stream->rng);
    if (k == 0) first_heading = heading;
    if (chained) heading = first_heading;
    const Eigen::Vector3d tilt = stream->Normal3();
    attitudes[k] = (AxisAngle(heading, Eigen::Vector3d::UnitZ()) * nominal[k] *
                    FromRotationVector(placement_rad * tilt))
                       .normalized();
  }
  return attitudes;
}

// The timeline: samples of the first still period, of each later hold and
// of each rotation (with its hand profile when rotation_profile is hand).
struct Timeline {
  long first_still = 0;
  // Samples of pose k's hold (k >= 1; the first pose's is first_still).
  std::vector<long> hold;
  bool hand = false;
  std::vector<HandProfile> profiles;
  std::vector<long> rotation;
  size_t total = 0;
};

// The hand profiles draw from a stream of their own (G with the other
// effects in DrawEffects), so switching them on leaves every other number of
// a seed unchanged. False when the session is too long.
bool PlanTimeline(const SimulatorOptions& options, uint64_t seed,
                  const std::vector<double>& hold_seconds, Timeline* plan, std::string* error) {
  const double rate = options.sample_rate;
  const size_t pose_count = hold_seconds.size();
  plan->first_still = SampleCount(options.initial_still_seconds + hold_seconds[0], rate);
  plan->hold.resize(pose_count);
  for (size_t k = 0; k < pose_count; ++k) plan->hold[k] = SampleCount(hold_seconds[k], rate);
  plan->hand = options.rotation_profile == "hand";
  std::mt19937_64 extra_rng(seed ^ 0xc2b2ae3d27d4eb4fULL);
  plan->profiles.assign(pose_count > 0 ? pose_count - 1 : 0, HandProfile());
  plan->rotation.assign(plan->profiles.size(), SampleCount(options.rotation_seconds, rate));
  for (size_t k = 0; k < plan->profiles.size() && plan->hand; ++k) {
    plan->profiles[k] = HandProfile::Random(options, &extra_rng);
    plan->rotation[k] = std::max(1L, SampleCount(plan->profiles[k].seconds, rate));
  }
  // A planned turn's own duration.
  for (size_t k = 0; k < plan->rotation.size() && k + 1 < options.planned_poses.size(); ++k) {
    const double seconds = options.planned_poses[k + 1].turn_seconds;
    if (seconds > 0.0) plan->rotation[k] = std::max(1L, SampleCount(seconds, rate));
  }
  plan->total = static_cast<size_t>(plan->first_still);
  for (size_t k = 1; k < pose_count; ++k) plan->total += static_cast<size_t>(plan->hold[k]);
  for (long r : plan->rotation) plan->total += static_cast<size_t>(r);
  if (static_cast<double>(plan->total) > internal::kMaxSimulatedSamples) {
    if (error) *error = "the session is too long (" + std::to_string(plan->total) + " samples)";
    return false;
  }
  return true;
}

// Per-pose specific-force disturbances (SimulatorOptions::pose_disturbance),
// from a stream of their own.
std::vector<Eigen::Vector3d> DrawPoseDisturbances(const SimulatorOptions& options, uint64_t seed,
                                                  size_t pose_count) {
  std::mt19937_64 rng(seed ^ 0x510e527fade682d1ULL);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::vector<Eigen::Vector3d> disturbance(pose_count, Eigen::Vector3d::Zero());
  for (Eigen::Vector3d& d : disturbance) {
    if (options.pose_disturbance > 0.0) {
      const double x = n01(rng);
      const double y = n01(rng);
      const double z = n01(rng);
      d = options.pose_disturbance * Eigen::Vector3d(x, y, z);
    }
  }
  return disturbance;
}

// Turns the true specific force and body rate into raw samples of the log:
// the truth sensors, the effects, then the sensor noise (sensor_noise.h),
// whose white and random-walk draws come from the session's main stream.
class SampleWriter {
 public:
  SampleWriter(const SimulatorOptions& options, uint64_t seed, SimulatedSession* s,
               MainStream* stream)
      : o_(options),
        s_(*s),
        stream_(*stream),
        accel_effects_(
            options.accel_quadratic_std > 0.0 || options.accel_temperature_bias_std > 0.0 ||
            options.accel_temperature_scale_std > 0.0 || options.accel_bias_drift_std > 0.0),
        gyro_effects_(options.gyro_g_sensitivity_std > 0.0 ||
                      options.gyro_temperature_bias_std > 0.0 || options.gyro_bias_drift_std > 0.0),
        upper_inverse_(s->accel_truth.upper.inverse()),
        accel_inverse_(s->accel_truth.matrix().inverse()),
        gyro_inverse_(s->gyro_truth.matrix.inverse()),
        dt_(1.0 / options.sample_rate),
        noise_(options, s->accel_units_per_si, s->gyro_units_per_si, seed) {}

  double dt() const { return dt_; }
  Eigen::Vector3d Normal3() { return stream_.Normal3(); }

  // Writes sample i from the true specific force and body rate.
  void Emit(size_t i, const Eigen::Vector3d& force, const Eigen::Vector3d& body_rate) {
    const double t = static_cast<double>(i) * dt_;
    const double temperature = o_.temperature_end + (o_.temperature_start - o_.temperature_end) *
                                                        std::exp(-t / o_.temperature_tau);
    Eigen::Vector3d v = Accelerometer(force, temperature, t);
    Eigen::Vector3d u = Gyroscope(force, body_rate, temperature, t);
    noise_.Add([this] { return stream_.Normal3(); }, &v, &u);
    s_.log.t[i] = t;
    s_.log.accel[i] = v;
    s_.log.gyro[i] = u;
    s_.log.temperature[i] = temperature;
  }

 private:
  // The effect terms only when switched on, so that sessions without them
  // stay bit-identical.
  Eigen::Vector3d Accelerometer(const Eigen::Vector3d& force, double temperature, double t) const {
    if (!accel_effects_) return accel_inverse_ * force + s_.accel_truth.bias;
    const Eigen::Vector3d sensed =
        ApplyAccelEffects(s_.effects, s_.accel_truth.rotation.transpose() * force, temperature, t);
    return upper_inverse_ * sensed + s_.accel_truth.bias;
  }
  Eigen::Vector3d Gyroscope(const Eigen::Vector3d& force, const Eigen::Vector3d& body_rate,
                            double temperature, double t) const {
    if (!gyro_effects_) return gyro_inverse_ * body_rate + s_.gyro_truth.bias;
    const double dT = temperature - s_.effects.reference_temperature;
    return gyro_inverse_ *
               (body_rate + s_.gyro_g_sensitivity * force + s_.effects.gyro_temperature_bias * dT +
                s_.effects.gyro_bias_drift * t) +
           s_.gyro_truth.bias;
  }

  const SimulatorOptions& o_;
  SimulatedSession& s_;
  MainStream& stream_;
  const bool accel_effects_;
  const bool gyro_effects_;
  const Eigen::Matrix3d upper_inverse_;
  const Eigen::Matrix3d accel_inverse_;
  const Eigen::Matrix3d gyro_inverse_;
  const double dt_;
  internal::SensorNoise noise_;
};

// Earth rotation in the navigation frame (East-North-Up), zero when off.
Eigen::Vector3d EarthRateNav(const SimulatorOptions& options) {
  if (!std::isfinite(options.latitude_deg)) return Eigen::Vector3d::Zero();
  const double lat = options.latitude_deg * kPi / 180.0;
  return kEarthRate * Eigen::Vector3d(0.0, std::cos(lat), std::sin(lat));
}

// One still period of `count` samples from sample *i: the pose's specific
// force plus, when set, tremor (a first-order low-pass of white noise,
// stationary rms options.tremor per axis, started in its stationary
// distribution).
void WriteStill(const SimulatorOptions& options, const Eigen::Vector3d& force,
                const Eigen::Vector3d& rate, size_t count, SampleWriter* writer, size_t* i) {
  const double tremor_pole = std::exp(-2.0 * kPi * kTremorCornerHz * writer->dt());
  const double tremor_drive = options.tremor * std::sqrt(1.0 - tremor_pole * tremor_pole);
  Eigen::Vector3d tremor = Eigen::Vector3d::Zero();
  if (options.tremor > 0.0) tremor = options.tremor * writer->Normal3();
  const size_t end = *i + count;
  for (; *i < end; ++*i) {
    if (options.tremor > 0.0) {
      writer->Emit(*i, force + tremor, rate);
      tremor = tremor_pole * tremor + tremor_drive * writer->Normal3();
    } else {
      writer->Emit(*i, force, rate);
    }
  }
}

// The rotation from pose `from` to pose `to` over `count` samples from
// sample *i. Smooth: along the shortest great circle,
// q(t) = q0 exp(s(x) log(q0^-1 q1)), x = (t - t0) / T, whose body rate is
// w_b = axis * angle * s'(x) / T. Hand (`profile` set): q(x) = q0
// exp(s(tau(x)) angle axis) exp(beta(x) v), whose body rate is
// R(exp(beta v))^T axis angle s'(tau) tau'(x) / T + v beta'(x) / T.
void WriteRotation(const Eigen::Quaterniond& from, const Eigen::Quaterniond& to,
                   const HandProfile* profile, long count, const Eigen::Vector3d& gravity_nav,
                   const Eigen::Vector3d& earth_rate_nav, SampleWriter* writer, size_t* i) {
  Eigen::Quaterniond delta = from.conjugate() * to;
  if (delta.w() < 0.0) delta.coeffs() *= -1.0;
  const Eigen::AngleAxisd step(delta);
  const double duration = static_cast<double>(count) * writer->dt();
  for (long j = 0; j < count; ++j, ++*i) {
    const double x = static_cast<double>(j) / static_cast<double>(count);
    if (profile == nullptr) {
      const Eigen::Quaterniond q = from * AxisAngle(SmoothStep(x) * step.angle(), step.axis());
      writer->Emit(*i, q.conjugate() * gravity_nav,
                   step.axis() * (step.angle() * SmoothStepRate(x) / duration) +
                       q.conjugate() * earth_rate_nav);
      continue;
    }
    const HandProfile& p = *profile;
    const double tau = p.Warp(x);
    const Eigen::Quaterniond wobble = AxisAngle(p.Wobble(x), p.wobble_axis);
    const Eigen::Quaterniond q =
        from * AxisAngle(SmoothStep(tau) * step.angle(), step.axis()) * wobble;
    const Eigen::Vector3d main_rate =
        step.axis() * (step.angle() * SmoothStepRate(tau) * p.WarpRate(x) / duration);
    writer->Emit(*i, q.conjugate() * gravity_nav,
                 wobble.conjugate() * main_rate + p.wobble_axis * (p.WobbleRate(x) / duration) +
                     q.conjugate() * earth_rate_nav);
  }
}

bool SimulateImpl(const SimulatorOptions& options, uint64_t seed, SimulatedSession* session,
                  std::string* error) {
  if (!options.IsValid(error)) return false;
  std::vector<Eigen::Quaterniond> nominal;
  std::vector<int> nominal_up;
  if (options.planned_poses.empty()) {
    if (!SchemeAttitudes(options.scheme, seed, &nominal, &nominal_up, error)) return false;
  }
  std::vector<double> hold_seconds(nominal.size(), options.hold_seconds);
  const bool chained = PlannedTurns(options);
  for (const PlannedHold& p : options.planned_poses) {
    // A turn about the body axis a by t: q' = q exp(t a).
    nominal.push_back(
        chained && !nominal.empty()
            ? (nominal.back() * AxisAngle(p.turn_angle_deg * kPi / 180.0, p.turn_axis.normalized()))
                  .normalized()
            : UpToZenith(p.up));
    nominal_up.push_back(UpAxis(nominal.back()));
    hold_seconds.push_back(p.hold_seconds);
  }
  const size_t pose_count = nominal.size();

  MainStream stream(seed);
  SimulatedSession s;
  if (!DrawTruth(options, seed, &stream.rng, &s, error)) return false;
  const std::vector<Eigen::Quaterniond> attitudes = PlaceAttitudes(options, nominal, &stream);
  Timeline plan;
  if (!PlanTimeline(options, seed, hold_seconds, &plan, error)) return false;

  ImuLog& log = s.log;
  log.source = "simulated " + (options.planned_poses.empty() ? options.scheme : "plan") + " seed " +
               std::to_string(seed);
  log.t.resize(plan.total);
  log.accel.resize(plan.total);
  log.gyro.resize(plan.total);
  log.temperature.resize(plan.total);

  const Eigen::Vector3d gravity_nav(0.0, 0.0, options.gravity);
  const Eigen::Vector3d earth_rate_nav = EarthRateNav(options);
  const std::vector<Eigen::Vector3d> disturbance = DrawPoseDisturbances(options, seed, pose_count);
  SampleWriter writer(options, seed, &s, &stream);
  s.poses.resize(pose_count);
  size_t i = 0;
  for (size_t k = 0; k < pose_count; ++k) {
    SimulatedPose& pose = s.poses[k];
    const size_t still = static_cast<size_t>(k == 0 ? plan.first_still : plan.hold[k]);
    pose.begin = i;
    pose.end = i + still;
    pose.attitude = attitudes[k];
    pose.nominal_up = nominal_up[k];
    WriteStill(options, attitudes[k].conjugate() * gravity_nav + disturbance[k],
               attitudes[k].conjugate() * earth_rate_nav, still, &writer, &i);
    if (k + 1 == pose_count) break;
    WriteRotation(attitudes[k], attitudes[k + 1], plan.hand ? &plan.profiles[k] : nullptr,
                  plan.rotation[k], gravity_nav, earth_rate_nav, &writer, &i);
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
  SchemeKind kind;
  std::string scheme_error;
  if (!ParseScheme(o.scheme, &kind, pose_count, &scheme_error)) {
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
    if (PlannedTurns(o) && previous_up.norm() > 0.5) {
      const Eigen::Vector3d moved =
          Eigen::AngleAxisd(-p.turn_angle_deg * kPi / 180.0, p.turn_axis.normalized()) *
          previous_up;
      if (moved.dot(p.up.normalized()) < std::cos(kPi / 180.0)) {
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
  if (o.rotation_profile != "smooth" && o.rotation_profile != "hand") {
    c.Say("SimulatorOptions.rotation_profile: '" + o.rotation_profile +
          "' is not one of smooth, hand");
    return false;
  }
  if (!c.OneSample("hand_min_seconds", o.hand_min_seconds)) return false;
  if (!(o.hand_max_seconds >= o.hand_min_seconds) || !std::isfinite(o.hand_max_seconds)) {
    return c.Fail("hand_max_seconds", o.hand_max_seconds, "must be at least hand_min_seconds");
  }
  return c.NonNegative("hand_wobble_deg", o.hand_wobble_deg) &&
         c.NonNegative("gyro_g_sensitivity_std", o.gyro_g_sensitivity_std) &&
         c.NonNegative("tremor", o.tremor) && c.NonNegative("pose_disturbance", o.pose_disturbance);
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
  return c.NonNegative("fixture_attitude_noise_deg", o.fixture_attitude_noise_deg) &&
         c.NonNegative("accel_quadratic_std", o.accel_quadratic_std) &&
         c.NonNegative("accel_temperature_bias_std", o.accel_temperature_bias_std) &&
         c.AtMost("accel_temperature_scale_std", o.accel_temperature_scale_std, 0.01) &&
         c.NonNegative("accel_bias_drift_std", o.accel_bias_drift_std) &&
         c.NonNegative("gyro_temperature_bias_std", o.gyro_temperature_bias_std) &&
         c.NonNegative("gyro_bias_drift_std", o.gyro_bias_drift_std) &&
         c.Finite("effect_reference_temperature", o.effect_reference_temperature);
}

// The session's length against internal::kMaxSimulatedSamples.
bool CheckLength(const SimulatorOptions& o, long pose_count, const FieldCheck& c) {
  double hold_total = o.hold_seconds * static_cast<double>(pose_count);
  if (!o.planned_poses.empty()) {
    hold_total = 0.0;
    for (const PlannedHold& p : o.planned_poses) hold_total += p.hold_seconds;
  }
  const double samples =
      (o.initial_still_seconds + hold_total +
       static_cast<double>(pose_count - 1) *
           (o.rotation_profile == "hand" ? o.hand_max_seconds : o.rotation_seconds)) *
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
                    {"pose_disturbance", o.pose_disturbance},
                    {"accel_bias_instability", o.accel_bias_instability},
                    {"gyro_bias_instability", o.gyro_bias_instability},
                    {"bias_instability_tau_low", o.bias_instability_tau_low},
                    {"bias_instability_tau_high", o.bias_instability_tau_high},
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
