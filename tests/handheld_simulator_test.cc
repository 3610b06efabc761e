#include "gravcal/simulation/handheld_simulator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "gravcal/workflows/config.h"
#include "test_util.h"

namespace gravcal {
namespace {

SimulatorOptions NoiseFree() {
  SimulatorOptions sensor;
  sensor.raw_counts = false;
  sensor.accel_noise = 0.0;
  sensor.gyro_noise = 0.0;
  return sensor;
}

TEST(HandheldSimulator, DeterministicPerSeed) {
  MotionSession a, b, c;
  std::string error;
  ASSERT_TRUE(SimulateMotion(SimulatorOptions(), MotionOptions(), 5, &a, &error)) << error;
  ASSERT_TRUE(SimulateMotion(SimulatorOptions(), MotionOptions(), 5, &b, &error)) << error;
  ASSERT_TRUE(SimulateMotion(SimulatorOptions(), MotionOptions(), 6, &c, &error)) << error;
  // Every sample of every column, and the truth, identical for one seed.
  const ImuLog& la = a.sensor.log;
  const ImuLog& lb = b.sensor.log;
  ASSERT_EQ(la.size(), lb.size());
  EXPECT_EQ(la.t, lb.t);
  EXPECT_EQ(la.accel, lb.accel);
  EXPECT_EQ(la.gyro, lb.gyro);
  EXPECT_EQ(la.temperature, lb.temperature);
  EXPECT_EQ(a.position, b.position);
  EXPECT_EQ(a.velocity, b.velocity);
  for (size_t i = 0; i < a.attitude.size(); ++i) {
    ASSERT_EQ(a.attitude[i].coeffs(), b.attitude[i].coeffs()) << "sample " << i;
  }
  EXPECT_EQ(a.sensor.gyro_truth.matrix, b.sensor.gyro_truth.matrix);
  EXPECT_EQ(a.sensor.accel_truth.matrix(), b.sensor.accel_truth.matrix());
  // Another seed: another session (noise in every column).
  EXPECT_NE(la.accel, c.sensor.log.accel);
  EXPECT_NE(la.gyro, c.sensor.log.gyro);
}

TEST(HandheldSimulator, TurntableReturnsToZero) {
  MotionOptions motion;
  motion.profile = MotionProfile::kTurntable;
  motion.rate_dps = 30.0;
  MotionSession s;
  std::string error;
  ASSERT_TRUE(SimulateMotion(NoiseFree(), motion, 2, &s, &error)) << error;
  // Whole turns and the tilt back: the end attitude is the start one, level.
  EXPECT_LT(testing_util::QuaternionAngle(s.attitude.front(), s.attitude.back()), 1e-6);
  const Eigen::Vector3d up = s.attitude.front().conjugate() * Eigen::Vector3d::UnitZ();
  EXPECT_NEAR(up.z(), 1.0, 1e-12);
  // No sway on a table.
  for (const Eigen::Vector3d& p : s.position) EXPECT_EQ(p.norm(), 0.0);
}

TEST(HandheldSimulator, HandTurnsAboutRoughlyHorizontalAxes) {
  MotionSession s;
  std::string error;
  ASSERT_TRUE(SimulateMotion(NoiseFree(), MotionOptions(), 3, &s, &error)) << error;
  // Wherever the body rate is mostly about one axis and fast, that axis is
  // near horizontal (2 deg initial tilt per axis, 3 deg rms wobble): within
  // 20 degrees, 8 degrees rms; every axis gets such turns.
  int turning[3] = {0, 0, 0};
  double sum_sin2 = 0.0;
  double largest_sway = 0.0;
  for (size_t i = 0; i < s.sensor.log.size(); ++i) {
    const Eigen::Vector3d w = s.sensor.gyro_truth.Apply(s.sensor.log.gyro[i]);
    largest_sway = std::max(largest_sway, s.position[i].norm());
    int axis;
    if (w.cwiseAbs().maxCoeff(&axis) < 0.5 || std::fabs(w(axis)) < 0.9 * w.norm()) continue;
    const Eigen::Vector3d axis_n = s.attitude[i] * Eigen::Vector3d::Unit(axis);
    EXPECT_LT(std::fabs(axis_n.z()), std::sin(20.0 * M_PI / 180.0)) << "sample " << i;
    sum_sin2 += axis_n.z() * axis_n.z();
    ++turning[axis];
  }
  for (int a = 0; a < 3; ++a) EXPECT_GT(turning[a], 500) << a;
  const double rms_deg =
      std::asin(std::sqrt(sum_sin2 / (turning[0] + turning[1] + turning[2]))) * 180.0 / M_PI;
  EXPECT_LT(rms_deg, 8.0);
  std::printf("turning axis elevation rms %.1f deg\n", rms_deg);
  // A few centimetres of sway.
  EXPECT_GT(largest_sway, 0.005);
  EXPECT_LT(largest_sway, 0.1);
}

TEST(HandheldSimulator, RateTableSegmentsHaveTheirRate) {
  MotionOptions motion;
  motion.profile = MotionProfile::kRateTable;
  MotionSession s;
  std::string error;
  ASSERT_TRUE(SimulateMotion(NoiseFree(), motion, 4, &s, &error)) << error;
  ASSERT_EQ(s.segments.size(), 6u);
  for (const RateTableSegment& seg : s.segments) {
    ASSERT_LT(seg.begin + 100, seg.end);
    // The turning axis points up, and the gyroscope sees exactly the rate.
    int axis;
    seg.rate.cwiseAbs().maxCoeff(&axis);
    const Eigen::Vector3d up = s.attitude[seg.begin] * Eigen::Vector3d::Unit(axis);
    EXPECT_NEAR(up.z(), 1.0, 1e-6);
    for (size_t i = seg.begin; i < seg.end; i += 50) {
      EXPECT_LT((s.sensor.gyro_truth.Apply(s.sensor.log.gyro[i]) - seg.rate).norm(), 1e-12);
    }
  }
}

TEST(HandheldSimulator, BadOptionsAreNamed) {
  MotionOptions motion;
  motion.sway = -1.0;
  MotionSession s;
  std::string error;
  EXPECT_FALSE(SimulateMotion(SimulatorOptions(), motion, 1, &s, &error));
  EXPECT_NE(error.find("hh_sway"), std::string::npos) << error;
  Config config;
  EXPECT_FALSE(SetConfigValue("sim_motion", "spin", &config, &error));
  EXPECT_EQ(error,
            "key 'sim_motion': 'spin' is not one of handheld, turntable, vertical or rate_table "
            "(or empty)");
  ASSERT_TRUE(SetConfigValue("sim_motion", "turntable", &config, &error)) << error;
  ASSERT_TRUE(SetConfigValue("method", "handheld_kalman", &config, &error)) << error;
  EXPECT_TRUE(config.IsValid(&error)) << error;
  ASSERT_TRUE(SetConfigValue("hk_update_interval", "0", &config, &error)) << error;
  EXPECT_FALSE(config.IsValid(&error));
  EXPECT_NE(error.find("hk_update_interval"), std::string::npos) << error;
  MotionProfile profile;
  EXPECT_TRUE(FromString("rate_table", &profile));
  EXPECT_EQ(profile, MotionProfile::kRateTable);
  EXPECT_FALSE(FromString("spin", &profile));
}

}  // namespace
}  // namespace gravcal
