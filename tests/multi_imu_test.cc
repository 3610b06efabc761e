// Tests of the multi-IMU calibration (methods/multi_imu.h) on simulated
// plates (simulation/plate_simulator.h): rotations, intrinsics and time
// offsets honest against the truth, the gain of the joint fit, the checks
// that name a permuted unit, a unit that moved and a drifting clock, and a
// single level pose.
#include "gravcal/methods/multi_imu.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "gravcal/simulation/plate_simulator.h"

namespace gravcal {
namespace {

PlateSimulatorOptions PlateOptions(int imus) {
  PlateSimulatorOptions o;
  o.imus = imus;
  o.imu.scheme = {PoseScheme::kTwelve};
  o.imu.hold_seconds = 4.0;
  o.imu.initial_still_seconds = 4.0;
  o.imu.rotation_seconds = 2.0;
  o.oversample = 4;
  return o;
}

std::vector<PlateImu> PlateImus(const SimulatedPlate& plate) {
  std::vector<PlateImu> imus;
  for (size_t i = 0; i < plate.logs.size(); ++i) {
    PlateImu imu;
    imu.name = plate.truth[i].name;
    imu.log = plate.logs[i];
    imu.accel_scale = 1.0 / plate.truth[i].accel_units_per_si;
    imu.gyro_scale = 1.0 / plate.truth[i].gyro_units_per_si;
    imu.stated_mounting = plate.truth[i].stated_mounting;
    imus.push_back(imu);
  }
  return imus;
}

MultiImuOptions Options(const SimulatedPlate& plate) {
  MultiImuOptions o;
  o.gravity = plate.gravity;
  return o;
}

// z-scores of one IMU against the truth: b (3), U (6), b_g (3), M_g (9),
// rotation (3).
void ZScores(const SimulatedPlate& plate, const MultiImuResult& result, int i,
             std::vector<double>* z) {
  const PlateImuResult& r = result.imus[i];
  const PlateImuTruth& t = plate.truth[i];
  const Calibration& c = r.calibration;
  for (int j = 0; j < 3; ++j) {
    z->push_back((c.accel.model.bias[j] - t.accel.bias[j]) / c.accel.bias_std[j]);
  }
  const int rc[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};
  for (const auto& e : rc) {
    z->push_back((c.accel.model.upper(e[0], e[1]) - t.accel.upper(e[0], e[1])) /
                 c.accel.matrix_std(e[0], e[1]));
  }
  const Eigen::Matrix3d mg = PlateTruthGyroMatrix(plate, i);
  for (int j = 0; j < 3; ++j) {
    z->push_back((c.gyro.model.bias[j] - t.gyro.bias[j]) / c.gyro.bias_std[j]);
  }
  for (int k = 0; k < 9; ++k) {
    z->push_back((c.gyro.model.matrix(k / 3, k % 3) - mg(k / 3, k % 3)) /
                 c.gyro.matrix_std(k / 3, k % 3));
  }
  if (i != result.reference) {
    // C = C_hat Exp(e): e = log(C_hat^T C_true).
    const Eigen::AngleAxisd aa(r.rotation.transpose() * PlateTruthRotation(plate, i));
    const Eigen::Vector3d e = aa.angle() * aa.axis();
    for (int j = 0; j < 3; ++j) z->push_back(e[j] / r.rotation_std[j]);
  }
}

double Rms(const std::vector<double>& z) {
  double s = 0.0;
  for (double x : z) s += x * x;
  return std::sqrt(s / z.size());
}

TEST(MultiImu, PlatesOfTwoThreeAndEightAreHonest) {
  std::vector<double> z, zt;
  for (int imus : {2, 3, 8}) {
    for (uint64_t seed = 1; seed <= (imus == 8 ? 1u : 3u); ++seed) {
      PlateSimulatorOptions o = PlateOptions(imus);
      o.permuted_imu = imus - 1;
      SimulatedPlate plate;
      std::string error;
      ASSERT_TRUE(SimulatePlate(o, seed, &plate, &error)) << error;
      MultiImuResult result;
      ASSERT_TRUE(CalibrateMultiImu(PlateImus(plate), Options(plate), &result)) << result.message;
      for (int i = 0; i < imus; ++i) ZScores(plate, result, i, &z);
      bool named = false;
      for (const std::string& w : result.warnings) {
        std::printf("  %s\n", w.c_str());
        named = named || w.find(plate.truth[imus - 1].name + " looks rotated 90 degrees about z") !=
                             std::string::npos;
      }
      EXPECT_TRUE(named) << "the permuted unit is not named, seed " << seed;
      for (int i = 1; i < imus; ++i) {
        const PlateImuResult& r = result.imus[i];
        const double truth = plate.truth[i].clock_offset;
        zt.push_back((r.time_offset - truth) / r.time_offset_std);
        std::printf(
            "imus %d seed %llu %s: offset %.5f +- %.5f truth %.5f; sep/joint u_xy %.3g/%.3g\n",
            imus, static_cast<unsigned long long>(seed), r.name.c_str(), r.time_offset,
            r.time_offset_std, truth, r.separate_std[4], r.joint_std[4]);
      }
    }
  }
  std::printf("rms z intrinsics+rotations %.3f (%zu), time offsets %.3f (%zu)\n", Rms(z), z.size(),
              Rms(zt), zt.size());
  EXPECT_GT(Rms(z), 0.7);
  EXPECT_LT(Rms(z), 1.4);
  EXPECT_LT(Rms(zt), 1.4);
}

bool Named(const MultiImuResult& result, const std::string& text) {
  for (const std::string& w : result.warnings) {
    if (w.find(text) != std::string::npos) return true;
  }
  return false;
}

TEST(MultiImu, JointSigmasAreNoLargerThanSeparate) {
  PlateSimulatorOptions o = PlateOptions(3);
  SimulatedPlate plate;
  std::string error;
  ASSERT_TRUE(SimulatePlate(o, 11, &plate, &error)) << error;
  MultiImuResult result;
  ASSERT_TRUE(CalibrateMultiImu(PlateImus(plate), Options(plate), &result)) << result.message;
  for (const PlateImuResult& r : result.imus) {
    ASSERT_EQ(r.separate_std.size(), 21u);
    double gain = 0.0;
    for (int k = 0; k < 21; ++k) {
      EXPECT_LE(r.joint_std[k], r.separate_std[k] * 1.001) << r.name << " parameter " << k;
      gain = std::max(gain, r.separate_std[k] / r.joint_std[k]);
    }
    // The shared poses let the direction of each pose constrain the
    // accelerometer: some sigma shrinks markedly.
    EXPECT_GT(gain, 1.2) << r.name;
  }
}

TEST(MultiImu, UnitThatMovedIsNamedAndItsRotationSplit) {
  PlateSimulatorOptions o = PlateOptions(3);
  o.slip_imu = 1;
  o.slip_turn = 5;
  o.slip_deg = 2.0;
  SimulatedPlate plate;
  std::string error;
  ASSERT_TRUE(SimulatePlate(o, 5, &plate, &error)) << error;
  MultiImuResult result;
  ASSERT_TRUE(CalibrateMultiImu(PlateImus(plate), Options(plate), &result)) << result.message;
  EXPECT_TRUE(Named(result, "imu1 moved on the plate"))
      << ::testing::PrintToString(result.warnings);
  EXPECT_TRUE(Named(result, "between pose 5 and pose 6"))
      << ::testing::PrintToString(result.warnings);
  EXPECT_FALSE(Named(result, "imu2 moved"));
  // Its starting rotation is still right (z-scores of the rotation).
  std::vector<double> z;
  ZScores(plate, result, 1, &z);
  for (int j = 21; j < 24; ++j) EXPECT_LT(std::abs(z[j]), 4.0) << j;
  // A plate without a slip names none.
  o.slip_imu = -1;
  ASSERT_TRUE(SimulatePlate(o, 5, &plate, &error)) << error;
  ASSERT_TRUE(CalibrateMultiImu(PlateImus(plate), Options(plate), &result)) << result.message;
  EXPECT_FALSE(Named(result, "moved")) << ::testing::PrintToString(result.warnings);
}

TEST(MultiImu, FlippedAxisIsNamed) {
  PlateSimulatorOptions o = PlateOptions(3);
  o.flipped_imu = 1;
  o.flipped_axis = 1;
  SimulatedPlate plate;
  std::string error;
  ASSERT_TRUE(SimulatePlate(o, 9, &plate, &error)) << error;
  MultiImuResult result;
  ASSERT_TRUE(CalibrateMultiImu(PlateImus(plate), Options(plate), &result)) << result.message;
  EXPECT_TRUE(Named(result, "imu1's y accelerometer axis reads with the wrong sign"))
      << ::testing::PrintToString(result.warnings);
  EXPECT_FALSE(Named(result, "imu2's"));
  // The fit holds: its pose rows at the level of the others'.
  EXPECT_LT(result.imus[1].accel_residual_rms, 3.0 * result.imus[2].accel_residual_rms);
}

TEST(MultiImu, DriftingClockIsNamed) {
  PlateSimulatorOptions o = PlateOptions(2);
  o.clock_drift_std = 5e-4;  // 500 ppm: 50 ms over the session
  SimulatedPlate plate;
  std::string error;
  ASSERT_TRUE(SimulatePlate(o, 3, &plate, &error)) << error;
  MultiImuResult result;
  ASSERT_TRUE(CalibrateMultiImu(PlateImus(plate), Options(plate), &result)) << result.message;
  EXPECT_TRUE(Named(result, "imu1's clock drifts")) << ::testing::PrintToString(result.warnings);
  const PlateImuResult& r = result.imus[1];
  EXPECT_NEAR(r.clock_drift, plate.truth[1].clock_drift, 4.0 * r.clock_drift_std);
  EXPECT_NEAR(r.time_offset, plate.truth[1].clock_offset, 4.0 * r.time_offset_std);
  // No drift: none named.
  o.clock_drift_std = 0.0;
  ASSERT_TRUE(SimulatePlate(o, 3, &plate, &error)) << error;
  ASSERT_TRUE(CalibrateMultiImu(PlateImus(plate), Options(plate), &result)) << result.message;
  EXPECT_FALSE(Named(result, "drifts")) << ::testing::PrintToString(result.warnings);
}

TEST(MultiImu, OneLevelPoseGivesOffsetsAlongGravityOnly) {
  PlateSimulatorOptions o = PlateOptions(4);
  o.mounting = PlateMounting::kAligned;
  o.imu.scheme = {PoseScheme::kRandom, 1};
  o.imu.hold_seconds = 20.0;
  o.imu.initial_still_seconds = 20.0;
  SimulatedPlate plate;
  std::string error;
  ASSERT_TRUE(SimulatePlate(o, 2, &plate, &error)) << error;
  MultiImuResult result;
  ASSERT_TRUE(CalibrateMultiImu(PlateImus(plate), Options(plate), &result)) << result.message;
  EXPECT_EQ(result.poses, 1);
  for (size_t i = 0; i < plate.truth.size(); ++i) {
    const PlateImuResult& r = result.imus[i];
    // Truth: the nominal-scale magnitude of the noise-free reading minus g.
    const Eigen::Vector3d f =
        plate.truth[i].mounting_start.transpose() *
        (plate.poses[0].attitude.conjugate() * Eigen::Vector3d(0, 0, plate.gravity));
    const Eigen::Vector3d v = plate.truth[i].accel.Invert(f);
    const double truth = v.norm() / plate.truth[i].accel_units_per_si - plate.gravity;
    EXPECT_NEAR(r.up_offset, truth, 4.0 * r.up_offset_std) << r.name;
    EXPECT_GT(r.up_offset_std, 0.0);
    EXPECT_TRUE(std::isnan(r.calibration.accel.bias_std[0])) << "bias must be undetermined";
    for (double s : r.joint_std) EXPECT_TRUE(std::isnan(s));
    EXPECT_TRUE(std::isnan(r.time_offset));
  }
  ASSERT_GE(result.undetermined.size(), 2u);
  EXPECT_NE(result.undetermined[0].find("not determined"), std::string::npos);
}

TEST(MultiImu, BadInputIsRefused) {
  MultiImuResult result;
  EXPECT_FALSE(CalibrateMultiImu({}, MultiImuOptions(), &result));
  EXPECT_NE(result.message.find("no IMUs"), std::string::npos);
  PlateImu a;
  a.name = "a";
  a.log.t = {0.0, 0.0};
  a.log.accel = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  EXPECT_FALSE(CalibrateMultiImu({a, a}, MultiImuOptions(), &result));
  EXPECT_NE(result.message.find("given twice"), std::string::npos);
  EXPECT_FALSE(CalibrateMultiImu({a}, MultiImuOptions(), &result));
  EXPECT_NE(result.message.find("a: "), std::string::npos) << result.message;
}

TEST(MultiImu, AxisRotationsAreDescribed) {
  double angle = 0.0;
  const Eigen::Matrix3d z90 =
      Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Matrix3d p = NearestAxisRotation(
      z90 * Eigen::AngleAxisd(0.02, Eigen::Vector3d::UnitX()).toRotationMatrix(), &angle);
  EXPECT_TRUE(p.isApprox(z90, 1e-12));
  EXPECT_NEAR(angle, 0.02 * 180 / M_PI, 1e-6);
  EXPECT_EQ(DescribeAxisRotation(z90), "rotated 90 degrees about z");
  EXPECT_EQ(DescribeAxisRotation(z90.transpose()), "rotated 90 degrees about -z");
  EXPECT_EQ(
      DescribeAxisRotation(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix()),
      "rotated 180 degrees about x");
}

// Hand-like turns (irregular rate, wobbling axis) and a table in SI units
// read with the shipped config's units (counts): the gyroscope starts from
// the turns' scale, the accelerometer from the ellipsoid; still honest.
TEST(MultiImu, HandTurnsAndSiUnitsStayHonest) {
  for (int mode = 0; mode < 2; ++mode) {
    std::vector<double> z, zt;
    for (uint64_t seed = 1; seed <= 4; ++seed) {
      PlateSimulatorOptions o = PlateOptions(3);
      o.permuted_imu = 2;
      if (mode == 0) o.imu.rotation_profile = RotationProfile::kHand;
      if (mode == 1) o.imu.raw_counts = false;
      SimulatedPlate plate;
      std::string error;
      ASSERT_TRUE(SimulatePlate(o, seed, &plate, &error)) << error;
      std::vector<PlateImu> imus = PlateImus(plate);
      for (PlateImu& i : imus) {
        i.accel_scale = 9.80665 / 16384.0;
        i.gyro_scale = M_PI / 180.0 / 131.0;
      }
      MultiImuResult result;
      ASSERT_TRUE(CalibrateMultiImu(imus, Options(plate), &result)) << result.message;
      EXPECT_TRUE(Named(result, "imu2 looks rotated 90 degrees about z")) << seed;
      for (int i = 0; i < 3; ++i) ZScores(plate, result, i, &z);
      for (int i = 1; i < 3; ++i) {
        zt.push_back((result.imus[i].time_offset - plate.truth[i].clock_offset) /
                     result.imus[i].time_offset_std);
      }
    }
    std::printf("mode %d: rms z %.3f (%zu), offsets %.3f (%zu)\n", mode, Rms(z), z.size(), Rms(zt),
                zt.size());
    EXPECT_GT(Rms(z), 0.7) << mode;
    EXPECT_LT(Rms(z), 1.4) << mode;
    EXPECT_LT(Rms(zt), 2.0) << mode;
  }
}

}  // namespace
}  // namespace gravcal
