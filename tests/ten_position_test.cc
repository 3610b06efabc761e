// Ten-position (patent) calibration: what the self-aligned method recovers
// (bias, scale, non-orthogonality in the sensor frame) with honest sigmas,
// and what it cannot (the off-diagonal of K as elements: null std, warning).
#include "gravcal/methods/ten_position.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "gravcal/io/log_reader.h"
#include "gravcal/simulation/simulator.h"
#include "gravcal/workflows/config.h"
#include "gravcal/workflows/pipeline.h"
#include "sigma_check.h"
#include "test_util.h"

namespace gravcal {
namespace {

SimulatorOptions TenPositions() {
  SimulatorOptions sim;
  sim.scheme = {PoseScheme::kTen};
  sim.hold_seconds = 8.0;
  sim.initial_still_seconds = 2.0;
  sim.rotation_seconds = 2.0;
  return sim;
}

Config TenPositionConfig(const SimulatedSession& s) {
  Config config;
  std::string error;
  EXPECT_TRUE(
      LoadConfigFile(testing_util::SourceDir() + "/configs/ten_position.yaml", &config, &error))
      << error;
  config.calibration.gravity.gravity = s.gravity;
  return config;
}

TEST(TenPosition, SchemeHasTenDifferentRollPitchPoses) {
  std::vector<Eigen::Quaterniond> attitudes;
  std::vector<int> up;
  std::string error;
  ASSERT_TRUE(SchemeAttitudes({PoseScheme::kTen}, 1, &attitudes, &up, &error)) << error;
  ASSERT_EQ(attitudes.size(), 10u);
  // Ten different gravity directions in the body frame, not all in a plane.
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < attitudes.size(); ++i) {
    const Eigen::Vector3d gi = attitudes[i].conjugate() * Eigen::Vector3d::UnitZ();
    scatter += gi * gi.transpose();
    for (size_t j = 0; j < i; ++j) {
      const Eigen::Vector3d gj = attitudes[j].conjugate() * Eigen::Vector3d::UnitZ();
      EXPECT_LT(gi.dot(gj), std::cos(30.0 * M_PI / 180.0)) << i << " " << j;
    }
  }
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvalues().minCoeff(), 1.0);
}

// Per parameter over 40 seeds (sigmas twice too large fail SigmaCheck's
// band from 30 seeds on): bias and scale of each axis, and the three
// non-orthogonality terms of U in the sensor frame.
TEST(TenPosition, RecoversBiasAndScaleWithHonestSigmas) {
  const SimulatorOptions sim = TenPositions();
  const int seeds = 40;
  testing_util::SigmaCheck check;
  for (int seed = 1; seed <= seeds; ++seed) {
    SimulatedSession s;
    std::string error;
    ASSERT_TRUE(Simulate(sim, seed, &s, &error)) << error;
    PipelineInput input;
    input.log = s.log;
    Calibration c;
    ASSERT_TRUE(RunCalibration(TenPositionConfig(s), input, &c)) << c.message;
    EXPECT_EQ(c.method, "ten_position");
    ASSERT_EQ(c.positions.size(), 10u);
    // The estimate is K = R_K U_K; U_K is what the magnitude determines.
    const AccelModel& est = c.accel.model;
    testing_util::AddEach(&check, "bias", est.bias - s.accel_truth.bias, c.accel.bias_std);
    testing_util::AddEach(&check, "scale", est.upper.diagonal() - s.accel_truth.upper.diagonal(),
                          c.accel.matrix_std.diagonal());
    // Non-orthogonality in the sensor frame, from the step-4 covariance.
    const std::vector<std::string>& names = c.accel.covariance_names;
    for (const char* name : {"u_xy", "u_xz", "u_yz"}) {
      const int at = static_cast<int>(std::find(names.begin(), names.end(), name) - names.begin());
      ASSERT_LT(at, static_cast<int>(names.size()));
      const int r = name[2] - 'x', col = name[3] - 'x';
      check.Add(name, c.refinement.model.upper(r, col) - s.accel_truth.upper(r, col),
                std::sqrt(c.accel.covariance(at, at)));
    }
    // The off-diagonal of K is not determined: null, and said so.
    for (int r = 0; r < 3; ++r) {
      for (int col = 0; col < 3; ++col) {
        EXPECT_EQ(std::isnan(c.accel.matrix_std(r, col)), r != col);
      }
    }
    bool warned = false;
    for (const std::string& w : c.warnings) warned |= w.find("not determined") != std::string::npos;
    EXPECT_TRUE(warned);
  }
  EXPECT_EQ(check.Names().size(), 9u);
  std::printf("%s", check.Table().c_str());
  check.ExpectHonest("ten_position");
}

