// Issue 14: honest standard deviations on hand-placed sessions. The
// simulator adds what hand placement adds to the textbook white noise
// (configs/hand_placed.yaml: bias instability, bias random walks, tremor and
// a per-pose specific-force disturbance the samples of a pose cannot show,
// sized so the white-noise fit's residuals are 4-5 times the noise level as
// on the real recordings), and every estimated parameter's error / reported
// sigma must have rms in [0.8, 1.25] over at least 100 seeds, for
// twelve_position, ten_position and the gyroscope between poses, with the
// uncertainty keys of configs/hand_placed.yaml (pose_noise, pose_variance and
// its prior). The same sessions with the white-noise sigmas (pose_noise
// white, pose_variance false) are printed for contrast, not asserted.
//
// The gyroscope between poses runs twice: without a noise model (its bias is
// a known failure, below) and with `calibrate --noise` (asserted).
//
// Seeds: 1..kHonestySeeds; the large_seed run (GRAVCAL_PROPERTY_SEEDS=1001:400)
// checks kHonestySeeds other seeds from 1001.
#include <gtest/gtest.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "gravcal/workflows/pipeline.h"
#include "property/method_case.h"
#include "property/pipeline_case.h"
#include "simulated_noise.h"
#include "test_util.h"

namespace gravcal {
namespace testing_util {
namespace {

constexpr int kHonestySeeds = 100;

// The keys of configs/hand_placed.yaml that describe hand placement and the
// pipeline's answer to it: every sim_* key but the scheme and hold, and the
// uncertainty keys. `white` replaces the latter by the white-noise ones.
std::vector<std::pair<std::string, std::string>> HandPlacedKeys(bool white) {
  std::vector<std::pair<std::string, std::string>> keys;
  const YAML::Node root = YAML::LoadFile(SourceDir() + "/configs/hand_placed.yaml");
  for (const auto& entry : root) {
    const std::string key = entry.first.as<std::string>();
    const bool sim = key.rfind("sim_", 0) == 0 && key != "sim_scheme" && key != "sim_hold";
    const bool uncertainty = key.rfind("pose_", 0) == 0;
    if (sim || (uncertainty && !white)) keys.emplace_back(key, entry.second.as<std::string>());
  }
  if (white) {
    keys.emplace_back("pose_noise", "white");
    keys.emplace_back("pose_variance", "false");
  }
  return keys;
}

// CalibrateAsCli with --noise: the simulated sensor's noise.json.
bool CalibrateWithNoise(const Config& config, const SimulatedInput& input, uint64_t seed,
                        Calibration* calibration) {
  return CalibrateWithSimulatedNoise(config, input.session.log, "seed " + std::to_string(seed),
                                     calibration);
}

std::vector<MethodCase> HandPlacedCases(bool white) {
  const auto keys = HandPlacedKeys(white);
  std::vector<MethodCase> cases;
  auto with = [&](std::vector<std::pair<std::string, std::string>> extra) {
    extra.insert(extra.begin(), keys.begin(), keys.end());
    return extra;
  };
  cases.push_back(PipelineCase("hand_placed/twelve_position",
                               ShippedConfig("hand_placed.yaml", with({{"gyro_model", "none"}}))));
  {
    // Ten poses; checked as in method_property_test.cc: step 4's covariance
    // parameters and the diagonal of K.
    MethodCase m = PipelineCase("hand_placed/ten_position",
                                ShippedConfig("ten_position.yaml", with({{"sim_hold", "6"}})));
    m.extract = TenPositionErrors;
    cases.push_back(m);
  }
  {
    MethodCase m =
        PipelineCase("hand_placed/gyro_between_poses", ShippedConfig("hand_placed.yaml", with({})));
    m.extract = AccelAndGyroErrors;
    // Known failure without a noise model, measured 2026-11-23 (seeds
    // 1-100): the gyroscope bias's wander over the session, common to every
    // pose, is sized from the static poses' REML scatter (twice it, the
    // random walk's ratio; src/methods/gyro_bias_wander.h), which brings
    // the bias's rms error/sigma from 1.56-1.72 to 1.11-1.30. One session
    // cannot do better: a pose's white mean noise (8e-9 (rad/s)^2) is eight
    // times the scatter, so s^2 is known to about +-200 % and is often 0;
    // the ratio 3 or 4 instead of 2 gives 1.07-1.26 and 1.04-1.24. The
    // case below, with the noise model, is asserted.
    m.known_failures = {"gyro.bias_x", "gyro.bias_y", "gyro.bias_z"};
    cases.push_back(m);
  }
  {
    // The same with `calibrate --noise noise.json` (the noise model of the
    // simulated sensor as a perfect `gravcal noise` would give it): the
    // bias's wander is B^2 + K^2 T / 3 (gyro_bias_wander.h); measured rms
    // 0.98-1.05 (1.16-1.26 with the Allan variance at T, 0.44 B^2, instead
    // of B^2).
    MethodCase m = PipelineCase("hand_placed/gyro_between_poses+noise",
                                ShippedConfig("hand_placed.yaml", with({})));
    m.extract = AccelAndGyroErrors;
    // The white-noise contrast calibrates without it.
    m.calibrate = [white](const Config& config, const SimulatedInput& input, uint64_t seed,
                          Calibration* c) {
      return white ? CalibrateAsCli(config, input, seed, c)
                   : CalibrateWithNoise(config, input, seed, c);
    };
    cases.push_back(m);
  }
  return cases;
}

// Runs a case over the seeds; false seeds are test failures.
SigmaCheck RunCase(const MethodCase& method, int first, int seeds, double* seconds,
                   SigmaCheck* known) {
  const auto start = std::chrono::steady_clock::now();
  SigmaCheck check;
  const std::vector<SeedOutcome> failed =
      RunMethodCase(method, first, seeds, PropertyThreads(), &check, known);
  *seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  for (const SeedOutcome& f : failed) {
    ADD_FAILURE() << method.name << " seed " << f.seed << ": " << f.message;
  }
  return check;
}

class HandPlaced : public ::testing::TestWithParam<int> {};

TEST_P(HandPlaced, ErrorOverSigmaRmsIsNearOne) {
  // GRAVCAL_PROPERTY_SEEDS moves the first seed (the large_seed run checks
  // seeds 1001-1100); the count stays kHonestySeeds, for CI time (each seed
  // is calibrated twice, about 1 s per 10 seeds on two threads).
  int first = 1, requested = 0;
  if (std::getenv("GRAVCAL_PROPERTY_SEEDS") != nullptr) PropertySeeds(&first, &requested);
  const int seeds = kHonestySeeds;
  ASSERT_GE(seeds, 2);
  const MethodCase honest = HandPlacedCases(false)[GetParam()];
  const MethodCase white = HandPlacedCases(true)[GetParam()];
  double honest_seconds = 0.0, white_seconds = 0.0;
  SigmaCheck known, known_white;
  const SigmaCheck check = RunCase(honest, first, seeds, &honest_seconds, &known);
  const SigmaCheck contrast = RunCase(white, first, seeds, &white_seconds, &known_white);
  std::printf(
      "%s: seeds %d..%d, %.1f s\nwith configs/hand_placed.yaml's uncertainty keys:\n%s"
      "white-noise sigmas on the same sessions (%.1f s):\n%s",
      honest.name.c_str(), first, first + seeds - 1, honest_seconds, check.Table().c_str(),
      white_seconds, contrast.Table().c_str());
  if (!honest.known_failures.empty()) {
    std::printf("known failures (not asserted):\n%swith white sigmas:\n%s", known.Table().c_str(),
                known_white.Table().c_str());
  }
  ASSERT_FALSE(check.Names().empty());
  for (const std::string& name : check.Names()) {
    EXPECT_GT(check.Rms(name), 0.8) << honest.name << " " << name;
    EXPECT_LT(check.Rms(name), 1.25) << honest.name << " " << name;
  }
}

std::string HandPlacedCaseName(const ::testing::TestParamInfo<int>& info) {
  return TestParameterName(HandPlacedCases(false)[info.param].name);
}

INSTANTIATE_TEST_SUITE_P(Methods, HandPlaced,
                         ::testing::Range(0, static_cast<int>(HandPlacedCases(false).size())),
                         HandPlacedCaseName);

}  // namespace
}  // namespace testing_util
}  // namespace gravcal
