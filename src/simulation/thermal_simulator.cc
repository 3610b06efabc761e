#include "gravcal/simulation/thermal_simulator.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <random>

#include "core/enum_names.h"

namespace gravcal {

namespace {
const internal::EnumName<ThermalProfile> kThermalProfiles[] = {
    {ThermalProfile::kSoakSteps, "soak_steps"},
    {ThermalProfile::kWarmUp, "warm_up"},
    {ThermalProfile::kCoolDown, "cool_down"},
    {ThermalProfile::kWarmUpPoses, "warm_up_poses"},
    {ThermalProfile::kWarmCoolPoses, "warm_cool_poses"}};
}  // namespace

GRAVCAL_ENUM_STRINGS(ThermalProfile, kThermalProfiles)

bool ThermalSimulatorOptions::IsValid(std::string* error) const {
  auto fail = [error](const std::string& what) {
    if (error != nullptr) *error = what;
    return false;
  };
  if (!(sample_rate > 0.0)) return fail("thermal simulator: sample_rate must be positive");
  if (!(hold_seconds > 0.0) || !(rotation_seconds > 0.0)) {
    return fail("thermal simulator: hold_seconds and rotation_seconds must be positive");
  }
  if (poses < 6 || poses > 12) return fail("thermal simulator: poses must be between 6 and 12");
  if (profile == ThermalProfile::kSoakSteps && soak_temperatures.empty()) {
    return fail("thermal simulator: soak_temperatures is empty");
  }
  if (profile != ThermalProfile::kSoakSteps &&
      (!(ramp_time_constant > 0.0) || !(ramp_seconds > 0.0))) {
    return fail("thermal simulator: ramp_time_constant and ramp_seconds must be positive");
  }
  if (!(lag_time_constant >= 0.0)) {
    return fail("thermal simulator: lag_time_constant must be >= 0");
  }
  for (const std::vector<double>* v :
       {&accel_bias_tempco, &accel_scale_tempco, &accel_misalignment_tempco, &gyro_bias_tempco,
        &gyro_scale_tempco, &gyro_misalignment_tempco}) {
    if (static_cast<int>(v->size()) > kMaxThermalOrder) {
      return fail("thermal simulator: at most " + std::to_string(kMaxThermalOrder) +
                  " temperature coefficients per term");
    }
  }
  return true;
}

namespace {

// The up directions (body frame) of the poses: the six faces, then
// 45-degree poses.
std::vector<Eigen::Vector3d> PoseDirections(int count) {
  std::vector<Eigen::Vector3d> up = {
      Eigen::Vector3d::UnitZ(),  -Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX(),
      -Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),  -Eigen::Vector3d::UnitY(),
      Eigen::Vector3d(1, 0, 1),  Eigen::Vector3d(0, 1, 1),  Eigen::Vector3d(1, 1, 0),
      Eigen::Vector3d(-1, 0, 1), Eigen::Vector3d(0, -1, 1), Eigen::Vector3d(1, -1, 0)};
  up.resize(count);
  for (Eigen::Vector3d& u : up) u.normalize();
  return up;
}

// A term with per-axis coefficients drawn N(0, stds[k]) times `units`.
void DrawTerm(ThermalSensor sensor, ThermalQuantity q, const std::vector<double>& stds,
              double units, std::mt19937_64* rng, ThermalPolynomial* p) {
  int order = static_cast<int>(stds.size());
  while (order > 0 && stds[order - 1] == 0.0) --order;
  p->Resize(ThermalComponents(sensor, q), order);
  p->max_order = order;
  p->selection = "truth";
  std::normal_distribution<double> n(0.0, 1.0);
  for (int i = 0; i < p->coefficients.rows(); ++i) {
    for (int k = 0; k < order; ++k) p->coefficients(i, k) = stds[k] * units * n(*rng);
  }
}

// One segment of the attitude schedule: from attitude a to b over
// [t0, t0 + duration) (a == b: held).
struct Segment {
  double t0 = 0.0;
  double duration = 0.0;
  Eigen::Quaterniond a, b;
};

}  // namespace

