// The model discrepancy workflow on simulated sessions in which an effect is
// hidden (the workflow is not told which), and on the real recordings.
#include "gravcal/workflows/discovery.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <random>

#include "effect_session.h"
#include "gravcal/io/log_reader.h"
#include "gravcal/simulation/simulator.h"
#include "gravcal/workflows/config.h"
#include "test_util.h"

namespace gravcal {
namespace {

// Magnitudes a real MEMS sensor shows (simulator.h documents the ranges),
// at or below the typical values: the accelerometer's of effect_session.h,
// gyroscope g-sensitivity 0.05 deg/s/g, gyroscope bias tempco
// 0.01 deg/s/K, gyroscope bias drift 0.03 deg/s per minute. Each is the
// standard deviation of a per-axis draw.
using testing_util::kBiasDrift;
using testing_util::kQuadratic;
using testing_util::kTemperatureBias;
using testing_util::kTemperatureScale;
constexpr double kGSensitivity = 9e-5;
constexpr double kGyroTemperatureBias = 1.7e-4;
constexpr double kGyroDrift = 1e-5;

// The session the hidden effects are looked for in: the warm-up of
// test_util.h with 26 random poses. 26, not 24: the richest accelerometer
// model of the catalogue (the baseline's 9 parameters and five 3-parameter
// effects) has 24 parameters, so 26 poses keep the magnitudes the
// min_dof (2) residual degrees of freedom that let them test every
// candidate on their own, and discovery leaves the rotations between poses
// out of these fits (discovery.cc, CheckRotations); with 24 poses every fit
// integrated every turn, 5-15 times the CPU, for decisions the magnitudes
// and trends make. The rotations' decisions are the twelve-pose tests'
// (discovery_twelve_poses_test.cc), where the magnitudes cannot make them.
SimulatorOptions DiscoverySession() {
  SimulatorOptions o = testing_util::WarmUpSession();
  o.scheme.random_poses = 26;
  return o;
}

// The seeds a test runs: 1..count, or GRAVCAL_DISCOVERY_SEEDS="F:N" (seeds
// F..F+N-1; the rates recorded beside the thresholds were measured with
// 1001:200).
void DiscoverySeeds(int count, int* first, int* n) {
  *first = 1;
  *n = count;
  const char* value = std::getenv("GRAVCAL_DISCOVERY_SEEDS");
  if (value == nullptr || std::strchr(value, ':') == nullptr) return;
  *first = std::atoi(value);
  *n = std::max(1, std::atoi(std::strchr(value, ':') + 1));
}

struct Outcome {
  DiscoveryResult result;
  bool ok = false;
};

Outcome Discover(const SimulatorOptions& sim, uint64_t seed,
                 AccelParameterization p = AccelParameterization::kScaleMisalignment,
                 const DiscoveryOptions& options = DiscoveryOptions()) {
  Outcome run;
  SimulatedSession session;
  std::string error;
  EXPECT_TRUE(Simulate(sim, seed, &session, &error)) << error;
  CalibrationOptions calibration;
  calibration.gravity.gravity = session.gravity;
  calibration.refinement.parameterization = p;
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
  int first = 1;
  DiscoverySeeds(seeds, &first, &seeds);
  for (int seed = first; seed < first + seeds; ++seed) {
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

// The counts are held to thresholds from binomial tails
// (testing_util::RequiredSuccesses): an honest workflow fails a test with
// probability below 0.001. The per-seed probabilities are stated per test:
// the one-sided 99.9 % lower confidence bound of the rate measured on seeds
// 1001-1200 (not the test's; GRAVCAL_DISCOVERY_SEEDS=1001:200), recorded
// next to each. Measured 2026-11-28 on DiscoverySession's 26 poses; the
// rates of the 24-pose session before are in brackets where they differ.
void ExpectFound(const Tally& t, double p_named_first, double p_cv_halved) {
  std::printf("named first %d, cv halved %d of %d\n", t.named_first, t.cv_halved, t.seeds);
  EXPECT_GE(t.named_first, testing_util::RequiredSuccesses(t.seeds, p_named_first))
      << t.named_first << " of " << t.seeds;
  EXPECT_GE(t.cv_halved, testing_util::RequiredSuccesses(t.seeds, p_cv_halved))
      << t.cv_halved << " of " << t.seeds;
}

constexpr int kSeeds = 20;

TEST(Discovery, FindsAccelQuadraticNonlinearity) {
  SimulatorOptions sim = DiscoverySession();
  sim.effect_std[Effect::kAccelQuadratic] = kQuadratic;
  ExpectFound(RunSeeds(sim, kSeeds, Effect::kAccelQuadratic),
              /*198 (197) of 200*/ 0.92, /*187 (188) of 200*/ 0.86);
}

TEST(Discovery, FindsAccelTemperatureBias) {
  SimulatorOptions sim = DiscoverySession();
  sim.effect_std[Effect::kAccelTemperatureBias] = kTemperatureBias;
  ExpectFound(RunSeeds(sim, kSeeds, Effect::kAccelTemperatureBias),
              /*200 (199) of 200*/ 0.94, /*200 (198) of 200*/ 0.93);
}

TEST(Discovery, FindsAccelTemperatureScale) {
  SimulatorOptions sim = DiscoverySession();
  sim.effect_std[Effect::kAccelTemperatureScale] = kTemperatureScale;
  ExpectFound(RunSeeds(sim, kSeeds, Effect::kAccelTemperatureScale),
              /*192 (190) of 200*/ 0.87, /*169 (174) of 200*/ 0.75);
}

TEST(Discovery, FindsAccelBiasDrift) {
  SimulatorOptions sim = DiscoverySession();
  sim.effect_std[Effect::kAccelBiasDrift] = kBiasDrift;
  ExpectFound(RunSeeds(sim, kSeeds, Effect::kAccelBiasDrift),
              /*199 (194) of 200*/ 0.90, /*197 (193) of 200*/ 0.89);
}

TEST(Discovery, FindsAccelMisalignmentMissingFromScaleBaseline) {
  SimulatorOptions sim = DiscoverySession();
  ExpectFound(RunSeeds(sim, kSeeds, Effect::kAccelMisalignment, AccelParameterization::kScale),
              /*200 of 200*/ 0.95, /*200 of 200*/ 0.95);
}

TEST(Discovery, FindsGyroGSensitivity) {
  SimulatorOptions sim = DiscoverySession();
  sim.effect_std[Effect::kGyroGSensitivity] = kGSensitivity;
  ExpectFound(RunSeeds(sim, kSeeds, Effect::kGyroGSensitivity),
              /*200 of 200*/ 0.95, /*200 (199) of 200*/ 0.94);
}

TEST(Discovery, FindsGyroTemperatureBias) {
  SimulatorOptions sim = DiscoverySession();
  sim.effect_std[Effect::kGyroTemperatureBias] = kGyroTemperatureBias;
  ExpectFound(RunSeeds(sim, kSeeds, Effect::kGyroTemperatureBias),
              /*200 of 200*/ 0.95, /*200 (199) of 200*/ 0.94);
}

TEST(Discovery, FindsGyroBiasDrift) {
  SimulatorOptions sim = DiscoverySession();
  sim.effect_std[Effect::kGyroBiasDrift] = kGyroDrift;
  ExpectFound(RunSeeds(sim, kSeeds, Effect::kGyroBiasDrift),
              /*200 of 200*/ 0.95, /*199 (198) of 200*/ 0.93);
}

TEST(Discovery, NamesNothingWithoutHiddenEffect) {
  SimulatorOptions sim = DiscoverySession();
  Tally t;
  int first = 1, seeds = kSeeds;
  DiscoverySeeds(kSeeds, &first, &seeds);
  for (int seed = first; seed < first + seeds; ++seed) {
    const Outcome run = Discover(sim, seed);
    ++t.seeds;
    if (run.result.named().empty()) {
      ++t.named_nothing;
      // The verdict may go on to say that a sensor's static means exceed
      // their noise (a test at 1e-3 per sensor: seed 9 of these 20 sessions,
      // none of seeds 1001-1200), but it names nothing.
      if (run.result.verdict != "no significant missing effect")
        std::printf("seed %d: %s\n", seed, run.result.verdict.c_str());
      EXPECT_EQ(run.result.verdict.rfind("no significant missing effect", 0), 0u)
          << "seed " << seed << ": " << run.result.verdict;
    } else {
      std::printf("seed %d: false discovery %s\n", seed, ToString(run.result.named().front()));
    }
  }
  // Each step names an effect only below a family-wise significance of
  // 0.01 (and a BIC gain): a session without a hidden effect names nothing
  // with probability at least 0.99 (measured: 200 of 200 on seeds 1001-1200).
  std::printf("named nothing %d of %d\n", t.named_nothing, t.seeds);
  EXPECT_GE(t.named_nothing, testing_util::RequiredSuccesses(t.seeds, 0.99))
      << t.named_nothing << " of " << t.seeds;
}

// A log with neither gyroscope nor temperature: the effects that need them
// are not tried, with a warning naming why, and the rest still work.
TEST(Discovery, SaysWhatALogWithoutGyroscopeOrTemperatureCannotTest) {
  SimulatorOptions sim = DiscoverySession();
  sim.effect_std[Effect::kAccelQuadratic] = kQuadratic;
  SimulatedSession session;
  std::string error;
  ASSERT_TRUE(Simulate(sim, 1, &session, &error)) << error;
  session.log.gyro.clear();
  session.log.temperature.clear();
  CalibrationOptions calibration;
  calibration.gravity.gravity = session.gravity;
  DiscoveryResult r;
  ASSERT_TRUE(DiscoverEffects(session.log, calibration, {}, DiscoveryOptions(), &r)) << r.message;
  ASSERT_FALSE(r.named().empty());
  EXPECT_EQ(r.named().front(), Effect::kAccelQuadratic);
  std::string warnings;
  for (const std::string& w : r.warnings) warnings += w + "\n";
  EXPECT_NE(warnings.find("gyro_g_sensitivity cannot be tested in this session: the log has no "
                          "gyroscope"),
            std::string::npos)
      << warnings;
  EXPECT_NE(warnings.find("accel_temperature_bias cannot be tested in this session: the log has "
                          "no temperature"),
            std::string::npos)
      << warnings;
  EXPECT_TRUE(std::isnan(r.baseline.gap.gyro));
}

TEST(Discovery, InvalidOptionsAndTooFewPositionsFailWithAMessage) {
  SimulatedSession session;
  std::string error;
  ASSERT_TRUE(Simulate(SimulatorOptions(), 1, &session, &error)) << error;
  CalibrationOptions calibration;
  DiscoveryOptions options;
  options.significance = 1.5;
  DiscoveryResult r;
  EXPECT_FALSE(DiscoverEffects(session.log, calibration, {}, options, &r));
  EXPECT_NE(r.message.find("discovery_significance"), std::string::npos) << r.message;
  SimulatorOptions six;
  six.scheme = {PoseScheme::kSix};
  ASSERT_TRUE(Simulate(six, 1, &session, &error)) << error;
  EXPECT_FALSE(DiscoverEffects(session.log, calibration, {}, DiscoveryOptions(), &r));
  EXPECT_NE(r.message.find("needs at least 9"), std::string::npos) << r.message;
}

// Two effects hidden: an accelerometer bias tempco of 0.6 mg/K and a
// quadratic nonlinearity of 1500 ug/g^2 (typical consumer values). Both are
// named, the larger first; "larger" is the one whose gap (rms of |a| - g
// under the baseline) is larger when it is hidden alone in the same session
// (same seed: the effects come from their own random streams, so the
// session is otherwise identical). The warm-up is faster (time constant
// 60 s) so that temperature and time are not alike: with the 120 s of the
// other tests, the quadratic's residual sometimes tips a bias drift in time
// ahead of the bias tempco, which that session can barely tell apart.
constexpr AccelParameterization kTwoEffectsModel = AccelParameterization::kScaleMisalignment;
const DiscoveryOptions kTwoEffectsBaselineOnly = [] {
  DiscoveryOptions o;
  o.max_steps = 0;
  return o;
}();

TEST(Discovery, FindsTwoHiddenEffectsLargerFirst) {
  SimulatorOptions a = DiscoverySession();
  a.temperature_tau = 60.0;
  a.effect_std[Effect::kAccelTemperatureBias] = 3.0 * kTemperatureBias;
  SimulatorOptions b = DiscoverySession();
  b.effect_std[Effect::kAccelQuadratic] = 1.5 * kQuadratic;
  SimulatorOptions both = a;
  both.effect_std[Effect::kAccelQuadratic] = b.effect_std[Effect::kAccelQuadratic];
  int found = 0, in_order = 0;
  int first = 1, seeds = kSeeds;
  DiscoverySeeds(kSeeds, &first, &seeds);
  for (int seed = first; seed < first + seeds; ++seed) {
    const Outcome run = Discover(both, seed);
    const std::vector<Effect> named = run.result.named();
    // The gaps are the baseline's alone: no step is taken (max_steps 0), the
    // same baseline fit and assessment at a fraction of the search's cost.
    const double gap_a =
        Discover(a, seed, kTwoEffectsModel, kTwoEffectsBaselineOnly).result.baseline.gap.accel;
    const double gap_b =
        Discover(b, seed, kTwoEffectsModel, kTwoEffectsBaselineOnly).result.baseline.gap.accel;
    const Effect larger = gap_a > gap_b ? Effect::kAccelTemperatureBias : Effect::kAccelQuadratic;
    const bool has_both =
        Contains(named, Effect::kAccelTemperatureBias) && Contains(named, Effect::kAccelQuadratic);
    found += has_both ? 1 : 0;
    in_order += has_both && named.front() == larger ? 1 : 0;
    if (!has_both || named.front() != larger) {
      std::printf("seed %d (gaps %.3g, %.3g): %s\n", seed, gap_a, gap_b,
                  run.result.verdict.c_str());
    }
  }
  // Measured on seeds 1001-1200: both named in 199, in order in 183 (186
  // with 24 poses) of 200 (lower 99.9 % bounds 0.94 and 0.83; 11 of 20 in
  // order either way).
  std::printf("both named %d, in order %d of %d\n", found, in_order, seeds);
  EXPECT_GE(found, testing_util::RequiredSuccesses(seeds, 0.94)) << found << " of " << seeds;
  EXPECT_GE(in_order, testing_util::RequiredSuccesses(seeds, 0.83)) << in_order << " of " << seeds;
}

// A slow, monotonic warm-up (time constant 3000 s over a 5-minute session):
// temperature is nearly proportional to time, so a bias linear in
// temperature and one linear in time fit the data equally. The report must
// say so, with advice, instead of silently picking one.
TEST(Discovery, ReportsTemperatureVersusTimeAmbiguityInMonotonicWarmUp) {
  SimulatorOptions sim = DiscoverySession();
  sim.temperature_tau = 3000.0;
  sim.effect_std[Effect::kAccelTemperatureBias] = 5.0 * kTemperatureBias;
  int reported = 0;
  int first = 1, seeds = 10;
  DiscoverySeeds(10, &first, &seeds);
  for (int seed = first; seed < first + seeds; ++seed) {
    const Outcome run = Discover(sim, seed);
    bool found = false;
    for (const Ambiguity& a : run.result.ambiguous) {
      found |= Contains(a.effects, Effect::kAccelTemperatureBias) &&
               Contains(a.effects, Effect::kAccelBiasDrift) &&
               a.advice.find("cool-down") != std::string::npos;
    }
    reported += found ? 1 : 0;
    if (!found) std::printf("seed %d: %s\n", seed, run.result.verdict.c_str());
    if (found) {
      EXPECT_NE(run.result.verdict.find("cannot tell them apart"), std::string::npos);
    }
  }
  // Measured on seeds 1001-1200: reported in 199 (197 with 24 poses) of 200
  // (lower 99.9 % bound 0.92).
  std::printf("reported %d of %d\n", reported, seeds);
  EXPECT_GE(reported, testing_util::RequiredSuccesses(seeds, 0.92)) << reported << " of " << seeds;
}

// Issue 21: each sensor's evidence stands on its own. Fourteen poses with
// the scale baseline, as on the repeat recordings of the AHRS unit of
// ../shared/data/real/ahrs_static_poses: the accelerometer hides a
// non-orthogonality (1.5 mrad per angle: chi2 33 to 4000 on 8 dof over the
// seeds, at the noise with it), while every pose's gyroscope mean carries
// an offset of 30 sigma per axis that no catalogue effect explains (the
// AHRS's gyroscope output has its own processing). The accelerometer effect
// is named; the gyroscope is reported as unexplained; and every
// accelerometer candidate is scored exactly as on the same positions
// without the gyroscope (before issue 21 the gyroscope's candidates shared
// the accelerometer's test family and BIC n, so they differed).
// The same static positions as if the log had no gyroscope column.
std::vector<StaticObservation> WithoutGyroscope(std::vector<StaticObservation> observations) {
  for (StaticObservation& o : observations) o.has_gyro = false;
  return observations;
}

TEST(Discovery, GyroscopeExcessDoesNotMaskAccelerometerEffect) {
  SimulatorOptions sim;
  sim.scheme = {PoseScheme::kRandom, 14};
  sim.hold_seconds = 10.0;
  sim.accel_misalignment_std = 1.5e-3;
  CalibrationOptions calibration;
  calibration.refinement.parameterization = AccelParameterization::kScale;
  const int seeds = 10;
  int named = 0, gyro_unexplained = 0, same_scores = 0;
  for (int seed = 1; seed <= seeds; ++seed) {
    SimulatedSession session;
    std::string error;
    ASSERT_TRUE(Simulate(sim, seed, &session, &error)) << error;
    testing_util::AddPoseOffsetsToGyro(30.0, seed, &session, sim);
    calibration.gravity.gravity = session.gravity;
    DiscoveryResult with_gyro, without_gyro;
    ASSERT_TRUE(DiscoverEffects(session.log, calibration, {}, DiscoveryOptions(), &with_gyro))
        << with_gyro.message;
    ASSERT_TRUE(DiscoverFromObservations(WithoutGyroscope(with_gyro.observations), calibration, {},
                                         DiscoveryOptions(), &without_gyro))
        << without_gyro.message;
    const std::vector<Effect> found = with_gyro.named();
    const bool has = Contains(found, Effect::kAccelMisalignment) ||
                     (!with_gyro.steps.empty() &&
                      Contains(with_gyro.steps.front().ambiguous_with, Effect::kAccelMisalignment));
    named += has ? 1 : 0;
    ASSERT_EQ(with_gyro.sensors.size(), 2u);
    const SensorVerdict& gyro = with_gyro.sensors[1];
    EXPECT_EQ(gyro.sensor, EffectSensor::kGyroscope);
    EXPECT_EQ(gyro.information, with_gyro.final_model.fit.gyro_fit.information);
    EXPECT_FALSE(gyro.information.empty());
    EXPECT_EQ(with_gyro.sensors[0].information, with_gyro.final_model.fit.accel_fit.information);
    EXPECT_GT(gyro.excess, 10.0);
    if (gyro.unexplained &&
        gyro.verdict.find("gyroscope static means exceed their noise by") != std::string::npos &&
        gyro.verdict.find("no catalogue effect explains it") != std::string::npos &&
        with_gyro.verdict.find("no catalogue effect explains it") != std::string::npos) {
      ++gyro_unexplained;
    }
    // The accelerometer's verdict is the same with and without the
    // gyroscope. (Its scores are no longer identical: the static detector
    // judges the level on the gyroscope when there is one, issue 33, so the
    // intervals differ by a few samples at the turns' ends.)
    const bool same = with_gyro.verdict.rfind(without_gyro.verdict, 0) == 0;
    same_scores += same ? 1 : 0;
    std::printf("seed %d: %s | without gyroscope: %s\n", seed, with_gyro.verdict.c_str(),
                without_gyro.verdict.c_str());
  }
  // Measured on seeds 1001-1060 (the same session through `gravcal
  // simulate` and `discover`): named first in 60 of 60 (lower 99.9 % bound
  // 0.89), the gyroscope reported unexplained in every seed, and the
  // accelerometer's verdict the same without the gyroscope.
  EXPECT_GE(named, testing_util::RequiredSuccesses(seeds, 0.89)) << named << " of " << seeds;
  EXPECT_EQ(gyro_unexplained, seeds);
  EXPECT_EQ(same_scores, seeds);
}

}  // namespace
}  // namespace gravcal

namespace gravcal {
namespace {

// ---------------------------------------------------------------------------
// Real recordings: the workflow runs to completion, and its verdict (the
// effects it names) is the same when any one position is left out, in at
// least 80 % of the leave-outs.

struct RealCase {
  const char* config;
  const char* file;
  // What the full session names: nothing (no false alarm), except on the
  // Ferraris session, whose accelerometer's chi2 falls from 164 on 7 dof to
  // 6.9 on 4 with a bias drift (discover.md, "Measured").
  std::vector<Effect> named;
};

class DiscoveryRealData : public ::testing::TestWithParam<RealCase> {};

TEST_P(DiscoveryRealData, RunsAndIsStableWhenOnePositionIsLeftOut) {
  const std::string dir = testing_util::RealDataDir();
  if (dir.empty()) GTEST_SKIP() << "no ../shared/data/real";
  const RealCase& rc = GetParam();
  Config config;
  ImuLog log;
  std::string error;
  ASSERT_TRUE(testing_util::LoadRealSession(rc.config, rc.file, &config, &log, &error)) << error;
  DiscoveryResult full;
  ASSERT_TRUE(DiscoverEffects(log, config.calibration, config.effects, config.discovery, &full))
      << full.message;
  EXPECT_FALSE(full.verdict.empty());
  std::printf("%s: %s\n", rc.config, full.verdict.c_str());
  const std::vector<Effect> named = full.named();
  EXPECT_EQ(EffectNames(named), EffectNames(rc.named)) << full.verdict;
  int same = 0, runs = 0;
  for (size_t leave = 0; leave < full.observations.size(); ++leave) {
    std::vector<StaticObservation> subset = full.observations;
    subset.erase(subset.begin() + leave);
    CalibrationOptions calibration = config.calibration;
    calibration.nominal_up.clear();
    DiscoveryResult sub;
    ASSERT_TRUE(
        DiscoverFromObservations(subset, calibration, config.effects, config.discovery, &sub))
        << "leave " << leave << ": " << sub.message;
    ++runs;
    same += sub.named() == named ? 1 : 0;
    const std::vector<CandidateScore>& round =
        sub.steps.empty() ? sub.final_candidates : sub.steps.front().candidates;
    std::string scores;
    for (const CandidateScore& c : round) {
      if (!c.tried) continue;
      char b[128];
      std::snprintf(b, sizeof(b), " %s:%.2g/%.1f", ToString(c.effect), c.p_value, c.delta_bic);
      scores += b;
    }
    std::printf("  leave %zu: %s |%s\n", leave, sub.verdict.c_str(), scores.c_str());
  }
  EXPECT_GE(same, 0.8 * runs) << same << " of " << runs;
}

// Issue 21 on the first AHRS recording (nine poses, scale baseline): its
// gyroscope's static means sit several times their noise from every static
// model (the AHRS processes its gyroscope output), and no catalogue effect
// explains that. The report says so for the gyroscope, names nothing, and
// the accelerometer's own verdict is exactly the one the log gives without
// its gyroscope column.
TEST(DiscoveryRealAhrs, GyroscopeExcessIsReportedWithoutSilencingTheAccelerometer) {
  const std::string dir = testing_util::RealDataDir();
  if (dir.empty()) GTEST_SKIP() << "no ../shared/data/real";
  Config config;
  ImuLog log;
  std::string error;
  ASSERT_TRUE(testing_util::LoadRealSession(
      "ahrs_static_poses.yaml", "ahrs_static_poses/imu_good1.txt", &config, &log, &error))
      << error;
  // The six-parameter scale model (the shipped config fits
  // scale_misalignment, which nine poses fit exactly).
  config.calibration.refinement.parameterization = AccelParameterization::kScale;
  DiscoveryResult r;
  ASSERT_TRUE(DiscoverEffects(log, config.calibration, config.effects, config.discovery, &r))
      << r.message;
  std::printf("%s\n", r.verdict.c_str());
  EXPECT_TRUE(r.named().empty()) << r.verdict;
  ASSERT_EQ(r.sensors.size(), 2u);
  const SensorVerdict& accel = r.sensors[0];
  const SensorVerdict& gyro = r.sensors[1];
  EXPECT_EQ(accel.information, r.final_model.fit.accel_fit.information);
  EXPECT_EQ(gyro.information, r.final_model.fit.gyro_fit.information);
  EXPECT_FALSE(accel.information.empty());
  EXPECT_FALSE(gyro.information.empty());
  // Measured: 6.4 (chi2 983 on 24 dof).
  EXPECT_GT(gyro.excess, 3.0);
  EXPECT_TRUE(gyro.unexplained);
  EXPECT_NE(gyro.verdict.find("gyroscope static means exceed their noise by"), std::string::npos)
      << gyro.verdict;
  EXPECT_NE(r.verdict.find("no catalogue effect explains it"), std::string::npos) << r.verdict;
  // Nine poses leave the six-parameter scale model three residuals: no
  // three-parameter accelerometer effect can be tested, and the verdict
  // says so rather than calling the accelerometer's excess explained.
  EXPECT_FALSE(accel.unexplained);
  EXPECT_NE(accel.verdict.find("can be tested"), std::string::npos) << accel.verdict;
  CalibrationOptions calibration = config.calibration;
  calibration.nominal_up.clear();
  DiscoveryResult without;
  ASSERT_TRUE(DiscoverFromObservations(WithoutGyroscope(r.observations), calibration,
                                       config.effects, config.discovery, &without))
      << without.message;
  ASSERT_EQ(without.sensors.size(), 1u);
  EXPECT_EQ(without.sensors[0].verdict, accel.verdict);
  EXPECT_EQ(without.sensors[0].excess, accel.excess);
}

INSTANTIATE_TEST_SUITE_P(
    Recordings, DiscoveryRealData,
    ::testing::Values(RealCase{"ferraris_nilspod.yaml",
                               "ferraris_nilspod/session.csv",
                               {Effect::kAccelBiasDrift}},
                      RealCase{"mpu6050_ten_pose.yaml", "mpu6050_ten_pose/session.csv", {}},
                      // good2: good1's nine poses fit the config's nine
                      // parameters exactly, and leaving one out leaves none.
                      RealCase{"ahrs_static_poses.yaml", "ahrs_static_poses/imu_good2.txt", {}}),
    [](const ::testing::TestParamInfo<RealCase>& info) {
      std::string name = info.param.config;
      return name.substr(0, name.find('.'));
    });

}  // namespace
}  // namespace gravcal
