// Issue 33, physics checks that name the cause: a flipped or swapped
// gyroscope axis (a left-handed fitted matrix), a saturated axis, and the
// chi-square check on the Newton solver path, each on simulated data.
#include "core/sensor_checks.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "gravcal/io/log_reader.h"
#include "gravcal/methods/handheld_kalman.h"
#include "gravcal/methods/twelve_position.h"
#include "gravcal/simulation/handheld_simulator.h"
#include "gravcal/simulation/simulator.h"
#include "gravcal/workflows/config.h"
#include "gravcal/workflows/pipeline.h"
#include "test_util.h"

namespace gravcal {
namespace {

// The index of the first warning containing every one of `parts`, or -1.
int FindWarning(const Calibration& c, const std::vector<std::string>& parts) {
  for (size_t i = 0; i < c.warnings.size(); ++i) {
    bool all = true;
    for (const std::string& p : parts) all = all && c.warnings[i].find(p) != std::string::npos;
    if (all) return static_cast<int>(i);
  }
  return -1;
}

std::string AllWarnings(const Calibration& c) {
  std::string all;
  for (const std::string& w : c.warnings) all += "\n  " + w;
  return all;
}

// A twelve-pose session with hand-like turns, gyroscope calibrated.
struct GyroSession {
  Config config;
  SimulatedSession session;
};

GyroSession MakeGyroSession() {
  GyroSession g;
  g.config.simulation.rotation_profile = RotationProfile::kHand;
  g.config.simulation.hold_seconds = 6.0;
  g.config.simulation.initial_still_seconds = 4.0;
  std::string error;
  EXPECT_TRUE(SetConfigValue("gyro_model", "full", &g.config, &error)) << error;
  EXPECT_TRUE(Simulate(g.config.simulation, 2, &g.session, &error)) << error;
  g.config.calibration.gravity.gravity = g.session.gravity;
  return g;
}

// The gyroscope's x column negated (the opposite sign convention), or its x
// and y columns swapped: the fitted matrix is left-handed and the warning
// names the cause; the session as simulated gets no such warning.
TEST(SensorChecks, FlippedAndSwappedGyroAxesAreNamed) {
  const GyroSession g = MakeGyroSession();
  PipelineInput input;
  input.log = g.session.log;
  Calibration c;
  ASSERT_TRUE(RunCalibration(g.config, input, &c)) << c.message;
  EXPECT_EQ(FindWarning(c, {"left-handed"}), -1) << AllWarnings(c);

  input.log = g.session.log;
  for (Eigen::Vector3d& w : input.log.gyro) w.x() = -w.x();
  ASSERT_TRUE(RunCalibration(g.config, input, &c)) << c.message;
  int i = FindWarning(c, {"gyroscope matrix is left-handed", "raw x axis looks flipped"});
  ASSERT_GE(i, 0) << AllWarnings(c);
  EXPECT_EQ(c.warning_codes[i], WarningCode::kSensorData);

  input.log = g.session.log;
  for (Eigen::Vector3d& w : input.log.gyro) std::swap(w.x(), w.y());
  ASSERT_TRUE(RunCalibration(g.config, input, &c)) << c.message;
  i = FindWarning(c, {"gyroscope matrix is left-handed", "raw x and y axes look swapped"});
  ASSERT_GE(i, 0) << AllWarnings(c);
  EXPECT_EQ(c.warning_codes[i], WarningCode::kSensorData);
}

// The accelerometer's samples in the gyroscope columns: named as such, not
// "did not converge".
TEST(SensorChecks, AccelerometerDataInTheGyroscopeColumnsIsNamed) {
  const GyroSession g = MakeGyroSession();
  PipelineInput input;
  input.log = g.session.log;
  input.log.source = "mixed.csv";
  input.log.gyro = input.log.accel;
  Calibration c;
  EXPECT_FALSE(RunCalibration(g.config, input, &c));
  EXPECT_FALSE(c.not_converged);
  EXPECT_NE(c.message.find("mixed.csv: the gyroscope columns look like accelerometer data"),
            std::string::npos)
      << c.message;
}

// A handheld run whose gyroscope is in deg/s, read as rad/s: the filter runs
// away; refused as diverged (exit 2 in the CLI), not a calibration.
TEST(SensorChecks, HandheldDivergenceIsRefused) {
  SimulatorOptions sensor;
  sensor.raw_counts = false;
  sensor.accel_misalignment_std = 0.0;
  sensor.gyro_misalignment_std = 0.0;
  MotionSession s;
  std::string error;
  ASSERT_TRUE(SimulateMotion(sensor, MotionOptions(), 1, &s, &error)) << error;
  HandheldKalmanOptions options;
  options.gravity.gravity = sensor.gravity;
  Calibration c;
  ASSERT_TRUE(CalibrateHandheld(s.sensor.log, options, &c)) << c.message;
  ImuLog degrees = s.sensor.log;
  for (Eigen::Vector3d& w : degrees.gyro) w *= 180.0 / M_PI;
  EXPECT_FALSE(CalibrateHandheld(degrees, options, &c));
  EXPECT_TRUE(c.not_converged) << c.message;
  EXPECT_NE(c.message.find("diverged"), std::string::npos) << c.message;
  EXPECT_NE(c.message.find("gyro_nominal_scale"), std::string::npos) << c.message;
}

TEST(SensorChecks, HandednessOfAMatrix) {
  const Eigen::Matrix3d m = 1e-3 * Eigen::Matrix3d::Identity();
  EXPECT_EQ(internal::HandednessWarning("gyroscope", m), "");
  Eigen::Matrix3d flipped = m;
  flipped(2, 2) = -flipped(2, 2);
  EXPECT_NE(internal::HandednessWarning("gyroscope", flipped).find("raw z axis looks flipped"),
            std::string::npos);
  Eigen::Matrix3d swapped = m;
  swapped.col(0).swap(swapped.col(2));
  EXPECT_NE(internal::HandednessWarning("accelerometer", swapped)
                .find("accelerometer matrix is left-handed (determinant -1e-09): its raw x and "
                      "z axes look swapped"),
            std::string::npos)
      << internal::HandednessWarning("accelerometer", swapped);
  // All three negated: no single cause.
  EXPECT_NE(internal::HandednessWarning("gyroscope", -m).find("no single flipped axis"),
            std::string::npos);
}

// The accelerometer's x axis clipped at 0.9 g (counts): the +x pose sits at
// the limit. The calibration says which axis is saturated and where, not
// only that the residuals are large; the unclipped session says nothing.
TEST(SensorChecks, SaturatedAxisIsNamed) {
  SimulatorOptions sim;
  sim.hold_seconds = 5.0;
  sim.initial_still_seconds = 5.0;
  SimulatedSession s;
  std::string error;
  ASSERT_TRUE(Simulate(sim, 3, &s, &error)) << error;
  CalibrationOptions options;
  options.gravity.gravity = s.gravity;
  Calibration c;
  ASSERT_TRUE(CalibrateAccelerometer(s.log, options, &c)) << c.message;
  EXPECT_EQ(FindWarning(c, {"saturated"}), -1) << AllWarnings(c);

  ImuLog clipped = s.log;
  const double limit = 0.9 * sim.accel_counts_per_g;
  size_t first = clipped.size();
  for (size_t i = 0; i < clipped.size(); ++i) {
    if (clipped.accel[i].x() > limit) {
      clipped.accel[i].x() = limit;
      first = std::min(first, i);
    }
  }
  ASSERT_LT(first, clipped.size());
  CalibrateAccelerometer(clipped, options, &c);
  const int i = FindWarning(
      c, {"accelerometer x: ", "largest value " + std::to_string(static_cast<int>(limit)),
          "first at sample " + std::to_string(first), "saturated"});
  ASSERT_GE(i, 0) << AllWarnings(c);
  EXPECT_EQ(c.warning_codes[i], WarningCode::kSensorData);

  // Gyroscope clipped at +-20 deg/s during the turns: named too.
  ImuLog fast = s.log;
  const double rate_limit = 20.0 * sim.gyro_counts_per_dps;
  for (Eigen::Vector3d& w : fast.gyro) w = w.cwiseMax(-rate_limit).cwiseMin(rate_limit);
  const std::vector<std::string> warnings = internal::SaturationWarnings(fast);
  ASSERT_FALSE(warnings.empty());
  for (const std::string& w : warnings) {
    EXPECT_EQ(w.rfind("gyroscope ", 0), 0u) << w;
    EXPECT_NE(w.find("saturated"), std::string::npos) << w;
  }
  EXPECT_TRUE(internal::SaturationWarnings(s.log).empty());
}

// One disturbed pose (0.05 m/s^2 off gravity, 100 times its noise): the
// Newton solver reports the chi-square check as the Ceres path does.
TEST(SensorChecks, NewtonReportsTheChiSquareCheck) {
  std::mt19937_64 rng(9);
  AccelModel truth;
  truth.bias = Eigen::Vector3d(30.0, -20.0, 50.0);
  truth.upper = testing_util::kCountScale * Eigen::Matrix3d::Identity();
  std::vector<Position> positions = testing_util::MakePositions(
      truth, testing_util::TwelveDirections(), kStandardGravity, 0.02, 0.02, 1000, true, &rng);
  positions[3].raw_mean *= 1.0 + 0.05 / kStandardGravity;
  for (RefinementSolver solver : {RefinementSolver::kCeres, RefinementSolver::kNewton}) {
    SCOPED_TRACE(ToString(solver));
    CalibrationOptions options;
    options.solver = solver;
    options.gravity.gravity = kStandardGravity;
    options.nominal_scale = testing_util::kCountScale;
    Calibration c;
    ASSERT_TRUE(CalibrateFromPositions(positions, options, &c)) << c.message;
    const int i = FindWarning(c, {"times the noise level", "chi2"});
    ASSERT_GE(i, 0) << AllWarnings(c);
    EXPECT_EQ(c.warning_codes[i], WarningCode::kResidualsAboveNoise);
  }
}

// The gyroscope's axis convention checked against the accelerometer's from
// the turns alone (no gyroscope model fitted: gyro_model none, as for a
// hand-held log): a flipped x or swapped x and y is named for every method;
// the session as simulated gets no such warning.
TEST(SensorChecks, GyroAxisConventionNamedWithoutAGyroscopeFit) {
  GyroSession g = MakeGyroSession();
  std::string error;
  ASSERT_TRUE(SetConfigValue("gyro_model", "none", &g.config, &error)) << error;
  const std::string kCheck = "the gyroscope's axes disagree with the accelerometer's";
  PipelineInput input;
  input.log = g.session.log;
  Calibration c;
  ASSERT_TRUE(RunCalibration(g.config, input, &c)) << c.message;
  EXPECT_EQ(FindWarning(c, {kCheck}), -1) << AllWarnings(c);
  EXPECT_EQ(internal::GyroAxisConventionWarning(g.session.log), "");

  for (int change = 0; change < 3; ++change) {
    input.log = g.session.log;
    for (Eigen::Vector3d& w : input.log.gyro) {
      if (change == 0) w.x() = -w.x();
      if (change == 1) std::swap(w.x(), w.y());
      if (change == 2) w.z() = -w.z();
    }
    ASSERT_TRUE(RunCalibration(g.config, input, &c)) << c.message;
    const char* cause[3] = {"raw x axis looks flipped", "raw x and y axes look swapped",
                            "raw z axis looks flipped"};
    const int i = FindWarning(c, {kCheck, cause[change]});
    ASSERT_GE(i, 0) << change << AllWarnings(c);
    EXPECT_EQ(c.warning_codes[i], WarningCode::kSensorData);
  }
}

// The real logs (skipped without ../shared/data/real). The sunsided
// MPU-6050 hand-held logs' README says only their gyroscope x axis has the
// opposite sign convention. The data say x and y: fitted one axis at a
// time, the rates of full_sphere.csv enter with signs -, -, + (gains -1.00,
// -0.95, +1.04), x alone explains 42 % of the turning against 86 % for x and
// y, and the columns as given 0 %; roll_and_tilt_45_90.csv (set 2 too) gives
// -1.02, -1.02 and a barely turned z. The dataset author's own set-2 filter
// scripts negate gyroscope x and y before integrating. tilt_sphere.csv (set
// 1, accelerometer reading the up vector) fits as given. The other real logs
// with a gyroscope get no warning.
TEST(SensorChecks, GyroAxisConventionOnTheRealLogs) {
  if (testing_util::RealDataDir().empty()) GTEST_SKIP() << "../shared/data/real is not there";
  struct Log {
    const char* config;
    const char* file;
    const char* expected;  // nullptr: no warning
  };
  const Log logs[] = {
      {nullptr, "sunsided_mpu6050/full_sphere.csv",
       "raw x and y axes both look flipped (a half turn about z against the accelerometer's "
       "axes). Fitted one by one, the raw axes' rates enter as x -1, y -0.95 and z +1.04"},
      {nullptr, "sunsided_mpu6050/roll_and_tilt_45_90.csv",
       "raw x and y axes both look flipped (a half turn about z against the accelerometer's "
       "axes). Fitted one by one, the raw axes' rates enter as x -1.02, y -1.02 and z +0.96 "
       "(barely turned about"},
      {nullptr, "sunsided_mpu6050/tilt_sphere.csv", nullptr},
      {nullptr, "sunsided_mpu6050/still_10min.csv", nullptr},
      {"ahrs_static_poses.yaml", "ahrs_static_poses/imu_good2.txt", nullptr},
      {"mpu6050_ten_pose.yaml", "mpu6050_ten_pose/session.csv", nullptr},
      {"ferraris_nilspod.yaml", "ferraris_nilspod/session.csv", nullptr},
  };
  for (const Log& l : logs) {
    Config config;
    ImuLog log;
    std::string error;
    if (l.config != nullptr) {
      ASSERT_TRUE(testing_util::LoadRealSession(l.config, l.file, &config, &log, &error)) << error;
    } else {
      ASSERT_TRUE(
          ReadImuLog(testing_util::RealDataDir() + "/" + l.file, config.input, &log, &error))
          << error;
    }
    const std::string w = internal::GyroAxisConventionWarning(log);
    std::printf("%s: %s\n", l.file, w.empty() ? "(no warning)" : w.c_str());
    if (l.expected == nullptr) {
      EXPECT_EQ(w, "") << l.file;
    } else {
      EXPECT_NE(w.find(l.expected), std::string::npos) << l.file << ": " << w;
    }
  }
}

}  // namespace
}  // namespace gravcal