// The real MPU-6050 session of ten hand-held poses (skips when the data is
// absent): the method runs on it, the calibrated |a| is g to 1 mm/s^2 in
// every pose, and its bias agrees with the twelve-position refinement's (the
// same magnitude information) within their sigmas.
TEST(TenPosition, RealMpu6050TenPoses) {
  const std::string dir = testing_util::RealDataDir();
  if (dir.empty()) GTEST_SKIP() << "no real data folder";
  Config config;
  PipelineInput input;
  input.source = dir + "/mpu6050_ten_pose/session.csv";
  std::string error;
  ASSERT_TRUE(testing_util::LoadRealSession("mpu6050_ten_pose.yaml", "mpu6050_ten_pose/session.csv",
                                            &config, &input.log, &error))
      << error;
  Calibration twelve;
  ASSERT_TRUE(RunCalibration(config, input, &twelve)) << twelve.message;
  config.method = Method::kTenPosition;
  config.ten_position.gyro_nominal_scale = M_PI / 180.0 / 131.0;
  // The twelve-position config's nominal_scale: ten_position does not read it
  // (it scales by the data), so it would be an unused-key error.
  config.keys_set.erase(
      std::remove(config.keys_set.begin(), config.keys_set.end(), "nominal_scale"),
      config.keys_set.end());
  Calibration ten;
  ASSERT_TRUE(RunCalibration(config, input, &ten)) << ten.message;
  ASSERT_EQ(ten.positions.size(), 10u);
  // The ten poses do not determine u_xy: it is held at zero, which leaves
  // two residual degrees of freedom instead of one, and the residuals are
  // the poses' own scatter (measured up to 2.2e-3 m/s^2; before the hold,
  // the near-exact fit left them below 1e-3).
  for (const PositionReport& r : ten.positions) {
    EXPECT_LT(std::fabs(r.residual_after), 3e-3);
    EXPECT_TRUE(std::isfinite(r.roll_deg));
  }
  for (int i = 0; i < 3; ++i) {
    const double sigma = std::hypot(ten.accel.bias_std(i), twelve.accel.bias_std(i));
    if (!std::isfinite(sigma)) continue;
    EXPECT_LT(std::fabs(ten.accel.model.bias(i) - twelve.accel.model.bias(i)), 3.0 * sigma) << i;
  }
}

TEST(TenPosition, RejectsTooFewPositions) {
  SimulatorOptions sim = TenPositions();
  sim.scheme = {PoseScheme::kRandom, 4};
  SimulatedSession s;
  std::string error;
  ASSERT_TRUE(Simulate(sim, 1, &s, &error)) << error;
  PipelineInput input;
  input.log = s.log;
  Calibration c;
  EXPECT_FALSE(RunCalibration(TenPositionConfig(s), input, &c));
  EXPECT_NE(c.message.find("needs at least 6"), std::string::npos) << c.message;
}

TEST(TenPosition, InvalidOptionsNameTheKey) {
  Config config;
  config.method = Method::kTenPosition;
  config.ten_position.gyro_nominal_scale = -1.0;
  std::string error;
  EXPECT_FALSE(config.IsValid(&error));
  EXPECT_NE(error.find("gyro_nominal_scale"), std::string::npos) << error;
  std::string text_error;
  EXPECT_FALSE(SetConfigValue("align_accel_bias_std", "0", &config, &text_error) &&
               config.IsValid(&text_error));
  EXPECT_NE(text_error.find("align_accel_bias_std"), std::string::npos) << text_error;
}

}  // namespace
}  // namespace gravcal
