#include "gravcal/methods/rate_table.h"

#include <gtest/gtest.h>

#include <cmath>

#include "gravcal/simulation/handheld_simulator.h"

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

TEST(RateTable, RecoversGyroBiasAndMatrix) {
  double sum_z2 = 0.0;
  int count = 0;
  for (uint64_t seed = 1; seed <= 10; ++seed) {
    const MotionSession s = RateTableSession(seed);
    ASSERT_EQ(s.segments.size(), 6u);
    RateTableResult r;
    ASSERT_TRUE(CalibrateRateTable(s.sensor.log, s.segments, &r)) << r.message;
    const GyroModel& truth = s.sensor.gyro_truth;
    for (int i = 0; i < 3; ++i) {
      const double zb = (r.gyro.model.bias(i) - truth.bias(i)) / r.gyro.bias_std(i);
      EXPECT_LT(std::fabs(zb), 4.0) << "seed " << seed << " bias " << i;
      sum_z2 += zb * zb;
      ++count;
      for (int k = 0; k < 3; ++k) {
        const double zm =
            (r.gyro.model.matrix(i, k) - truth.matrix(i, k)) / r.gyro.matrix_std(i, k);
        EXPECT_LT(std::fabs(zm), 4.0) << "seed " << seed << " matrix " << i << k;
        sum_z2 += zm * zm;
        ++count;
      }
      // Scale to better than 0.1 % at 60 deg/s for 20 s per direction.
      EXPECT_NEAR(r.gyro.model.matrix(i, i) / truth.matrix(i, i), 1.0, 1e-3);
    }
    for (double n : r.normalized_residuals) EXPECT_LT(n, 5.0);
  }
  const double rms = std::sqrt(sum_z2 / count);
  EXPECT_GT(rms, 0.6);
  EXPECT_LT(rms, 1.5);
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
