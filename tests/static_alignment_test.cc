// Static alignment: roll and pitch against the simulator's truth, with the
// reported standard deviations matching the spread seen over many seeds.
#include "gravcal/estimation/static_alignment.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "gravcal/simulation/simulator.h"
#include "sigma_check.h"

namespace gravcal {
namespace {

constexpr double kDeg = M_PI / 180.0;
// Seeds of the gyrocompass checks: sigmas twice too large fail SigmaCheck's
// band from 30 on.
constexpr int kGyrocompassSeeds = 30;

// Samples of one simulated pose, in SI units.
void PoseSamples(const SimulatedSession& s, const SimulatedPose& pose,
                 std::vector<Eigen::Vector3d>* force, std::vector<Eigen::Vector3d>* rate) {
  force->clear();
  rate->clear();
  for (size_t i = pose.begin; i < pose.end; ++i) {
    force->push_back(s.log.accel[i] / s.accel_units_per_si);
    rate->push_back(s.log.gyro[i] / s.gyro_units_per_si);
  }
}

// error / reported sigma of roll and pitch over `seeds` ten-position
// sessions, per pose ("roll[k]", "pitch[k]": the poses of one session share
// the accelerometer's bias, so their errors are correlated and only one
// value per seed goes into each parameter), for the poses with |pitch| < 60
// deg, where roll is defined.
testing_util::SigmaCheck RollPitchConsistency(const SimulatorOptions& sim,
                                              const StaticAlignmentOptions& align, int seeds,
                                              bool use_gyro) {
  testing_util::SigmaCheck check;
  std::vector<Eigen::Vector3d> force, rate;
  for (int seed = 1; seed <= seeds; ++seed) {
    SimulatedSession s;
    std::string error;
    EXPECT_TRUE(Simulate(sim, seed, &s, &error)) << error;
    for (size_t k = 0; k < s.poses.size(); ++k) {
      const SimulatedPose& pose = s.poses[k];
      const Eigen::Vector3d truth = RollPitchHeading(pose.attitude);
      if (std::fabs(truth(1)) > 60.0 * kDeg) continue;
      PoseSamples(s, pose, &force, &rate);
      StaticAlignmentResult r;
      EXPECT_TRUE(AlignStatic(force, use_gyro ? rate : std::vector<Eigen::Vector3d>(),
                              1.0 / sim.sample_rate, align, &r))
          << r.message;
      const std::string index = "[" + std::to_string(k) + "]";
      check.Add("roll" + index, std::remainder(r.roll - truth(0), 2.0 * M_PI), r.roll_std);
      check.Add("pitch" + index, r.pitch - truth(1), r.pitch_std);
    }
  }
  std::printf("%s", check.Table().c_str());
  return check;
}

SimulatorOptions TenPoseSession() {
  SimulatorOptions sim;
  sim.scheme = {PoseScheme::kTen};
  sim.hold_seconds = 8.0;
  sim.initial_still_seconds = 0.0;
  sim.rotation_seconds = 1.0;
  // The accelerometer's only constant error is its bias, so the prior below
  // describes it exactly.
  sim.accel_scale_std = 0.0;
  sim.accel_misalignment_std = 0.0;
  return sim;
}

TEST(StaticAlignment, RollPitchSigmaMatchesSpreadWhenBiasDominates) {
  // An uncalibrated MEMS accelerometer: 0.3 m/s^2 bias, which a static base
  // cannot tell from tilt; the sigma must say about 1.7 degrees.
  SimulatorOptions sim = TenPoseSession();
  sim.accel_bias_std = 0.3;
  StaticAlignmentOptions align;
  align.accel_bias_std = 0.3;
  const testing_util::SigmaCheck check = RollPitchConsistency(sim, align, 50, true);
  EXPECT_GE(check.Names().size(), 12u);
  check.ExpectHonest("static alignment, bias dominates");
}

TEST(StaticAlignment, RollPitchSigmaMatchesSpreadWhenNoiseDominates) {
  // A calibrated accelerometer (bias 2e-4 m/s^2): the sigma comes from the
  // noise and the gyroscope's random walk, two orders of magnitude smaller.
  SimulatorOptions sim = TenPoseSession();
  sim.accel_bias_std = 2e-4;
  sim.raw_counts = false;
  StaticAlignmentOptions align;
  align.accel_bias_std = 2e-4;
  for (bool use_gyro : {true, false}) {
    const testing_util::SigmaCheck check = RollPitchConsistency(sim, align, 50, use_gyro);
    EXPECT_GE(check.Names().size(), 12u);
    check.ExpectHonest(use_gyro ? "static alignment, noise dominates, with gyroscope"
                                : "static alignment, noise dominates, accelerometer only");
  }
}

TEST(StaticAlignment, ReportsSigmaOfTheBiasPrior) {
  SimulatorOptions sim = TenPoseSession();
  SimulatedSession s;
  std::string error;
  ASSERT_TRUE(Simulate(sim, 3, &s, &error)) << error;
  std::vector<Eigen::Vector3d> force, rate;
  PoseSamples(s, s.poses[0], &force, &rate);
  StaticAlignmentOptions align;
  align.accel_bias_std = 0.3;
  StaticAlignmentResult r;
  ASSERT_TRUE(AlignStatic(force, rate, 0.01, align, &r)) << r.message;
  // Level pose: a horizontal bias of 0.3 m/s^2 is a tilt of 0.3 / g rad.
  EXPECT_NEAR(r.roll_std, 0.3 / 9.80665, 0.1 * 0.3 / 9.80665);
  EXPECT_NEAR(r.pitch_std, 0.3 / 9.80665, 0.1 * 0.3 / 9.80665);
  EXPECT_NEAR(r.gravity_body.norm(), sim.gravity, 1e-9);
  EXPECT_FALSE(r.heading_observed);
  EXPECT_TRUE(std::isnan(r.heading_std));
  EXPECT_EQ(r.heading, 0.0);
  // The horizontal biases are not visible on a static base: they stay at
  // their prior.
  EXPECT_GT(r.accel_bias_std(0), 0.25);
  EXPECT_GT(r.accel_bias_std(1), 0.25);
}

// A navigation-grade, calibrated gyroscope (its bias prior is its only
// constant error: a misalignment would turn vertical Earth rate into
// horizontal) at 45 deg latitude, and an accelerometer with `accel_bias`
// m/s^2 of bias: pose 4 (+z up, near level) of `seed`, aligned; `truth` gets
// the true roll, pitch and heading.
StaticAlignmentResult NavigationGradeAlignment(double accel_bias, double hold_seconds, int seed,
                                               Eigen::Vector3d* truth) {
  SimulatorOptions sim = TenPoseSession();
  sim.scheme = {PoseScheme::kSix};
  sim.hold_seconds = hold_seconds;
  sim.raw_counts = false;
  sim.latitude_deg = 45.0;
  sim.accel_bias_std = accel_bias;
  sim.gyro_bias_std = 1e-8;
  sim.gyro_noise = 1e-6;
  sim.gyro_scale_std = 0.0;
  sim.gyro_misalignment_std = 0.0;
  StaticAlignmentOptions align;
  align.latitude_deg = 45.0;
  align.accel_bias_std = accel_bias;
  align.gyro_bias_std = 1e-8;
  SimulatedSession s;
  std::string error;
  EXPECT_TRUE(Simulate(sim, seed, &s, &error)) << error;
  std::vector<Eigen::Vector3d> force, rate;
  PoseSamples(s, s.poses[4], &force, &rate);
  StaticAlignmentResult r;
  EXPECT_TRUE(AlignStatic(force, rate, 0.01, align, &r)) << r.message;
  EXPECT_TRUE(r.heading_observed) << r.gyrocompass_heading_std / kDeg;
  *truth = RollPitchHeading(s.poses[4].attitude);
  return r;
}

// The heading error against its sigma over seeds, with `accel_bias` m/s^2
// of accelerometer bias (60 s hold).
testing_util::SigmaCheck HeadingConsistency(double accel_bias, int seeds) {
  testing_util::SigmaCheck check;
  for (int seed = 1; seed <= seeds; ++seed) {
    Eigen::Vector3d truth;
    const StaticAlignmentResult r = NavigationGradeAlignment(accel_bias, 60.0, seed, &truth);
    check.Add("heading", std::remainder(r.heading - truth(2), 2.0 * M_PI), r.heading_std);
  }
  std::printf("%s", check.Table().c_str());
  return check;
}

TEST(StaticAlignment, GyrocompassesWithANavigationGradeGyroscope) {
  // A 0.15 m/s^2 accelerometer bias tilts the levelling by about 0.9 deg,
  // which turns vertical Earth rate into horizontal: heading is good to
  // about a degree (tan(latitude) times the tilt error), and the sigma says
  // so, against the spread of the heading error over the seeds.
  // (Measured, 200 seeds: rms error/sigma 0.93 at 0.05 m/s^2, 0.97 at 0.15;
  // at 0.3 it was 1.37 and at 0.6 3.5 before the sigma was held at the
  // static limit, see HeadingSigmaHonestWithLargeBias.)
  HeadingConsistency(0.15, kGyrocompassSeeds)
      .ExpectHonest("gyrocompass, 0.15 m/s^2 accelerometer bias");
}

// With 0.3 and 0.6 m/s^2 of accelerometer bias the filter's heading sigma
// (linearised at the coarse attitude) fell below what no static base can
// resolve, tan(latitude) b_a / g: 1.1-1.7 deg against the 1.75 deg limit at
// 0.3 m/s^2 (rms error/sigma 1.37 over 300 seeds), 1.6 deg at 0.6 (rms 3.5).
// The sigma is now held at that limit (HoldHeadingStdAtTheStaticLimit).
// Measured, 300 seeds at 0.3 m/s^2: rms error/sigma 0.99. 60 seeds each here
// (about 3 s per bias).
TEST(StaticAlignment, HeadingSigmaHonestWithLargeBias) {
  for (double bias : {0.3, 0.6}) {
    char what[64];
    std::snprintf(what, sizeof(what), "gyrocompass, %.1f m/s^2 accelerometer bias", bias);
    HeadingConsistency(bias, 60).ExpectHonest(what);
  }
}

TEST(StaticAlignment, GyrocompassSigmasMatchSpread) {
  // With a partly calibrated accelerometer (0.05 m/s^2) roll, pitch and
  // heading are all within what the filter says.
  testing_util::SigmaCheck check;
  for (int seed = 1; seed <= kGyrocompassSeeds; ++seed) {
    Eigen::Vector3d truth;
    const StaticAlignmentResult r = NavigationGradeAlignment(0.05, 30.0, seed, &truth);
    check.Add("roll", r.roll - truth(0), r.roll_std);
    check.Add("pitch", r.pitch - truth(1), r.pitch_std);
    check.Add("heading", std::remainder(r.heading - truth(2), 2.0 * M_PI), r.heading_std);
  }
  std::printf("%s", check.Table().c_str());
  check.ExpectHonest("gyrocompass, 0.05 m/s^2 accelerometer bias");
}

TEST(StaticAlignment, MemsGyroscopeCannotResolveEarthRate) {
  SimulatorOptions sim = TenPoseSession();
  sim.latitude_deg = 45.0;
  SimulatedSession s;
  std::string error;
  ASSERT_TRUE(Simulate(sim, 1, &s, &error)) << error;
  std::vector<Eigen::Vector3d> force, rate;
  PoseSamples(s, s.poses[0], &force, &rate);
  StaticAlignmentOptions align;
  align.latitude_deg = 45.0;
  StaticAlignmentResult r;
  ASSERT_TRUE(AlignStatic(force, rate, 0.01, align, &r)) << r.message;
  EXPECT_FALSE(r.heading_observed);
  // 0.02 rad/s of bias against 5.2e-5 rad/s of horizontal Earth rate.
  EXPECT_GT(r.gyrocompass_heading_std, 100.0);
  ASSERT_FALSE(r.warnings.empty());
  EXPECT_NE(r.warnings.back().find("heading not observed"), std::string::npos);
}

TEST(StaticAlignment, RejectsBadInput) {
  StaticAlignmentOptions align;
  StaticAlignmentResult r;
  std::vector<Eigen::Vector3d> few(5, Eigen::Vector3d(0, 0, 9.8));
  EXPECT_FALSE(AlignStatic(few, {}, 0.01, align, &r));
  EXPECT_NE(r.message.find("at least 10 samples"), std::string::npos);
  std::vector<Eigen::Vector3d> counts(100, Eigen::Vector3d(0, 0, 16384));
  EXPECT_FALSE(AlignStatic(counts, {}, 0.01, align, &r));
  EXPECT_NE(r.message.find("not near g"), std::string::npos);
  std::vector<Eigen::Vector3d> nan(100, Eigen::Vector3d(0, 0, 9.8));
  nan[50](1) = NAN;
  EXPECT_FALSE(AlignStatic(nan, {}, 0.01, align, &r));
  align.accel_bias_std = -1.0;
  std::string error;
  EXPECT_FALSE(align.IsValid(&error));
  EXPECT_NE(error.find("align_accel_bias_std"), std::string::npos);
}

}  // namespace
}  // namespace gravcal
