#include "gravcal/simulation/handheld_simulator.h"

#include <Eigen/LU>
#include <cmath>
#include <random>
#include <sstream>

#include "estimation/strapdown.h"
#include "simulation/sensor_noise.h"
#include "util/random_vector.h"
#include "util/units.h"

namespace gravcal {
namespace {

using internal::RotationVectorToQuaternion;

using Vec3 = Eigen::Vector3d;
using Quat = Eigen::Quaterniond;

using internal::kDegToRad;
// Truth attitude integration steps per sample.
constexpr int kSubsteps = 4;
// Ramp at each end of a turn, s (rate rises as sin^2).
constexpr double kRamp = 1.0;
// Pause between turns (regrip, or the table's return), s.
constexpr double kPause = 1.0;
// The 90-degree tilts that bring z horizontal and back, s.
constexpr double kTiltSeconds = 2.5;

// One sinusoid: amplitude * sin(2 pi f t + phase).
struct Sine {
  double amplitude = 0.0;
  double hz = 0.0;
  double phase = 0.0;
  double Value(double t) const { return amplitude * std::sin(2.0 * M_PI * hz * t + phase); }
  double Rate(double t) const {
    return amplitude * 2.0 * M_PI * hz * std::cos(2.0 * M_PI * hz * t + phase);
  }
  double Acceleration(double t) const {
    const double w = 2.0 * M_PI * hz;
    return -amplitude * w * w * std::sin(w * t + phase);
  }
};

// Three random sinusoids per axis with frequencies in [lo, hi] Hz and a
// total rms of `rms` per axis.
std::vector<Sine> RandomSines(double rms, double lo, double hi, std::mt19937_64* rng) {
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::vector<Sine> out;
  for (int i = 0; i < 9; ++i) {
    Sine s;
    s.amplitude = rms / std::sqrt(1.5);
    s.hz = lo + (hi - lo) * u01(*rng);
    s.phase = 2.0 * M_PI * u01(*rng);
    out.push_back(s);
  }
  return out;
}

// Sum over the three sinusoids of each axis of the given member function.
Vec3 SumSines(const std::vector<Sine>& sines, double t, double (Sine::*f)(double) const) {
  Vec3 v = Vec3::Zero();
  for (size_t i = 0; i < sines.size(); ++i) v(static_cast<int>(i / 3)) += (sines[i].*f)(t);
  return v;
}

// A turn about a body axis, or a still period (scale 0):
//   w(t) = axis * scale * shape(t - t0),
//   shape = window * max(0.2, 1 + variation * sum of slow sines),
// window rising and falling as sin^2 over kRamp at each end.
struct Phase {
  double t0 = 0.0;
  double t1 = 0.0;
  Vec3 axis = Vec3::UnitX();
  double scale = 0.0;
  double variation = 0.0;
  Sine irregular[3];
  // Whether the hand's wobble applies (handheld turns).
  bool wobble = false;

