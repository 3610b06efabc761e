// The model discrepancy workflow on simulated sessions in which an effect is
// hidden (the workflow is not told which), and on the real recordings.
#include "gravcal/discovery.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <functional>

#include "gravcal/config.h"
#include "gravcal/log_reader.h"
#include "gravcal/simulator.h"
#include "test_util.h"

namespace gravcal {
namespace {

// Magnitudes a real MEMS sensor shows (simulator.h documents the ranges):
// k2 5e-5 per m/s^2 (about 500 ug/g^2), accelerometer bias tempco 0.2 mg/K,
// scale tempco 0.01 %/K, bias drift 2e-5 m/s^2/s (0.1 mg per minute),
// gyroscope g-sensitivity 0.05 deg/s/g, gyroscope bias tempco 0.01 deg/s/K.
constexpr double kQuadratic = 1e-4;
constexpr double kTemperatureBias = 0.002;
constexpr double kTemperatureScale = 1e-4;
constexpr double kBiasDrift = 5e-5;
constexpr double kGSensitivity = 9e-5;
constexpr double kGyroTemperatureBias = 1.7e-4;
constexpr double kGyroDrift = 1e-5;

// 24 random poses held 10 s during a warm-up from 20 to 35 degC (time
// constant 120 s): temperature and time both vary and are not proportional.
SimulatorOptions Session() {
  SimulatorOptions o;
  o.scheme = "random:24";
  o.hold_seconds = 10.0;
  o.initial_still_seconds = 5.0;
  o.rotation_seconds = 2.0;
  o.temperature_start = 20.0;
  o.temperature_end = 35.0;
  o.temperature_tau = 120.0;
  return o;
}

struct Outcome {
  DiscoveryResult result;
  bool ok = false;
};

Outcome Discover(const SimulatorOptions& sim, uint64_t seed,
                 AccelParameterization p = AccelParameterization::kScaleMisalignment) {
  Outcome run;
  SimulatedSession session;
  std::string error;
  EXPECT_TRUE(Simulate(sim, seed, &session, &error)) << error;
  CalibrationOptions calibration;
  calibration.gravity.gravity = session.gravity;
  calibration.refinement.parameterization = p;
  DiscoveryOptions options;
  run.ok = DiscoverEffects(session.log, calibration, {}, options, &run.result);
  EXPECT_TRUE(run.ok) << run.result.message;
  return run;
}

struct Tally {
  int seeds = 0;
  int named_first = 0;
  int cv_halved = 0;
  int named_nothing = 0;
};

// Runs `seeds` sessions and counts how often `expected` is named first and
// its step halves the cross-validated gap of its sensor.
Tally RunSeeds(const SimulatorOptions& sim, int seeds, Effect expected,
               AccelParameterization p = AccelParameterization::kScaleMisalignment) {
  Tally t;
  for (int seed = 1; seed <= seeds; ++seed) {
    const Outcome run = Discover(sim, seed, p);
    ++t.seeds;
    const std::vector<Effect> named = run.result.named();
    if (named.empty()) {
      ++t.named_nothing;
      continue;
    }
    std::string line;
    for (Effect e : named) line += std::string(ToString(e)) + " ";
    if (named.front() != expected) {
      std::printf("seed %d: named %s\n", seed, line.c_str());
      continue;
    }
    ++t.named_first;
    const DiscoveryStep& s = run.result.steps.front();
    const bool accel = Info(expected).sensor == EffectSensor::kAccelerometer;
    const double before = accel ? s.cv_gap_before.accel : s.cv_gap_before.gyro;
    const double after = accel ? s.cv_gap_after.accel : s.cv_gap_after.gyro;
    if (after <= 0.5 * before) ++t.cv_halved;
    std::printf("seed %d: %s cv %.3g -> %.3g, p %.2g dBIC %.1f\n", seed, line.c_str(), before,
                after, s.p_value, s.delta_bic);
  }
  return t;
}

void ExpectFound(const Tally& t) {
  EXPECT_GE(t.named_first, 0.9 * t.seeds) << t.named_first << " of " << t.seeds;
  EXPECT_GE(t.cv_halved, 0.9 * t.seeds) << t.cv_halved << " of " << t.seeds;
}

constexpr int kSeeds = 20;

TEST(Discovery, FindsAccelQuadraticNonlinearity) {
  SimulatorOptions sim = Session();
  sim.accel_quadratic_std = kQuadratic;
  ExpectFound(RunSeeds(sim, kSeeds, Effect::kAccelQuadratic));
}

TEST(Discovery, FindsAccelTemperatureBias) {
  SimulatorOptions sim = Session();
  sim.accel_temperature_bias_std = kTemperatureBias;
  ExpectFound(RunSeeds(sim, kSeeds, Effect::kAccelTemperatureBias));
}

TEST(Discovery, FindsAccelTemperatureScale) {
  SimulatorOptions sim = Session();
  sim.accel_temperature_scale_std = kTemperatureScale;
  ExpectFound(RunSeeds(sim, kSeeds, Effect::kAccelTemperatureScale));
}

TEST(Discovery, FindsAccelBiasDrift) {
  SimulatorOptions sim = Session();
  sim.accel_bias_drift_std = kBiasDrift;
  ExpectFound(RunSeeds(sim, kSeeds, Effect::kAccelBiasDrift));
}

TEST(Discovery, FindsAccelMisalignmentMissingFromScaleBaseline) {
  SimulatorOptions sim = Session();
  ExpectFound(RunSeeds(sim, kSeeds, Effect::kAccelMisalignment, AccelParameterization::kScale));
}

TEST(Discovery, FindsGyroGSensitivity) {
  SimulatorOptions sim = Session();
  sim.gyro_g_sensitivity_std = kGSensitivity;
  ExpectFound(RunSeeds(sim, kSeeds, Effect::kGyroGSensitivity));
}

TEST(Discovery, FindsGyroTemperatureBias) {
  SimulatorOptions sim = Session();
  sim.gyro_temperature_bias_std = kGyroTemperatureBias;
  ExpectFound(RunSeeds(sim, kSeeds, Effect::kGyroTemperatureBias));
}

TEST(Discovery, FindsGyroBiasDrift) {
  SimulatorOptions sim = Session();
  sim.gyro_bias_drift_std = kGyroDrift;
  ExpectFound(RunSeeds(sim, kSeeds, Effect::kGyroBiasDrift));
}

TEST(Discovery, NamesNothingWithoutHiddenEffect) {
  SimulatorOptions sim = Session();
  Tally t;
  for (int seed = 1; seed <= kSeeds; ++seed) {
    const Outcome run = Discover(sim, seed);
    ++t.seeds;
    if (run.result.named().empty()) {
      ++t.named_nothing;
      EXPECT_EQ(run.result.verdict, "no significant missing effect");
    } else {
      std::printf("seed %d: false discovery %s\n", seed, ToString(run.result.named().front()));
    }
  }
  EXPECT_GE(t.named_nothing, 0.9 * t.seeds) << t.named_nothing << " of " << t.seeds;
}

}  // namespace
}  // namespace gravcal
