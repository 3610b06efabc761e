// gravcal record's core (issue 37): the closed loop with a virtual hand that
// follows the suggestions, a hand that ignores them, the capture of a hold
// only when its information is in, and the calibration equal to calibrate's
// on the written log.
#include "gravcal/workflows/recorder.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <nlohmann/json.hpp>

#include "gravcal/detection/static_detector.h"
#include "gravcal/io/log_reader.h"
#include "gravcal/simulation/virtual_hand.h"
#include "gravcal/workflows/pipeline.h"
#include "gravcal/workflows/plan.h"
#include "test_util.h"

namespace gravcal {
namespace {

using testing_util::SourceDir;

constexpr char kTargets[] = "accel_bias=0.3mg accel_scale=100ppm accel_misalignment=0.2mrad";

Config RecordConfig() {
  Config config;
  std::string error;
  EXPECT_TRUE(LoadConfigFile(SourceDir() + "/configs/twelve_position.yaml", &config, &error))
      << error;
  return config;
}

RecorderOptions Options() {
  RecorderOptions options;
  options.request.targets = kTargets;
  options.max_time_seconds = 900.0;
  return options;
}

struct LoopResult {
  bool started = false;
  std::string reason;
  int poses = 0;
  std::vector<nlohmann::json> events;
  RecorderResult result;
  VirtualHandOptions hand;
  AccelModel truth;
  double accel_scale = 1.0;
};

// The hand follows each suggestion (follow) or keeps putting the unit back
// on +Z (not follow), until the recorder is done or max_time.
LoopResult RunLoop(uint64_t seed, bool follow, double max_time = 900.0) {
  LoopResult out;
  Recorder recorder;
  std::string error;
  RecorderOptions options = Options();
  options.max_time_seconds = max_time;
  out.started = recorder.Start(RecordConfig(), options, &error);
  EXPECT_TRUE(out.started) << error;
  if (!out.started) return out;
  VirtualHand hand(out.hand, seed);
  out.truth = hand.accel_truth();
  out.accel_scale = hand.accel_scale();
  while (!recorder.done()) {
    const ImuSample s = hand.Next();
    for (const RecorderEvent& e : recorder.Feed(s.t, s.accel, s.gyro)) {
      out.events.push_back(nlohmann::json::parse(e.json));
      if (e.type == RecorderEventType::kSuggest) {
        hand.MoveTo(follow ? Eigen::Vector3d(out.events.back()["up"][0], out.events.back()["up"][1],
                                             out.events.back()["up"][2])
                           : Eigen::Vector3d::UnitZ());
      }
      if (e.type == RecorderEventType::kPoseCaptured) ++out.poses;
    }
  }
  out.reason = recorder.status().done_reason;
  EXPECT_TRUE(recorder.Finish(out.reason, {"record.csv"}, &out.result, &error)) << error;
  out.events.push_back(nlohmann::json::parse(out.result.done.json));
  return out;
}

// z = (estimate - truth) / sigma of b and U.
void AddZ(const LoopResult& r, std::vector<double>* z) {
  const AccelCalibration& a = r.result.calibration.accel;
  for (int i = 0; i < 3; ++i) z->push_back((a.model.bias(i) - r.truth.bias(i)) / a.bias_std(i));
  for (int i = 0; i < 3; ++i) {
    for (int j = i; j < 3; ++j) {
      // M = R U with R = I for the magnitude model: matrix_std is U's.
      z->push_back((a.model.upper(i, j) - r.truth.upper(i, j)) / a.matrix_std(i, j));
    }
  }
}

int SeedCount() {
  const char* env = std::getenv("GRAVCAL_RECORD_SEEDS");
  return env ? std::max(1, std::atoi(env)) : 3;
}

TEST(Recorder, ClosedLoopMeetsTargetsWithinPlanPlusTwoAndHonestSigmas) {
  PlanRequest request;
  request.targets = kTargets;
  request.accel_noise_density = VirtualHandOptions().accel_noise / std::sqrt(100.0);
  RecordingPlan plan;
  std::string error;
  ASSERT_TRUE(MakeRecordingPlan(RecordConfig(), request, &plan, &error)) << error;
  std::vector<double> z;
  const auto start = std::chrono::steady_clock::now();
  for (int seed = 1; seed <= SeedCount(); ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const LoopResult r = RunLoop(seed, true);
    ASSERT_TRUE(r.started);
    EXPECT_EQ(r.reason, "targets_met");
    EXPECT_LE(r.poses, static_cast<int>(plan.poses.size()) + 2);
    ASSERT_TRUE(r.result.ok) << r.result.calibration.message;
    AddZ(r, &z);
    std::printf("seed %d: %d poses (plan %zu), %s\n", seed, r.poses, plan.poses.size(),
                r.result.done.text.c_str());
  }
  double sum = 0.0;
  for (double v : z) sum += v * v;
  const double rms = std::sqrt(sum / static_cast<double>(z.size()));
  std::printf("closed loop: rms z %.3f over %zu parameters, %.2f s\n", rms, z.size(),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  // Few seeds in the default suite: a wide band (GRAVCAL_RECORD_SEEDS=20
  // for the issue's [0.7, 1.4]).
  EXPECT_GT(rms, SeedCount() >= 20 ? 0.7 : 0.5);
  EXPECT_LT(rms, SeedCount() >= 20 ? 1.4 : 1.6);
}

TEST(Recorder, AHandRepeatingOneFaceNeverMeetsTargetsAndIsToldWhy) {
  const LoopResult r = RunLoop(7, false, 200.0);
  ASSERT_TRUE(r.started);
  EXPECT_EQ(r.reason, "max_time");
  EXPECT_GE(r.poses, 3);
  const nlohmann::json& done = r.events.back();
  ASSERT_EQ(done["event"], "done");
  ASSERT_FALSE(done["undetermined"].empty());
  // Each undetermined parameter with its reason: the poses cannot tell it
  // apart, seen only with +Z up.
  for (const auto& u : done["undetermined"]) {
    EXPECT_NE(u["reason"].get<std::string>().find("+Z up"), std::string::npos) << u.dump();
  }
  for (const auto& e : r.events) EXPECT_FALSE(e["event"] == "sigma" && e["targets_met"] == true);
}

TEST(Recorder, CalibrationEqualsCalibrateOnTheWrittenLog) {
  const LoopResult r = RunLoop(2, true);
  ASSERT_TRUE(r.result.ok);
  Config config = RecordConfig();
  ImuLog log;
  std::string error;
  ASSERT_TRUE(ParseImuLog(r.result.log_csv, "written.csv", config.input, &log, &error)) << error;
  PipelineInput input;
  input.log = log;
  Calibration c;
  ASSERT_TRUE(RunCalibration(config, input, &c)) << c.message;
  EXPECT_EQ(c.accel.model.bias, r.result.calibration.accel.model.bias);
  EXPECT_EQ(c.accel.model.upper, r.result.calibration.accel.model.upper);
  EXPECT_EQ(c.positions.size(), r.result.calibration.positions.size());
  // Every captured pose is one the offline detector finds in the log.
  StaticDetection detection;
  ASSERT_TRUE(DetectStaticIntervals(log, config.calibration.detector, &detection));
  for (const auto& e : r.events) {
    if (e["event"] != "pose_captured") continue;
    const double t = e["t_begin"].get<double>() + 0.5 * e["duration"].get<double>();
    bool found = false;
    for (const StaticInterval& s : detection.intervals) found |= s.t_begin <= t && t <= s.t_end;
    EXPECT_TRUE(found) << e.dump();
  }
}

TEST(Recorder, DescribesUpDirectionsInWords) {
  EXPECT_EQ(DescribeUp(Eigen::Vector3d(0, 1, 0)).instruction, "+Y up");
  EXPECT_EQ(DescribeUp(Eigen::Vector3d(1, 1, 0)).instruction,
            "+X up, then tilt about 45 degrees toward +Y (+Y rises)");
  EXPECT_EQ(DescribeUp(Eigen::Vector3d(0, -1, -1)).face, "-Y");
}

TEST(Recorder, RefusesBadOptionsAndMissingTargets) {
  Recorder recorder;
  std::string error;
  RecorderOptions options;
  EXPECT_FALSE(recorder.Start(RecordConfig(), options, &error));
  EXPECT_NE(error.find("--target"), std::string::npos) << error;
  options.request.targets = kTargets;
  options.min_hold_seconds = 0.0;
  EXPECT_FALSE(recorder.Start(RecordConfig(), options, &error));
  EXPECT_NE(error.find("min_hold"), std::string::npos) << error;
}

}  // namespace
}  // namespace gravcal

namespace gravcal {
namespace {

TEST(Recorder, AHoldThatMovesIsNamed) {
  Recorder recorder;
  std::string error;
  RecorderOptions options = Options();
  ASSERT_TRUE(recorder.Start(RecordConfig(), options, &error)) << error;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n(0.0, 1.0);
  const double g = 16384.0;
  std::vector<std::string> kinds;
  // Still on +Z for 8 s, then "held" while it turns slowly about x (2
  // degrees a second) for 20 s.
  for (int k = 0; k < 2800; ++k) {
    const double t = k * 0.01;
    const double angle = t < 8.0 ? 0.0 : (t - 8.0) * 2.0 * M_PI / 180.0;
    const Eigen::Vector3d accel(30.0 * n(rng), g * std::sin(angle) + 30.0 * n(rng),
                                g * std::cos(angle) + 30.0 * n(rng));
    const Eigen::Vector3d gyro(t < 8.0 ? 0.0 : 2.0 * 131.0, 0.0, 0.0);
    for (const RecorderEvent& e :
         recorder.Feed(t, accel, gyro + Eigen::Vector3d(n(rng), n(rng), n(rng)))) {
      const nlohmann::json j = nlohmann::json::parse(e.json);
      if (j["event"] == "warning") kinds.push_back(j["kind"]);
    }
  }
  // Named once for the one stretch.
  EXPECT_EQ(std::count(kinds.begin(), kinds.end(), "moving_hold"), 1);
}

}  // namespace
}  // namespace gravcal
