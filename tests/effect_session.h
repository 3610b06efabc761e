// Shared by the effect tests (effect_trends_test.cc,
// effect_rotations_test.cc): the simulated twelve-position session with a
// warm-up and the nominal model and references a fit starts from.
#ifndef GRAVCAL_TESTS_EFFECT_SESSION_H_
#define GRAVCAL_TESTS_EFFECT_SESSION_H_

#include <cmath>
#include <random>
#include <vector>

#include "gravcal/detection/static_detector.h"
#include "gravcal/methods/effect_fit.h"
#include "gravcal/simulation/simulator.h"
#include "test_util.h"

namespace gravcal {
namespace testing_util {

// Typical consumer-MEMS sizes of the accelerometer effects, each the
// standard deviation of a per-axis draw: k2 1.5e-4 per m/s^2 (about
// 1500 ug/g^2), bias tempco 0.2 mg/K, scale tempco 0.01 %/K, bias drift
// 8e-5 m/s^2/s (0.5 mg per minute during warm-up).
constexpr double kQuadratic = 1.5e-4;
constexpr double kTemperatureBias = 0.002;
constexpr double kTemperatureScale = 1e-4;
constexpr double kBiasDrift = 8e-5;

// The family-wise level of discovery (discovery_significance 0.01) divided
// over the candidates of the catalogue.
constexpr double kCandidateLevel = 0.01 / kNumEffects;

// The seed's twelve poses held 30 s during a warm-up 20 -> 35 degC (time
// constant 200 s, so the poses see different temperature rates), with the
// hand_placed.yaml correlated accelerometer noise on top of the default
// white noise (0.02 m/s^2 per sample at 100 Hz).
inline SimulatorOptions TwelvePoseWarmUp() {
  SimulatorOptions o = WarmUpSession();
  o.scheme = {PoseScheme::kTwelve};
  o.hold_seconds = 30.0;
  o.initial_still_seconds = 10.0;
  o.rotation_seconds = 3.0;
  o.temperature_tau = 200.0;
  o.accel_bias_random_walk = 2e-5;
  o.accel_bias_instability = 2e-4;
  return o;
}

// The simulated hidden effect `e` drawn per axis with standard deviation
// `std` (others unchanged).
inline SimulatorOptions WithHidden(SimulatorOptions o, Effect e, double std) {
  o.effect_std[e] = std;
  return o;
}

// Every pose's gyroscope samples offset by `sigmas` times the standard
// deviation of the pose's mean, per axis, one draw per pose (rounded to
// counts): an excess of the static means that no catalogue effect
// explains, as an AHRS's own processing of its gyroscope output gives.
inline void AddPoseOffsetsToGyro(double sigmas, uint64_t seed, SimulatedSession* session,
                                 const SimulatorOptions& sim) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> z(0.0, 1.0);
  const double per_sample = sim.gyro_noise * session->gyro_units_per_si;
  for (const SimulatedPose& p : session->poses) {
    const double sigma_of_mean = per_sample / std::sqrt(static_cast<double>(p.end - p.begin));
    const Eigen::Vector3d offset(z(rng), z(rng), z(rng));
    for (size_t i = p.begin; i < p.end; ++i) {
      session->log.gyro[i] += (sigmas * sigma_of_mean * offset).array().round().matrix();
    }
  }
}

// The simulator's own still periods (so that detection is not under test).
inline std::vector<StaticInterval> SessionIntervals(const SimulatedSession& session) {
  std::vector<StaticInterval> intervals;
  for (const SimulatedPose& p : session.poses) {
    intervals.push_back(MakeInterval(session.log, p.begin, p.end));
  }
  return intervals;
}

// References as calibrate sets them: mean time and temperature of the poses.
inline EffectParameters References(const std::vector<StaticObservation>& observations) {
  EffectParameters p;
  for (const StaticObservation& o : observations) {
    p.reference_time += o.time() / observations.size();
    p.reference_temperature += o.temperature() / observations.size();
  }
  return p;
}

// The nominal model of the simulated sensor: no bias, U = I / units.
inline AccelModel Nominal(const SimulatedSession& session) {
  AccelModel m;
  m.bias.setZero();
  m.upper = Eigen::Matrix3d::Identity() / session.accel_units_per_si;
  return m;
}

// The accelerometer effects' block (core/effect_registry.h) with every term
// switched on, for the residuals' Jacobian checks.
inline std::vector<double> EveryAccelEffectOn() {
  EffectParameters p;
  p.Vector(Effect::kAccelQuadratic) << 1e-4, -2e-4, 5e-5;
  p.Vector(Effect::kAccelTemperatureBias) << 0.002, -0.001, 0.003;
  p.Vector(Effect::kAccelTemperatureScale) << 1e-4, -2e-4, 3e-4;
  p.Vector(Effect::kAccelBiasDrift) << 8e-5, -5e-5, 2e-5;
  p.Vector(Effect::kAccelTemperatureBiasQuadratic) << 2e-4, -1e-4, 3e-4;
  return std::vector<double>(p.accel.begin(), p.accel.end());
}

}  // namespace testing_util
}  // namespace gravcal

#endif  // GRAVCAL_TESTS_EFFECT_SESSION_H_
