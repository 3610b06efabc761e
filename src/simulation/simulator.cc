// The synthesis of a simulated multi-position session (Simulate): the truth
// sensors and effects, the placed poses, the timeline, and the samples of
// each still period and each rotation between poses. The poses come from
// simulator_schemes.cc, the option checks from simulator_validation.cc.
#include "gravcal/simulation/simulator.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <exception>
#include <random>

#include "gravcal/core/gravity.h"
#include "simulation/sensor_noise.h"
#include "simulation/simulator_schemes.h"
#include "simulation/smooth_step.h"
#include "util/random_vector.h"
#include "util/so3.h"
#include "util/units.h"

namespace gravcal {
namespace {

using internal::AxisAngle;
using internal::FromRotationVector;

// Corner frequency of the first-order low-pass that shapes hand tremor, Hz.
constexpr double kTremorCornerHz = 5.0;

using internal::SmoothStep;
using internal::SmoothStepRate;

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
    p.amplitude = options.hand_wobble_deg * M_PI / 180.0 * n01(*rng);
    const Eigen::Vector3d v = internal::DrawVector3([&] { return n01(*rng); });
    if (v.norm() > 0.0) p.wobble_axis = v.normalized();
    return p;
  }
  double Warp(double x) const {
    double tau = x;
    for (int j = 1; j <= 3; ++j) tau += c[j - 1] * std::sin(2.0 * M_PI * j * x) / (2.0 * M_PI * j);
    return tau;
  }
  double WarpRate(double x) const {
    double rate = 1.0;
    for (int j = 1; j <= 3; ++j) rate += c[j - 1] * std::cos(2.0 * M_PI * j * x);
    return rate;
  }
  double Wobble(double x) const { return amplitude * 64.0 * std::pow(x * (1.0 - x), 3); }
  double WobbleRate(double x) const {
    return amplitude * 192.0 * std::pow(x * (1.0 - x), 2) * (1.0 - 2.0 * x);
  }
};

// True when an effect of `sensor` has a spread.
bool AnySpread(const SimulatorOptions& o, EffectSensor sensor) {
  for (const EffectInfo& info : EffectCatalogue()) {
    if (info.sensor == sensor && info.simulation.key != nullptr &&
        o.effect_std[info.effect] > 0.0) {
      return true;
    }
  }
  return false;
}

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
  // In registry order, three values per draw (a matrix row by row).
  for (const EffectInfo& info : EffectCatalogue()) {
    double* values = e.Block(info.effect);
    if (values == nullptr) continue;
    const double std = info.simulation.key != nullptr ? o.effect_std[info.effect] : 0.0;
    for (int i = 0; i < info.num_parameters; i += 3) {
      const Eigen::Vector3d d = draw3(std);
      for (int j = 0; j < 3 && i + j < info.num_parameters; ++j) values[i + j] = d(j);
    }
  }
  s->gyro_g_sensitivity = e.Matrix(Effect::kGyroGSensitivity);
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
  const double gyro_scale =
      options.raw_counts ? internal::kDegToRad / options.gyro_counts_per_dps : 1.0;
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
// With planned turns every pose keeps the first pose's heading (its
// nominal attitude already follows the turns).
std::vector<Eigen::Quaterniond> PlaceAttitudes(const SimulatorOptions& options,
                                               const std::vector<Eigen::Quaterniond>& nominal,
                                               MainStream* stream) {
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const double placement_rad = options.placement_error_deg * M_PI / 180.0;
  const bool chained = internal::PlannedTurns(options);
  double first_heading = 0.0;
  std::vector<Eigen::Quaterniond> attitudes(nominal.size());
  for (size_t k = 0; k < nominal.size(); ++k) {
    double heading = 2.0 * M_PI * u01(stream->rng);
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
  plan->hand = options.rotation_profile == RotationProfile::kHand;
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
        accel_effects_(AnySpread(options, EffectSensor::kAccelerometer)),
        gyro_effects_(AnySpread(options, EffectSensor::kGyroscope)),
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
    // w + G f + gamma dT + eta t: every gyroscope effect's term, in rad/s.
    const double dT = temperature - s_.effects.reference_temperature;
    const double* all[kNumEffects] = {};
    PointIntoBlocks<double>(nullptr, s_.effects.gyro.data(), all);
    Eigen::Vector3d offset;
    GyroEffectOffset<double>(all, force.data(), dT, t, offset.data());
    return gyro_inverse_ * (body_rate + offset) + s_.gyro_truth.bias;
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
  const double lat = options.latitude_deg * M_PI / 180.0;
  return kEarthRate * Eigen::Vector3d(0.0, std::cos(lat), std::sin(lat));
}

// One still period of `count` samples from sample *i: the pose's specific
// force plus, when set, tremor (a first-order low-pass of white noise,
// stationary rms options.tremor per axis, started in its stationary
// distribution).
void WriteStill(const SimulatorOptions& options, const Eigen::Vector3d& force,
                const Eigen::Vector3d& rate, size_t count, SampleWriter* writer, size_t* i) {
  const double tremor_pole = std::exp(-2.0 * M_PI * kTremorCornerHz * writer->dt());
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
  internal::NominalPoses nominal;
  if (!internal::MakeNominalPoses(options, seed, &nominal, error)) return false;
  const size_t pose_count = nominal.attitudes.size();

  MainStream stream(seed);
  SimulatedSession s;
  if (!DrawTruth(options, seed, &stream.rng, &s, error)) return false;
  const std::vector<Eigen::Quaterniond> attitudes =
      PlaceAttitudes(options, nominal.attitudes, &stream);
  Timeline plan;
  if (!PlanTimeline(options, seed, nominal.hold_seconds, &plan, error)) return false;

  ImuLog& log = s.log;
  log.source = "simulated " + (options.planned_poses.empty() ? ToString(options.scheme) : "plan") +
               " seed " + std::to_string(seed);
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
    pose.nominal_up = nominal.nominal_up[k];
    WriteStill(options, attitudes[k].conjugate() * gravity_nav + disturbance[k],
               attitudes[k].conjugate() * earth_rate_nav, still, &writer, &i);
    if (k + 1 == pose_count) break;
    WriteRotation(attitudes[k], attitudes[k + 1], plan.hand ? &plan.profiles[k] : nullptr,
                  plan.rotation[k], gravity_nav, earth_rate_nav, &writer, &i);
  }

  *session = std::move(s);
  return true;
}

}  // namespace

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

}  // namespace gravcal
