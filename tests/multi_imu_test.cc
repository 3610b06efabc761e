// Tests of the multi-IMU calibration (methods/multi_imu.h) on simulated
// plates (simulation/plate_simulator.h): rotations, intrinsics and time
// offsets honest against the truth, the gain of the joint fit, the checks
// that name a permuted unit, a unit that moved and a drifting clock, and a
// single level pose.
#include "gravcal/methods/multi_imu.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
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
  o.imu.scheme = "twelve";
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

}  // namespace
}  // namespace gravcal
