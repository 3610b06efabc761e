// The plate simulator (plate_simulator.h): one noise-free session of the
// plate at a high rate, then each IMU's clock, mounting and sensor.
#include "gravcal/simulation/plate_simulator.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <exception>
#include <random>
#include <sstream>

#include "simulation/smooth_step.h"
#include "util/random_vector.h"
#include "util/so3.h"
#include "util/units.h"

namespace gravcal {
namespace {

using internal::AxisAngle;
using internal::FromRotationVector;

using internal::SmoothStep;
using internal::SmoothStepRate;

// Catmull-Rom interpolation of a uniformly sampled signal (step h, first
// sample at 0) at time t, clamped to the ends.
Eigen::Vector3d Interpolate(const std::vector<Eigen::Vector3d>& v, double h, double t) {
  const double x = std::clamp(t / h, 0.0, static_cast<double>(v.size() - 1));
  const long j = std::min(static_cast<long>(x), static_cast<long>(v.size()) - 2);
  const double s = x - static_cast<double>(j);
  auto at = [&](long k) { return v[std::clamp(k, 0L, static_cast<long>(v.size()) - 1)]; };
  const Eigen::Vector3d p0 = at(j - 1), p1 = at(j), p2 = at(j + 1), p3 = at(j + 2);
  return 0.5 * ((2.0 * p1) + (-p0 + p2) * s + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * s * s +
                (-p0 + 3.0 * p1 - 3.0 * p2 + p3) * s * s * s);
}

Eigen::Matrix3d RandomRotation(std::mt19937_64* rng) {
  std::normal_distribution<double> n01(0.0, 1.0);
  const double w = n01(*rng);
  const Eigen::Vector3d v = internal::DrawVector3([&] { return n01(*rng); });
  return Eigen::Quaterniond(w, v.x(), v.y(), v.z()).normalized().toRotationMatrix();
}

bool SimulatePlateImpl(const PlateSimulatorOptions& options, uint64_t seed, SimulatedPlate* out,
                       std::string* error) {
  if (!options.IsValid(error)) return false;
  // The plate: a perfect sensor in SI units at the high rate.
  SimulatorOptions perfect = options.imu;
  perfect.sample_rate = options.imu.sample_rate * options.oversample;
  perfect.raw_counts = false;
  perfect.accel_noise = perfect.gyro_noise = 0.0;
  perfect.accel_bias_random_walk = perfect.gyro_bias_random_walk = 0.0;
  perfect.accel_bias_instability = perfect.gyro_bias_instability = 0.0;
  perfect.accel_bias_std = perfect.accel_scale_std = perfect.accel_misalignment_std = 0.0;
  perfect.gyro_bias_std = perfect.gyro_scale_std = perfect.gyro_misalignment_std = 0.0;
  perfect.effect_std = EffectSpreads();
  SimulatedSession plate_session;
  if (!Simulate(perfect, seed, &plate_session, error)) return false;
  const ImuLog& hi = plate_session.log;
  const double h = 1.0 / perfect.sample_rate;
  const size_t samples = hi.size() / static_cast<size_t>(options.oversample);

  SimulatedPlate plate;
  plate.seed = seed;
  plate.gravity = plate_session.gravity;
  for (const SimulatedPose& p : plate_session.poses) {
    SimulatedPose q = p;
    q.begin = (p.begin + options.oversample - 1) / options.oversample;
    q.end = std::min(samples, p.end / options.oversample);
    plate.poses.push_back(q);
  }
  // The slip's turn, in plate time.
  double slip_begin = 0.0, slip_end = 0.0;
  if (options.slip_imu >= 0) {
    slip_begin = static_cast<double>(plate_session.poses[options.slip_turn].end) * h;
    slip_end = static_cast<double>(plate_session.poses[options.slip_turn + 1].begin) * h;
  }

  std::mt19937_64 rng(seed ^ 0x9e3779b97f4a7c15ULL);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (int i = 0; i < options.imus; ++i) {
    PlateImuTruth truth;
    truth.name = "imu" + std::to_string(i);
    // The sensor: the simulator's random truth of its own seed.
    SimulatorOptions small = options.imu;
    small.scheme = {PoseScheme::kSix};
    small.planned_poses.clear();
    small.hold_seconds = small.initial_still_seconds = 1.0;
    small.rotation_seconds = 1.0;
    SimulatedSession sensor;
    if (!Simulate(small, seed * 1000003ULL + 7919ULL * (i + 1), &sensor, error)) return false;
    truth.accel = sensor.accel_truth;
    truth.gyro = sensor.gyro_truth;
    truth.accel_units_per_si = sensor.accel_units_per_si;
    truth.gyro_units_per_si = sensor.gyro_units_per_si;
    // The mounting.
    const Eigen::Vector3d error_vector = internal::DrawVector3([&] { return n01(rng); }) *
                                         options.mounting_error_deg * internal::kDegToRad;
    const Eigen::Matrix3d stated = options.mounting == PlateMounting::kRandom && i > 0
                                       ? RandomRotation(&rng)
                                       : Eigen::Matrix3d::Identity();
    truth.stated_mounting = stated;
    truth.mounting_start = stated * (i > 0 ? FromRotationVector(error_vector).toRotationMatrix()
                                           : Eigen::Matrix3d::Identity());
    if (i == options.permuted_imu) {
      truth.mounting_start =
          truth.mounting_start * AxisAngle(options.permuted_angle_deg * internal::kDegToRad,
                                           Eigen::Vector3d::Unit(options.permuted_axis))
                                     .toRotationMatrix();
    }
    Eigen::Vector3d slip = Eigen::Vector3d::Zero();
    if (i == options.slip_imu) {
      const Eigen::Vector3d axis = internal::DrawVector3([&] { return n01(rng); }).normalized();
      slip = axis * options.slip_deg * internal::kDegToRad;
    }
    truth.mounting_end = truth.mounting_start * FromRotationVector(slip).toRotationMatrix();
    // The clock.
    if (i > 0) {
      truth.clock_offset = options.max_clock_offset * u01(rng);
      truth.clock_drift = options.clock_drift_std * n01(rng);
    }
    // The samples.
    const Eigen::Matrix3d accel_inverse = truth.accel.matrix().inverse();
    const Eigen::Matrix3d gyro_inverse = truth.gyro.matrix.inverse();
    std::mt19937_64 noise(seed * 6364136223846793005ULL + 1442695040888963407ULL * (i + 1));
    ImuLog log;
    log.source = "simulated plate seed " + std::to_string(seed) + " " + truth.name;
    log.t.resize(samples);
    log.accel.resize(samples);
    log.gyro.resize(samples);
    for (size_t k = 0; k < samples; ++k) {
      const double t = static_cast<double>(k) / options.imu.sample_rate;
      const double tp = t - (truth.clock_offset + truth.clock_drift * t);
      Eigen::Matrix3d q = truth.mounting_start;
      Eigen::Vector3d slip_rate = Eigen::Vector3d::Zero();
      if (i == options.slip_imu && tp > slip_begin) {
        const double x = std::min(1.0, (tp - slip_begin) / (slip_end - slip_begin));
        q = truth.mounting_start * FromRotationVector(slip * SmoothStep(x)).toRotationMatrix();
        if (x < 1.0) slip_rate = slip * SmoothStepRate(x) / (slip_end - slip_begin);
      }
      const Eigen::Vector3d f = q.transpose() * Interpolate(hi.accel, h, tp);
      const Eigen::Vector3d w = q.transpose() * Interpolate(hi.gyro, h, tp) + slip_rate;
      const Eigen::Vector3d na =
          internal::DrawVector3([&] { return n01(noise); }) * options.imu.accel_noise;
      const Eigen::Vector3d ng =
          internal::DrawVector3([&] { return n01(noise); }) * options.imu.gyro_noise;
      Eigen::Vector3d v = accel_inverse * (f + na) + truth.accel.bias;
      Eigen::Vector3d u = gyro_inverse * (w + ng) + truth.gyro.bias;
      if (i == options.flipped_imu) {
        v[options.flipped_axis] = -v[options.flipped_axis];
        u[options.flipped_axis] = -u[options.flipped_axis];
      }
      if (options.imu.raw_counts) {
        v = v.array().round();
        u = u.array().round();
      }
      log.t[k] = t;
      log.accel[k] = v;
      log.gyro[k] = u;
    }
    plate.logs.push_back(std::move(log));
    plate.truth.push_back(truth);
  }
  *out = std::move(plate);
  return true;
}

void AppendMatrix(std::ostringstream* s, const Eigen::Matrix3d& m) {
  *s << "[";
  for (int r = 0; r < 3; ++r) {
    *s << (r ? ", [" : "[");
    for (int c = 0; c < 3; ++c) *s << (c ? ", " : "") << m(r, c);
    *s << "]";
  }
  *s << "]";
}

void AppendVector(std::ostringstream* s, const Eigen::Vector3d& v) {
  *s << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
}

}  // namespace

bool PlateSimulatorOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& what) {
    if (error) *error = "plate simulator: " + what;
    return false;
  };
  if (imus < 1 || imus > 64) return fail("imus must be 1..64");
  if (!(mounting_error_deg >= 0.0) || !(max_clock_offset >= 0.0) || !(clock_drift_std >= 0.0))
    return fail("mounting_error_deg, max_clock_offset and clock_drift_std must be >= 0");
  if (permuted_imu >= imus || slip_imu >= imus || flipped_imu >= imus)
    return fail("permuted_imu and slip_imu must name an IMU (or be -1)");
  if (permuted_axis < 0 || permuted_axis > 2 || flipped_axis < 0 || flipped_axis > 2)
    return fail("permuted_axis and flipped_axis must be 0, 1 or 2");
  if (oversample < 1 || oversample > 64) return fail("oversample must be 1..64");
  if (slip_imu >= 0 && (slip_turn < 0 || !std::isfinite(slip_deg)))
    return fail("slip_turn must be >= 0 and slip_deg finite");
  return imu.IsValid(error);
}