bool SimulateThermal(const ThermalSimulatorOptions& o, uint64_t seed,
                     ThermalSimulatedSession* session, std::string* error) {
  if (!o.IsValid(error)) return false;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  ThermalSimulatedSession out;
  out.seed = seed;
  // Raw units per SI unit: counts, or 1 when the session is written in SI.
  const double accel_units = o.raw_counts ? o.accel_counts_per_g / o.gravity : 1.0;
  const double gyro_units = o.raw_counts ? o.gyro_counts_per_dps * 180.0 / M_PI : 1.0;
  out.accel_units_per_si = accel_units;
  out.gyro_units_per_si = gyro_units;

  // Base models (raw -> SI): a = U (v - b), w = M_g (u - b_g).
  out.accel =
      AccelModel::Random(AccelParameterization::kScaleMisalignment, 1.0 / accel_units, o.scale_std,
                         o.misalignment_std, o.accel_bias_std * accel_units, &rng);
  out.gyro = GyroModel::Random(1.0 / gyro_units, o.scale_std, o.misalignment_std,
                               o.gyro_bias_std * gyro_units, &rng);
  ThermalModel& truth = out.thermal;
  truth.reference_temperature = o.reference_temperature;
  truth.lag_time_constant = o.lag_time_constant;
  DrawTerm(ThermalSensor::kAccel, ThermalQuantity::kBias, o.accel_bias_tempco, accel_units, &rng,
           &truth.accel.bias);
  DrawTerm(ThermalSensor::kAccel, ThermalQuantity::kScale, o.accel_scale_tempco, 1.0, &rng,
           &truth.accel.scale);
  DrawTerm(ThermalSensor::kAccel, ThermalQuantity::kMisalignment, o.accel_misalignment_tempco, 1.0,
           &rng, &truth.accel.misalignment);
  DrawTerm(ThermalSensor::kGyro, ThermalQuantity::kBias, o.gyro_bias_tempco, gyro_units, &rng,
           &truth.gyro.bias);
  DrawTerm(ThermalSensor::kGyro, ThermalQuantity::kScale, o.gyro_scale_tempco, 1.0, &rng,
           &truth.gyro.scale);
  DrawTerm(ThermalSensor::kGyro, ThermalQuantity::kMisalignment, o.gyro_misalignment_tempco, 1.0,
           &rng, &truth.gyro.misalignment);

  // The attitude schedule and the recorded temperature against time.
  const std::vector<Eigen::Vector3d> up = PoseDirections(o.poses);
  auto attitude_of = [&](int pose) {
    const Eigen::Vector3d u =
        pose < 0 ? o.single_pose_up.normalized() : up[pose % static_cast<int>(up.size())];
    // C u = z (the axis u points up).
    return Eigen::Quaterniond::FromTwoVectors(u, Eigen::Vector3d::UnitZ());
  };
  std::vector<Segment> schedule;
  double now = 0.0;
  Eigen::Quaterniond current = attitude_of(
      o.profile == ThermalProfile::kWarmUp || o.profile == ThermalProfile::kCoolDown ? -1 : 0);
  auto hold = [&](double seconds) {
    schedule.push_back({now, seconds, current, current});
    now += seconds;
  };
  auto turn_to = [&](int pose) {
    const Eigen::Quaterniond next = attitude_of(pose);
    schedule.push_back({now, o.rotation_seconds, current, next});
    now += o.rotation_seconds;
    current = next;
  };
  // The pose orders (shuffle_poses) come from a generator of their own, so
  // the truth and the noise of a seed do not depend on the option.
  std::mt19937_64 order_rng(seed ^ 0x9e3779b97f4a7c15ULL);
  int at = 0;  // the pose the unit is in
  auto all_poses = [&]() {
    if (!o.shuffle_poses) {
      for (int p = 0; p < o.poses; ++p) {
        if (p > 0) turn_to(p);
        hold(o.hold_seconds);
      }
      turn_to(0);
      return;
    }
    std::vector<int> order(o.poses);
    for (int p = 0; p < o.poses; ++p) order[p] = p;
    std::shuffle(order.begin(), order.end(), order_rng);
    for (int p : order) {
      if (p != at) turn_to(p);
      at = p;
      hold(o.hold_seconds);
    }
  };
  std::vector<double> soak_begin;  // kSoakSteps: when each soak's poses begin
  switch (o.profile) {
    case ThermalProfile::kSoakSteps:
      for (size_t s = 0; s < o.soak_temperatures.size(); ++s) {
        hold(s == 0 ? o.hold_seconds : o.transition_seconds);
        soak_begin.push_back(now);
        all_poses();
      }
      hold(o.hold_seconds);
      break;
    case ThermalProfile::kWarmUp:
    case ThermalProfile::kCoolDown:
      hold(o.ramp_seconds);
      break;
    case ThermalProfile::kWarmUpPoses:
    case ThermalProfile::kWarmCoolPoses: {
      const double total =
          o.profile == ThermalProfile::kWarmUpPoses ? o.ramp_seconds : 2.0 * o.ramp_seconds;
      while (now < total) all_poses();
      break;
    }
  }
  const double ramp_span = o.end_temperature - o.start_temperature;
  auto recorded_temperature = [&](double t) {
    switch (o.profile) {
      case ThermalProfile::kSoakSteps: {
        // Linear from soak s-1 to soak s over the transition before it.
        size_t s = 0;
        while (s + 1 < soak_begin.size() && t >= soak_begin[s + 1] - o.transition_seconds) ++s;
        const double target = o.soak_temperatures[s];
        if (s == 0 || t >= soak_begin[s]) return target;
        const double from = o.soak_temperatures[s - 1];
        const double f = (t - (soak_begin[s] - o.transition_seconds)) / o.transition_seconds;
        return from + (target - from) * f;
      }
      case ThermalProfile::kWarmUp:
      case ThermalProfile::kWarmUpPoses:
        return o.end_temperature - ramp_span * std::exp(-t / o.ramp_time_constant);
      case ThermalProfile::kCoolDown:
        return o.start_temperature + ramp_span * std::exp(-t / o.ramp_time_constant);
      case ThermalProfile::kWarmCoolPoses: {
        if (t < o.ramp_seconds) {
          return o.end_temperature - ramp_span * std::exp(-t / o.ramp_time_constant);
        }
        const double top =
            o.end_temperature - ramp_span * std::exp(-o.ramp_seconds / o.ramp_time_constant);
        return o.start_temperature +
               (top - o.start_temperature) * std::exp(-(t - o.ramp_seconds) / o.ramp_time_constant);
      }
    }
    return o.reference_temperature;
  };

  const double dt = 1.0 / o.sample_rate;
  const size_t n = static_cast<size_t>(std::floor(now * o.sample_rate));
  const double accel_noise = o.accel_noise_density * std::sqrt(o.sample_rate);
  const double gyro_noise = o.gyro_noise_density * std::sqrt(o.sample_rate);
  const Eigen::Matrix3d u_inverse = out.accel.upper.inverse();
  const Eigen::Matrix3d m_inverse = out.gyro.matrix.inverse();
  const ThermalBlocks<double> accel_blocks = truth.Blocks(ThermalSensor::kAccel);
  const ThermalBlocks<double> gyro_blocks = truth.Blocks(ThermalSensor::kGyro);
  ImuLog& log = out.log;
  log.source = std::string("thermal simulation (") + ToString(o.profile) + ")";
  log.t.reserve(n);
  log.accel.reserve(n);
  log.gyro.reserve(n);
  log.temperature.reserve(n);
  out.element_temperature.reserve(n);
  size_t segment = 0;
  double element = recorded_temperature(0.0);
  for (size_t i = 0; i < n; ++i) {
    const double t = i * dt;
    while (segment + 1 < schedule.size() && t >= schedule[segment + 1].t0) ++segment;
    const Segment& s = schedule[segment];
    // Attitude and body rate: a constant-rate turn about a body axis.
    const Eigen::AngleAxisd relative(s.a.inverse() * s.b);
    const double f = std::min(1.0, (t - s.t0) / s.duration);
    const Eigen::Quaterniond c =
        s.a * Eigen::Quaterniond(Eigen::AngleAxisd(relative.angle() * f, relative.axis()));
    const Eigen::Vector3d rate =
        s.a.isApprox(s.b) ? Eigen::Vector3d::Zero()
                          : Eigen::Vector3d(relative.axis() * relative.angle() / s.duration);
    const Eigen::Vector3d force = c.inverse() * Eigen::Vector3d(0.0, 0.0, o.gravity);
    // The element lags the recorded temperature (exact for a constant
    // input over the step).
    const double recorded = recorded_temperature(t);
    if (o.lag_time_constant > 0.0 && i > 0) {
      element = recorded + (element - recorded) * std::exp(-dt / o.lag_time_constant);
    } else {
      element = recorded;
    }
    const double x = element - truth.reference_temperature;
    double db[3];
    Eigen::Vector3d scaled = force;
    accel_blocks.ApplyScale(x, scaled.data());
    accel_blocks.BiasChange(x, db);
    Eigen::Vector3d v = out.accel.bias + Eigen::Vector3d(db[0], db[1], db[2]) + u_inverse * scaled;
    Eigen::Vector3d w_scaled = rate;
    gyro_blocks.ApplyScale(x, w_scaled.data());
    gyro_blocks.BiasChange(x, db);
    Eigen::Vector3d u = out.gyro.bias + Eigen::Vector3d(db[0], db[1], db[2]) + m_inverse * w_scaled;
    for (int k = 0; k < 3; ++k) {
      v(k) += accel_noise * accel_units * normal(rng);
      u(k) += gyro_noise * gyro_units * normal(rng);
    }
    log.t.push_back(t);
    log.accel.push_back(v);
    log.gyro.push_back(u);
    log.temperature.push_back(recorded + o.temperature_noise * normal(rng));
    out.element_temperature.push_back(element);
  }
  const auto [lo, hi] = std::minmax_element(log.temperature.begin(), log.temperature.end());
  truth.min_temperature = *lo;
  truth.max_temperature = *hi;
  *session = std::move(out);
  return true;
}

}  // namespace gravcal