  double Window(double tau) const {
    const double edge = std::min(tau, (t1 - t0) - tau) / kRamp;
    if (edge <= 0.0) return 0.0;
    if (edge >= 1.0) return 1.0;
    const double s = std::sin(0.5 * M_PI * edge);
    return s * s;
  }
  double Shape(double tau) const {
    double m = 1.0;
    for (const Sine& s : irregular) m += variation * s.Value(tau);
    return Window(tau) * std::max(0.2, m);
  }
  // Chooses the scale so that the turn covers `angle` radians.
  void SetAngle(double angle) {
    const int n = 4000;
    const double h = (t1 - t0) / n;
    double sum = 0.0;
    for (int i = 0; i <= n; ++i) {
      const double w = (i == 0 || i == n) ? 1.0 : (i % 2 == 1 ? 4.0 : 2.0);
      sum += w * Shape(i * h);
    }
    scale = angle / (sum * h / 3.0);
  }
};

class Trajectory {
 public:
  Vec3 Rate(double t) const {
    Vec3 w = SumSines(angular_tremor_, t, &Sine::Value);
    for (const Phase& p : phases_) {
      if (t < p.t0 || t >= p.t1) continue;
      w += p.axis * (p.scale * p.Shape(t - p.t0));
      if (p.wobble) w += p.Window(t - p.t0) * SumSines(wobble_, t, &Sine::Rate);
    }
    return w;
  }
  std::vector<Phase> phases_;
  std::vector<Sine> wobble_;
  std::vector<Sine> angular_tremor_;
  std::vector<Sine> sway_;
  std::vector<Sine> tremor_;
};

// Half turns (handheld) or whole turns (turntable) closest to rate * time.
double TurnAngle(double rate_rad, double seconds, double unit) {
  return unit * std::max(1.0, std::round(rate_rad * seconds / unit));
}

// The motion session's random stream. One normal distribution serves every
// draw (it caches every other value, so sharing it is part of what makes a
// seed's session what it is).
struct MotionStream {
  explicit MotionStream(uint64_t seed) : rng(seed) {}
  std::mt19937_64 rng;
  std::normal_distribution<double> n01{0.0, 1.0};
  std::uniform_real_distribution<double> u01{0.0, 1.0};
  Vec3 Normal3() {
    return internal::DrawVector3([this] { return n01(rng); });
  }
};

// The truth sensors, as in simulator.cc: scale in SI per raw unit.
void DrawMotionTruth(const SimulatorOptions& sensor, uint64_t seed, MotionStream* stream,
                     SimulatedSession* s) {
  const double accel_scale = sensor.raw_counts ? kStandardGravity / sensor.accel_counts_per_g : 1.0;
  const double gyro_scale = sensor.raw_counts ? kDegToRad / sensor.gyro_counts_per_dps : 1.0;
  s->seed = seed;
  s->gravity = sensor.gravity;
  s->accel_units_per_si = 1.0 / accel_scale;
  s->gyro_units_per_si = 1.0 / gyro_scale;
  s->accel_truth = AccelModel::Random(AccelParameterization::kAffine, accel_scale,
                                      sensor.accel_scale_std, sensor.accel_misalignment_std,
                                      sensor.accel_bias_std / accel_scale, &stream->rng);
  s->gyro_truth = GyroModel::Random(gyro_scale, sensor.gyro_scale_std, sensor.gyro_misalignment_std,
                                    sensor.gyro_bias_std / gyro_scale, &stream->rng);
}

// The phases of the profile from t = initial_still_seconds, with the
// starting attitude and the rate table's segments; returns the session's
// length in seconds.
double PlanPhases(const SimulatorOptions& sensor, const MotionOptions& motion, MotionStream* stream,
                  Trajectory* traj, Quat* start, MotionSession* out) {
  const MotionProfile profile = motion.profile;
  const double rate = motion.rate_dps * kDegToRad;
  const double turn_seconds = motion.seconds_per_axis;
  double t = motion.initial_still_seconds;
  *start = Quat::Identity();
  if (profile != MotionProfile::kRateTable) {
    const double heading = 2.0 * M_PI * stream->u01(stream->rng);
    const double tilt = profile == MotionProfile::kTurntable ? 0.0 : 2.0 * kDegToRad;
    *start = RotationVectorToQuaternion(Vec3(0, 0, heading)) *
             RotationVectorToQuaternion(
                 Vec3(tilt * stream->n01(stream->rng), tilt * stream->n01(stream->rng), 0.0));
  }
  auto add_turn = [&](const Vec3& axis, double seconds, bool irregular) {
    Phase p;
    p.t0 = t;
    p.t1 = t + seconds;
    p.axis = axis;
    p.wobble = irregular;
    if (irregular) {
      p.variation = motion.rate_variation;
      for (Sine& sine : p.irregular) {
        sine.amplitude = 1.0 / std::sqrt(1.5);
        sine.hz = 0.1 + 0.4 * stream->u01(stream->rng);
        sine.phase = 2.0 * M_PI * stream->u01(stream->rng);
      }
    }
    traj->phases_.push_back(p);
    t = p.t1;
    return &traj->phases_.back();
  };
  if (profile == MotionProfile::kHandheld || profile == MotionProfile::kTurntable) {
    const bool irregular = profile == MotionProfile::kHandheld;
    const double unit = irregular ? M_PI : 2.0 * M_PI;
    for (int round = 0; round < motion.rounds; ++round) {
      if (round > 0) t += kPause;
      add_turn(Vec3::UnitX(), turn_seconds, irregular)
          ->SetAngle(TurnAngle(rate, turn_seconds, unit));
      t += kPause;
      add_turn(Vec3::UnitY(), turn_seconds, irregular)
          ->SetAngle(TurnAngle(rate, turn_seconds, unit));
      t += kPause;
      add_turn(Vec3::UnitX(), kTiltSeconds, false)->SetAngle(0.5 * M_PI);
      add_turn(Vec3::UnitZ(), turn_seconds, irregular)
          ->SetAngle(TurnAngle(rate, turn_seconds, unit));
      add_turn(Vec3::UnitX(), kTiltSeconds, false)->SetAngle(-0.5 * M_PI);
    }
  } else if (profile == MotionProfile::kVertical) {
    const double seconds = 3.0 * turn_seconds * motion.rounds;
    add_turn(Vec3::UnitZ(), seconds, true)->SetAngle(TurnAngle(rate, seconds, M_PI));
  } else {
    // Rate table: x up, y up, z up; +rate then -rate about the up axis.
    // Each constant-rate part is a segment; between axes the unit is
    // re-mounted (a 90-degree turn).
    *start = RotationVectorToQuaternion(Vec3(0, -0.5 * M_PI, 0));  // x up
    for (int axis = 0; axis < 3; ++axis) {
      for (double sign : {1.0, -1.0}) {
        Phase* p = add_turn(Vec3::Unit(axis), turn_seconds + 2.0 * kRamp, false);
        p->scale = sign * rate;
        RateTableSegment seg;
        seg.begin = static_cast<size_t>(std::ceil((p->t0 + kRamp) * sensor.sample_rate + 1e-9));
        seg.end = static_cast<size_t>(std::floor((p->t1 - kRamp) * sensor.sample_rate - 1e-9));
        seg.rate = sign * rate * Vec3::Unit(axis);
        out->segments.push_back(seg);
        t += kPause;
      }
      // The +rate and -rate turns cancel, so axis a is up again. The turn R
      // (body frame) that brings axis a+1 up maps e_{a+1} to e_a: about
      // e_{a+1} x e_a by 90 deg, i.e. about z by -90 deg (x up -> y up) and
      // about x by -90 deg (y up -> z up).
      if (axis == 0) add_turn(Vec3::UnitZ(), kTiltSeconds, false)->SetAngle(-0.5 * M_PI);
      if (axis == 1) add_turn(Vec3::UnitX(), kTiltSeconds, false)->SetAngle(-0.5 * M_PI);
      t += kPause;
    }
  }
  return t + motion.final_still_seconds;
}

// The hand's wobble, angular tremor, sway and tremor (handheld and
// vertical profiles).
void AddHandMotion(const MotionOptions& motion, std::mt19937_64* rng, Trajectory* traj) {
  const double wobble_rad = motion.axis_wobble_deg * kDegToRad;
  traj->wobble_ = RandomSines(wobble_rad, 0.2, 1.0, rng);
  traj->angular_tremor_ = RandomSines(motion.angular_tremor, 8.0, 12.0, rng);
  traj->sway_ = RandomSines(motion.sway, 0.05, motion.sway_hz, rng);
  // Tremor displacement whose acceleration has the given rms.
  traj->tremor_ = RandomSines(motion.tremor, 8.0, 12.0, rng);
  for (Sine& sine : traj->tremor_) {
    const double w = 2.0 * M_PI * sine.hz;
    sine.amplitude /= w * w;
  }
}

// Samples 0..count-1: the truth attitude integrated from the rate (Simpson
// substeps plus the coning term), the position, velocity and acceleration of
// the hand and the lever arm, and the raw outputs.
void WriteMotionSamples(const SimulatorOptions& sensor, const MotionOptions& motion,
                        const Trajectory& traj, const Quat& start, const Vec3& lever, bool hand,
                        size_t count, uint64_t seed, MotionStream* stream, MotionSession* out) {
  SimulatedSession& s = out->sensor;
  const Eigen::Matrix3d accel_inverse = s.accel_truth.matrix().inverse();
  const Eigen::Matrix3d gyro_inverse = s.gyro_truth.matrix.inverse();
  const double dt = 1.0 / sensor.sample_rate;
  const double h = dt / kSubsteps;
  const Vec3 up_g(0.0, 0.0, sensor.gravity);
  Quat q = start;
  const Vec3 lever_start = start * lever;
  internal::SensorNoise noise(sensor, s.accel_units_per_si, s.gyro_units_per_si, seed);
  for (size_t i = 0; i < count; ++i) {
    const double ti = static_cast<double>(i) * dt;
    if (i > 0) {
      // Substeps: Simpson's rule for the integral of the rate plus the
      // coning term w_a x w_b h^2 / 12 (Bortz equation to second order).
      for (int k = 0; k < kSubsteps; ++k) {
        const double ta = ti - dt + k * h;
        const Vec3 wa = traj.Rate(ta);
        const Vec3 wb = traj.Rate(ta + h);
        const Vec3 rotation =
            (h / 6.0) * (wa + 4.0 * traj.Rate(ta + 0.5 * h) + wb) + (h * h / 12.0) * wa.cross(wb);
        q = q * RotationVectorToQuaternion(rotation);
      }
      q.normalize();
    }
    const Vec3 w = traj.Rate(ti);
    const Eigen::Matrix3d c = q.toRotationMatrix();
    Vec3 p = Vec3::Zero();
    Vec3 v = Vec3::Zero();
    Vec3 a = Vec3::Zero();
    if (hand) {
      p = SumSines(traj.sway_, ti, &Sine::Value) + SumSines(traj.tremor_, ti, &Sine::Value);
      v = SumSines(traj.sway_, ti, &Sine::Rate) + SumSines(traj.tremor_, ti, &Sine::Rate);
      a = SumSines(traj.sway_, ti, &Sine::Acceleration) +
          SumSines(traj.tremor_, ti, &Sine::Acceleration);
    }
    if (motion.lever_arm > 0.0) {
      // r^n = C r^b: v += C (w x r), a += C (w' x r + w x (w x r)).
      const double e = 1e-4;
      const Vec3 w_dot = (traj.Rate(ti + e) - traj.Rate(ti - e)) / (2.0 * e);
      p += c * lever - lever_start;
      v += c * w.cross(lever);
      a += c * (w_dot.cross(lever) + w.cross(w.cross(lever)));
    }
    const Vec3 f = c.transpose() * (a + up_g);
    Vec3 raw_a = accel_inverse * f + s.accel_truth.bias;
    Vec3 raw_g = gyro_inverse * w + s.gyro_truth.bias;
    noise.Add([stream] { return stream->Normal3(); }, &raw_a, &raw_g);
    s.log.t[i] = ti;
    s.log.accel[i] = raw_a;
    s.log.gyro[i] = raw_g;
    s.log.temperature[i] =
        sensor.temperature_end + (sensor.temperature_start - sensor.temperature_end) *
                                     std::exp(-ti / sensor.temperature_tau);
    out->attitude[i] = q;
    out->position[i] = p;
    out->velocity[i] = v;
  }
}

}  // namespace

bool MotionOptions::IsValid(std::string* error) const {
  auto check = [&](const char* key, double v, bool ok) {
    if (ok && std::isfinite(v)) return true;
    *error = std::string("key '") + key + "': out of range";
    return false;
  };
  return check("hh_initial_still", initial_still_seconds, initial_still_seconds >= 0.0) &&
         check("hh_final_still", final_still_seconds, final_still_seconds >= 0.0) &&
         check("hh_seconds_per_axis", seconds_per_axis, seconds_per_axis >= 2.0 * kRamp + 0.5) &&
         check("hh_rate", rate_dps, rate_dps > 0.0 && rate_dps <= 2000.0) &&
         check("hh_rate_variation", rate_variation,
               rate_variation >= 0.0 && rate_variation <= 2.0) &&
         check("hh_axis_wobble", axis_wobble_deg,
               axis_wobble_deg >= 0.0 && axis_wobble_deg <= 30.0) &&
         check("hh_sway", sway, sway >= 0.0 && sway <= 1.0) &&
         check("hh_sway_hz", sway_hz, sway_hz > 0.05 && sway_hz <= 5.0) &&
         check("hh_tremor", tremor, tremor >= 0.0 && tremor <= 10.0) &&
         check("hh_angular_tremor", angular_tremor,
               angular_tremor >= 0.0 && angular_tremor <= 1.0) &&
         check("hh_lever_arm", lever_arm, lever_arm >= 0.0 && lever_arm <= 1.0) &&
         check("hh_rounds", rounds, rounds >= 1 && rounds <= 100);
}

bool SimulateMotion(const SimulatorOptions& sensor, const MotionOptions& motion, uint64_t seed,
                    MotionSession* session, std::string* error) {
  if (!sensor.IsValid(error) || !motion.IsValid(error)) return false;
  MotionStream stream(seed);
  MotionSession out;
  DrawMotionTruth(sensor, seed, &stream, &out.sensor);
  Trajectory traj;
  Quat start;
  const double total_seconds = PlanPhases(sensor, motion, &stream, &traj, &start, &out);
  const bool hand =
      motion.profile == MotionProfile::kHandheld || motion.profile == MotionProfile::kVertical;
  if (hand) AddHandMotion(motion, &stream.rng, &traj);
  Vec3 lever_direction;
  for (int i = 0; i < 3; ++i) lever_direction(i) = stream.n01(stream.rng);
  const Vec3 lever = motion.lever_arm * lever_direction.normalized();
  out.lever_arm = lever;

  const double samples = std::floor(total_seconds * sensor.sample_rate) + 1.0;
  if (!(samples <= internal::kMaxSimulatedSamples)) {
    *error = "the motion session is too long (" + std::to_string(samples) + " samples)";
    return false;
  }
  const size_t count = static_cast<size_t>(samples);
  ImuLog& log = out.sensor.log;
  log.source =
      std::string("simulated ") + ToString(motion.profile) + " seed " + std::to_string(seed);
  log.t.resize(count);
  log.accel.resize(count);
  log.gyro.resize(count);
  log.temperature.resize(count);
  out.attitude.resize(count);
  out.position.resize(count);
  out.velocity.resize(count);
  WriteMotionSamples(sensor, motion, traj, start, lever, hand, count, seed, &stream, &out);
  *session = std::move(out);
  return true;
}

SensorErrorTruth ErrorTruth(const SimulatedSession& session) {
  SensorErrorTruth t;
  const double sa = 1.0 / session.accel_units_per_si;
  const double sg = 1.0 / session.gyro_units_per_si;
  t.accel_e = sa * session.accel_truth.matrix().inverse() - Eigen::Matrix3d::Identity();
  t.accel_bias = sa * session.accel_truth.bias;
  t.gyro_e = sg * session.gyro_truth.matrix.inverse() - Eigen::Matrix3d::Identity();
  t.gyro_bias = sg * session.gyro_truth.bias;
  return t;
}

}  // namespace gravcal
