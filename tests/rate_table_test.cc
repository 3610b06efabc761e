#include "gravcal/methods/rate_table.h"

#include <gtest/gtest.h>

#include <cmath>

#include "gravcal/simulation/handheld_simulator.h"
#include "sigma_check.h"
#include "test_util.h"

namespace gravcal {
namespace {

// A rate-table session in raw counts with a full (misaligned) gyroscope.
MotionSession RateTableSession(uint64_t seed) {
  SimulatorOptions sensor;
  MotionOptions motion;
  motion.profile = MotionProfile::kRateTable;
  motion.rate_dps = 60.0;
  motion.seconds_per_axis = 20.0;
  MotionSession s;
  std::string error;
  EXPECT_TRUE(SimulateMotion(sensor, motion, seed, &s, &error)) << error;
  return s;
}

// Every one of the 12 parameters on its own, over enough seeds that sigmas
// twice too large or too small fail (SigmaCheck's band).
TEST(RateTable, RecoversGyroBiasAndMatrix) {
  testing_util::SigmaCheck check;
  for (uint64_t seed = 1; seed <= 40; ++seed) {
    const MotionSession s = RateTableSession(seed);
    ASSERT_EQ(s.segments.size(), 6u);
    RateTableResult r;
    ASSERT_TRUE(CalibrateRateTable(s.sensor.log, s.segments, &r)) << r.message;
    const GyroModel& truth = s.sensor.gyro_truth;
    testing_util::AddEach(&check, "bias", r.gyro.model.bias - truth.bias, r.gyro.bias_std);
    testing_util::AddEach(&check, "matrix", r.gyro.model.matrix - truth.matrix, r.gyro.matrix_std);
    for (int i = 0; i < 3; ++i) {
      // Scale to better than 0.1 % at 60 deg/s for 20 s per direction.
      EXPECT_NEAR(r.gyro.model.matrix(i, i) / truth.matrix(i, i), 1.0, 1e-3);
    }
    for (double n : r.normalized_residuals) EXPECT_LT(n, 5.0);
  }
  check.ExpectHonest("rate table");
}

TEST(RateTable, NeedsRatesAboutThreeAxes) {
  const MotionSession s = RateTableSession(1);
  RateTableResult r;
  std::vector<RateTableSegment> few(s.segments.begin(), s.segments.begin() + 3);
  EXPECT_FALSE(CalibrateRateTable(s.sensor.log, few, &r));
  EXPECT_NE(r.message.find("at least 4"), std::string::npos) << r.message;
  // x and y only: z's column of A is not determined.
  std::vector<RateTableSegment> two_axes(s.segments.begin(), s.segments.begin() + 4);
  EXPECT_FALSE(CalibrateRateTable(s.sensor.log, two_axes, &r));
  EXPECT_NE(r.message.find("do not determine"), std::string::npos) << r.message;
  std::vector<RateTableSegment> outside = s.segments;
  outside[2].end = s.sensor.log.size() + 5;
  EXPECT_FALSE(CalibrateRateTable(s.sensor.log, outside, &r));
  EXPECT_NE(r.message.find("segment 2"), std::string::npos) << r.message;
  ImuLog no_gyro = s.sensor.log;
  no_gyro.gyro.clear();
  EXPECT_FALSE(CalibrateRateTable(no_gyro, s.segments, &r));
}

}  // namespace
}  // namespace gravcal
