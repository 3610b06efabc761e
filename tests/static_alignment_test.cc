// Static alignment: roll and pitch against the simulator's truth, with the
// reported standard deviations matching the spread seen over many seeds.
#include "gravcal/estimation/static_alignment.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "gravcal/simulation/simulator.h"

namespace gravcal {
namespace {

constexpr double kDeg = M_PI / 180.0;

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

struct Consistency {
  double rms = 0.0;
  int count = 0;
  double max_abs = 0.0;
};

// error / reported sigma of roll and pitch over `seeds` ten-position sessions
// (poses with |pitch| < 60 deg, where roll is defined).
Consistency RollPitchConsistency(const SimulatorOptions& sim, const StaticAlignmentOptions& align,
                                 int seeds, bool use_gyro) {
  Consistency c;
  double sum = 0.0;
  std::vector<Eigen::Vector3d> force, rate;
  for (int seed = 1; seed <= seeds; ++seed) {
    SimulatedSession s;
    std::string error;
    EXPECT_TRUE(Simulate(sim, seed, &s, &error)) << error;
    for (const SimulatedPose& pose : s.poses) {
      const Eigen::Vector3d truth = RollPitchHeading(pose.attitude);
      if (std::fabs(truth(1)) > 60.0 * kDeg) continue;
      PoseSamples(s, pose, &force, &rate);
      StaticAlignmentResult r;
      EXPECT_TRUE(AlignStatic(force, use_gyro ? rate : std::vector<Eigen::Vector3d>(),
                              1.0 / sim.sample_rate, align, &r))
          << r.message;
      const double roll_error = std::remainder(r.roll - truth(0), 2.0 * M_PI) / r.roll_std;
      const double pitch_error = (r.pitch - truth(1)) / r.pitch_std;
      for (double e : {roll_error, pitch_error}) {
        sum += e * e;
        c.max_abs = std::max(c.max_abs, std::fabs(e));
        ++c.count;
      }
    }
  }
  c.rms = std::sqrt(sum / c.count);
  return c;
}

SimulatorOptions TenPoseSession() {
  SimulatorOptions sim;
  sim.scheme = "ten";
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
  const Consistency c = RollPitchConsistency(sim, align, 50, true);
  EXPECT_GT(c.count, 300);
  EXPECT_GT(c.rms, 0.8);
  EXPECT_LT(c.rms, 1.25);
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
    const Consistency c = RollPitchConsistency(sim, align, 50, use_gyro);
    EXPECT_GT(c.rms, 0.8) << "use_gyro " << use_gyro;
    EXPECT_LT(c.rms, 1.25) << "use_gyro " << use_gyro;
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
  sim.scheme = "six";
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

TEST(StaticAlignment, GyrocompassesWithANavigationGradeGyroscope) {
  // A 0.3 m/s^2 accelerometer bias tilts the levelling by up to ~2 deg, which
  // turns vertical Earth rate into horizontal: heading is good to a few
  // degrees (tan(latitude) times the tilt error), and the sigma says so.
  for (int seed = 1; seed <= 5; ++seed) {
    Eigen::Vector3d truth;
    const StaticAlignmentResult r = NavigationGradeAlignment(0.3, 60.0, seed, &truth);
    EXPECT_LT(std::fabs(std::remainder(r.heading - truth(2), 2.0 * M_PI)), 5.0 * kDeg)
        << "seed " << seed << " heading " << r.heading / kDeg << " truth " << truth(2) / kDeg;
    EXPECT_GT(r.heading_std, 0.5 * kDeg);
    EXPECT_LT(r.heading_std, 2.5 * kDeg);
  }
}

TEST(StaticAlignment, GyrocompassSigmasMatchSpread) {
  // With a partly calibrated accelerometer (0.05 m/s^2) roll, pitch and
  // heading are all within what the filter says. (With 0.3 m/s^2 the RMS is
  // about 1.3: the filter is linearised, and the 1.7 deg tilt error no static
  // base can remove leaves second-order terms the gyroscope resolves.)
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  const int seeds = 30;
  for (int seed = 1; seed <= seeds; ++seed) {
    Eigen::Vector3d truth;
    const StaticAlignmentResult r = NavigationGradeAlignment(0.05, 30.0, seed, &truth);
    const Eigen::Vector3d e((r.roll - truth(0)) / r.roll_std, (r.pitch - truth(1)) / r.pitch_std,
                            std::remainder(r.heading - truth(2), 2.0 * M_PI) / r.heading_std);
    sum += e.cwiseProduct(e);
  }
  const Eigen::Vector3d rms = (sum / seeds).cwiseSqrt();
  EXPECT_GT(rms.minCoeff(), 0.7) << rms.transpose();
  EXPECT_LT(rms.maxCoeff(), 1.3) << rms.transpose();
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