bool SimulatePlate(const PlateSimulatorOptions& options, uint64_t seed, SimulatedPlate* plate,
                   std::string* error) {
  if (plate == nullptr) {
    if (error) *error = "SimulatePlate: null plate";
    return false;
  }
  try {
    if (options.slip_imu >= 0) {
      // The turn must exist: checked after the plate's poses are known.
      SimulatedPlate trial;
      PlateSimulatorOptions o = options;
      o.slip_imu = -1;
      o.imus = 1;
      o.oversample = 1;
      if (!SimulatePlateImpl(o, seed, &trial, error)) return false;
      if (options.slip_turn + 1 >= static_cast<int>(trial.poses.size())) {
        if (error) *error = "plate simulator: slip_turn is past the session's last turn";
        return false;
      }
    }
    return SimulatePlateImpl(options, seed, plate, error);
  } catch (const std::exception& e) {
    if (error) *error = std::string("plate simulation failed: ") + e.what();
    return false;
  }
}

std::string PlateToCsv(const SimulatedPlate& plate) {
  std::ostringstream s;
  s.precision(17);
  s << "t";
  for (const PlateImuTruth& truth : plate.truth) {
    for (const char* c : {"ax", "ay", "az", "gx", "gy", "gz"}) s << "," << truth.name << "." << c;
  }
  s << "\n";
  const size_t n = plate.logs.empty() ? 0 : plate.logs[0].size();
  for (size_t k = 0; k < n; ++k) {
    s << plate.logs[0].t[k];
    for (const ImuLog& log : plate.logs) {
      for (int j = 0; j < 3; ++j) s << "," << log.accel[k](j);
      for (int j = 0; j < 3; ++j) s << "," << log.gyro[k](j);
    }
    s << "\n";
  }
  return s.str();
}

