// Issue 21: the discovery workflow on the seed's twelve positions, where
// the magnitudes alone leave the nine-parameter baseline three residuals
// and so cannot test any three-parameter accelerometer effect. Each pose
// is held 30 s during a warm-up, with a gyroscope: the within-pose trends
// and the rotations between poses must carry the decisions.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "effect_session.h"
#include "gravcal/workflows/discovery.h"
#include "test_util.h"

namespace gravcal {
namespace {

// Typical consumer-MEMS sizes (effect_session.h) and a non-orthogonality
// of 1.5 mrad per angle, each the standard deviation of a per-axis draw.
using testing_util::kBiasDrift;
using testing_util::kQuadratic;
using testing_util::kTemperatureBias;
using testing_util::kTemperatureScale;
constexpr double kMisalignment = 1.5e-3;

constexpr int kTwelvePoseSeeds = 20;

struct Hidden {
  Effect effect;
  double std;
  // Seeds of kTwelvePoseSeeds in which it must be named first.
  int required;
};

// The twelve-pose session with `hidden` (none when std is 0), discovered
// from its log with the parameterization's baseline.
DiscoveryResult DiscoverTwelve(const Hidden& hidden, uint64_t seed) {
  SimulatorOptions sim = testing_util::TwelvePoseWarmUp();
  AccelParameterization p = AccelParameterization::kScaleMisalignment;
  if (hidden.effect == Effect::kAccelMisalignment && hidden.std > 0.0) {
    sim.accel_misalignment_std = hidden.std;
    p = AccelParameterization::kScale;
  } else if (hidden.std > 0.0) {
    sim = testing_util::WithHidden(sim, hidden.effect, hidden.std);
  }
  SimulatedSession session;
  std::string error;
  EXPECT_TRUE(Simulate(sim, seed, &session, &error)) << error;
  CalibrationOptions calibration;
  calibration.gravity.gravity = session.gravity;
  calibration.refinement.parameterization = p;
  DiscoveryResult r;
  EXPECT_TRUE(DiscoverEffects(session.log, calibration, {}, DiscoveryOptions(), &r)) << r.message;
  return r;
}

class DiscoveryTwelvePoses : public ::testing::TestWithParam<Hidden> {};

TEST_P(DiscoveryTwelvePoses, NamesTheHiddenAccelerometerEffectFirst) {
  const Hidden hidden = GetParam();
  int first = 0, wrong_preferred = 0;
  for (int seed = 1; seed <= kTwelvePoseSeeds; ++seed) {
    const DiscoveryResult r = DiscoverTwelve(hidden, seed);
    const bool ok = !r.steps.empty() && r.steps.front().effect == hidden.effect;
    first += ok ? 1 : 0;
    // Another effect named first because the trends and rotations preferred
    // it (not confirmed by them on their own).
    wrong_preferred +=
        !ok && !r.steps.empty() && r.steps.front().confirmed_by.find("prefer") != std::string::npos
            ? 1
            : 0;
    std::printf("seed %d: %s%s%s\n", seed, r.verdict.c_str(), r.steps.empty() ? "" : " | from the ",
                r.steps.empty() ? ""
                                : (r.steps.front().information +
                                   (r.steps.front().confirmed_by.empty()
                                        ? ""
                                        : "; confirmed by the " + r.steps.front().confirmed_by))
                                      .c_str());
    if (!ok && !r.final_candidates.empty()) {
      for (const CandidateScore& c : r.final_candidates) {
        if (c.effect == hidden.effect) std::printf("  %s\n", c.reason.c_str());
      }
    }
  }
  EXPECT_GE(first, hidden.required) << first << " of " << kTwelvePoseSeeds;
  // The preference test's margin bounds a wrong preference over the true
  // effect at the sensor's level, 0.01 / 4 per rival (three rivals).
  EXPECT_LE(wrong_preferred, testing_util::AllowedSuccesses(kTwelvePoseSeeds, 3 * 0.01 / 4))
      << wrong_preferred << " of " << kTwelvePoseSeeds;
}

// Each named first in at least 18 of 20 seeds, the bias tempco in 17: since
// the catalogue gained accel_temperature_bias_quadratic (issue 34's added
// effect), the significance is split over one more accelerometer candidate
// that also follows the temperature; on the same sessions seeds 9 and 15 now
// find no significant effect, 17 of 20 named first (at least 18 before).
// The scale tempco leans on
// the preference test: with the magnitudes at 0 residual dof its trend and
// rotation rows alone confirm it in only about 8 of 20 seeds (noncentrality
// 10.9 on average over these seeds, against 32.8 for the bias tempco and
// 38.3 for the drift), but they single it out among the candidates its
// size in most of the rest (discovery.h, preference_margin).
INSTANTIATE_TEST_SUITE_P(
    Effects, DiscoveryTwelvePoses,
    ::testing::Values(Hidden{Effect::kAccelQuadratic, kQuadratic, 18},
                      Hidden{Effect::kAccelTemperatureBias, kTemperatureBias, 17},
                      Hidden{Effect::kAccelTemperatureScale, kTemperatureScale, 18},
                      Hidden{Effect::kAccelBiasDrift, kBiasDrift, 18},
                      Hidden{Effect::kAccelMisalignment, kMisalignment, 18}),
    [](const ::testing::TestParamInfo<Hidden>& info) {
      return std::string(ToString(info.param.effect));
    });

TEST(DiscoveryTwelvePosesQuiet, NamesNothingWithoutHiddenEffect) {
  int quiet = 0;
  for (int seed = 1; seed <= kTwelvePoseSeeds; ++seed) {
    const DiscoveryResult r = DiscoverTwelve({Effect::kAccelQuadratic, 0.0, 0}, seed);
    quiet += r.named().empty() ? 1 : 0;
    if (!r.named().empty()) std::printf("seed %d: %s\n", seed, r.verdict.c_str());
  }
  EXPECT_GE(quiet, 19) << quiet << " of " << kTwelvePoseSeeds;
}

// Each sensor's evidence stands on its own, on twelve poses too: the
// accelerometer hides a non-orthogonality (scale baseline) while every
// pose's gyroscope mean sits 30 sigma off any static model. The gyroscope is
// reported unexplained and the accelerometer effect is still named (the
// same check on 14 random poses: discovery_test.cc,
// GyroscopeExcessDoesNotMaskAccelerometerEffect).
TEST(DiscoveryTwelvePosesGyroExcess, AccelerometerEffectIsStillNamed) {
  SimulatorOptions sim = testing_util::TwelvePoseWarmUp();
  sim.accel_misalignment_std = kMisalignment;
  CalibrationOptions calibration;
  calibration.refinement.parameterization = AccelParameterization::kScale;
  const int seeds = 10;
  int named = 0, gyro_unexplained = 0;
  for (int seed = 1; seed <= seeds; ++seed) {
    SimulatedSession session;
    std::string error;
    ASSERT_TRUE(Simulate(sim, seed, &session, &error)) << error;
    testing_util::AddPoseOffsetsToGyro(30.0, seed, &session, sim);
    calibration.gravity.gravity = session.gravity;
    DiscoveryResult r;
    ASSERT_TRUE(DiscoverEffects(session.log, calibration, {}, DiscoveryOptions(), &r)) << r.message;
    named += !r.steps.empty() && r.steps.front().effect == Effect::kAccelMisalignment ? 1 : 0;
    ASSERT_EQ(r.sensors.size(), 2u);
    gyro_unexplained += r.sensors[1].unexplained ? 1 : 0;
    std::printf("seed %d: %s | accelerometer from the %s\n", seed, r.verdict.c_str(),
                r.sensors[0].information.c_str());
  }
  EXPECT_GE(named, 9) << named << " of " << seeds;
  EXPECT_GE(gyro_unexplained, 9) << gyro_unexplained << " of " << seeds;
}

}  // namespace
}  // namespace gravcal
