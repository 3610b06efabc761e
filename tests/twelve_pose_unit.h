// A unit calibrated in process from simulated pose means: twelve poses
// (test_util.h MakePositions: each tilted by 0.01 rad, 100 samples of
// 0.01 m/s^2 white noise, the exact noise of the mean), the twelve-position
// fit at standard gravity. Hundreds of them take about a second (compare,
// verify, the store's history and the acceptance limits use them).
#ifndef GRAVCAL_TESTS_TWELVE_POSE_UNIT_H_
#define GRAVCAL_TESTS_TWELVE_POSE_UNIT_H_

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "gravcal/methods/twelve_position.h"
#include "test_util.h"

namespace gravcal {
namespace testing_util {

inline Calibration CalibrateTwelvePoseUnit(const AccelModel& truth, uint64_t seed) {
  std::mt19937_64 rng(seed);
  const std::vector<Position> positions =
      MakePositions(truth, TwelveDirections(), kStandardGravity, 0.01, 0.01, 100, true, &rng);
  CalibrationOptions options;
  options.gravity.gravity = kStandardGravity;
  Calibration c;
  EXPECT_TRUE(CalibrateFromPositions(positions, options, &c)) << c.message;
  return c;
}

}  // namespace testing_util
}  // namespace gravcal

#endif  // GRAVCAL_TESTS_TWELVE_POSE_UNIT_H_