std::string PlateTruthToJson(const SimulatedPlate& plate) {
  std::ostringstream s;
  s.precision(17);
  s << "{\n  \"seed\": " << plate.seed << ",\n  \"gravity\": " << plate.gravity
    << ",\n  \"imus\": [";
  for (size_t i = 0; i < plate.truth.size(); ++i) {
    const PlateImuTruth& t = plate.truth[i];
    s << (i ? ",\n" : "\n") << "    {\"name\": \"" << t.name << "\", \"accel_bias\": ";
    AppendVector(&s, t.accel.bias);
    s << ", \"accel_matrix\": ";
    AppendMatrix(&s, t.accel.matrix());
    s << ", \"gyro_bias\": ";
    AppendVector(&s, t.gyro.bias);
    s << ", \"gyro_matrix\": ";
    AppendMatrix(&s, t.gyro.matrix);
    s << ", \"stated_mounting\": ";
    AppendMatrix(&s, t.stated_mounting);
    s << ", \"mounting_start\": ";
    AppendMatrix(&s, t.mounting_start);
    s << ", \"mounting_end\": ";
    AppendMatrix(&s, t.mounting_end);
    s << ", \"rotation_to_reference\": ";
    AppendMatrix(&s, PlateTruthRotation(plate, static_cast<int>(i)));
    s << ", \"clock_offset\": " << t.clock_offset << ", \"clock_drift\": " << t.clock_drift << "}";
  }
  s << "\n  ],\n  \"poses\": [";
  for (size_t k = 0; k < plate.poses.size(); ++k) {
    s << (k ? ", " : "") << "[" << plate.poses[k].begin << ", " << plate.poses[k].end << "]";
  }
  s << "]\n}\n";
  return s.str();
}

Eigen::Matrix3d PlateTruthRotation(const SimulatedPlate& plate, int imu) {
  const PlateImuTruth& ref = plate.truth[0];
  const PlateImuTruth& t = plate.truth[imu];
  return (ref.mounting_start * ref.accel.rotation).transpose() * t.mounting_start *
         t.accel.rotation;
}

Eigen::Matrix3d PlateTruthGyroMatrix(const SimulatedPlate& plate, int imu) {
  const PlateImuTruth& t = plate.truth[imu];
  return t.accel.rotation.transpose() * t.gyro.matrix;
}

}  // namespace gravcal
