// The covariance of a pose's mean (pose_mean_covariance.h): the noise
// model's Allan variance at the pose's duration in raw units, the
// batch-means estimate on white noise (its mean is nu / (nu - 2) times the
// truth, by design) and on a random walk (it sees what C / n misses), and
// the fallbacks.
#include "gravcal/estimation/pose_mean_covariance.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "gravcal/core/gravity.h"
#include "gravcal/simulation/noise_process.h"

namespace gravcal {
namespace {

constexpr double kSampleRate = 100.0;
// Raw units: counts of 1/1000 g.
constexpr double kScale = kStandardGravity / 1000.0;

// One pose of `seconds`, gravity on z, noise `o` (SI) on every axis, in
// counts; the interval and the white-noise position.
void Pose(const NoiseProcessOptions& o, uint64_t seed, double seconds, ImuLog* log,
          std::vector<StaticInterval>* intervals,
          const Eigen::Vector3d& up = Eigen::Vector3d::UnitZ(), double offset = 0.0) {
  const size_t n = static_cast<size_t>(seconds * kSampleRate);
  const size_t begin = log->size();
  StaticInterval s;
  s.begin = begin;
  s.end = begin + n;
  std::vector<NoiseProcess> axes;
  for (int a = 0; a < 3; ++a) axes.emplace_back(o, seed * 4 + a);
  for (size_t i = 0; i < n; ++i) {
    log->t.push_back((begin + i) / kSampleRate);
    Eigen::Vector3d v = kStandardGravity * up;
    for (int a = 0; a < 3; ++a) v[a] += axes[a].Next();
    log->accel.push_back(v / kScale + Eigen::Vector3d::Constant(offset));
    s.accel_mean += log->accel.back() / static_cast<double>(n);
  }
  for (size_t i = s.begin; i < s.end; ++i) {
    const Eigen::Vector3d d = log->accel[i] - s.accel_mean;
    s.accel_cov += d * d.transpose() / static_cast<double>(n - 1);
  }
  s.t_begin = log->t[s.begin];
  s.t_end = log->t[s.end - 1];
  intervals->push_back(s);
}

TEST(PoseMeanCovariance, ModelGivesItsAllanVarianceInRawUnits) {
  NoiseProcessOptions o;
  o.white_noise = 2e-3;
  o.random_walk = 1e-3;
  ImuLog log;
  std::vector<StaticInterval> intervals;
  Pose(o, 1, 20.0, &log, &intervals);
  ImuNoiseModel model;
  for (AxisNoiseModel& a : model.accel) {
    a.white_noise.value = o.white_noise;
    a.random_walk.value = o.random_walk;
  }
  PoseNoiseOptions options;
  options.model = &model;
  std::vector<Position> positions = PositionsFromIntervals(intervals);
  std::vector<std::string> notes;
  std::string error;
  ASSERT_TRUE(SetPoseMeanCovariance(log, intervals, options, &positions, &notes, &error)) << error;
  EXPECT_TRUE(notes.empty()) << notes.front();
  const double expected =
      (o.white_noise * o.white_noise / 20.0 + o.random_walk * o.random_walk * 20.0 / 3.0) /
      (kScale * kScale);
  for (int a = 0; a < 3; ++a) {
    // 1 % for the scale read from the data (|mean| vs g).
    EXPECT_NEAR(positions[0].raw_mean_cov(a, a) / expected, 1.0, 0.01) << a;
  }
  // A model of a sensor ten times noisier: a warning.
  for (AxisNoiseModel& a : model.accel) a.white_noise.value *= 10.0;
  notes.clear();
  ASSERT_TRUE(SetPoseMeanCovariance(log, intervals, options, &positions, &notes, &error));
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("differs from the poses' own"), std::string::npos) << notes[0];
}

// 400 poses of white noise: batch / white averages nu / (nu - 2) = 19 / 17
// (4 sd of the average: 4 sqrt(2 / 19) / sqrt(1200) = 0.04); with a random
// walk dominating over the pose, batch means is several times C / n.
// An offset sensor (unsigned counts around 32768): the raw unit comes from
// the coarse fit's scale, not from |raw mean|, so a white-noise model gives
// the white-noise covariance of the mean (within a factor 2; |raw mean|
// would make it 30-50 times too large) and no warning of a factor.
TEST(PoseMeanCovariance, OffsetSensorTakesTheRawUnitFromTheCoarseFit) {
  NoiseProcessOptions o;
  o.white_noise = 2e-3;
  ImuLog log;
  std::vector<StaticInterval> intervals;
  for (int k = 0; k < 6; ++k) {
    Eigen::Vector3d up = Eigen::Vector3d::Zero();
    up[k / 2] = k % 2 == 0 ? 1.0 : -1.0;
    Pose(o, 10 + k, 10.0, &log, &intervals, up, 32768.0);
  }
  ImuNoiseModel model;
  for (AxisNoiseModel& a : model.accel) a.white_noise.value = o.white_noise;
  PoseNoiseOptions options;
  options.model = &model;
  std::vector<Position> positions = PositionsFromIntervals(intervals);
  std::vector<std::string> notes;
  std::string error;
  ASSERT_TRUE(SetPoseMeanCovariance(log, intervals, options, &positions, &notes, &error)) << error;
  for (const std::string& note : notes) {
    EXPECT_EQ(note.find("factor"), std::string::npos) << note;
  }
  const std::vector<Position> white = PositionsFromIntervals(intervals);
  for (size_t k = 0; k < positions.size(); ++k) {
    for (int a = 0; a < 3; ++a) {
      const double ratio = std::sqrt(positions[k].raw_mean_cov(a, a) / white[k].raw_mean_cov(a, a));
      EXPECT_GT(ratio, 0.5) << k << " " << a;
      EXPECT_LT(ratio, 2.0) << k << " " << a;
    }
  }
}

TEST(PoseMeanCovariance, BatchMeansOnWhiteNoiseAndRandomWalk) {
  NoiseProcessOptions white;
  white.white_noise = 2e-3;
  NoiseProcessOptions walk = white;
  walk.random_walk = 5e-3;
  for (const NoiseProcessOptions* o : {&white, &walk}) {
    ImuLog log;
    std::vector<StaticInterval> intervals;
    for (uint64_t seed = 0; seed < 400; ++seed) Pose(*o, seed, 10.0, &log, &intervals);
    PoseNoiseOptions options;
    options.method = PoseNoise::kBatchMeans;
    const std::vector<Position> before = PositionsFromIntervals(intervals);
    std::vector<Position> after = before;
    std::vector<std::string> notes;
    std::string error;
    ASSERT_TRUE(SetPoseMeanCovariance(log, intervals, options, &after, &notes, &error)) << error;
    EXPECT_TRUE(notes.empty());
    double ratio = 0.0;
    for (size_t k = 0; k < after.size(); ++k) {
      for (int a = 0; a < 3; ++a) {
        ratio += after[k].raw_mean_cov(a, a) / before[k].raw_mean_cov(a, a) / (3.0 * after.size());
      }
    }
    if (o == &white) {
      EXPECT_NEAR(ratio, 19.0 / 17.0, 0.04);
    } else {
      EXPECT_GT(ratio, 3.0);
    }
  }
}

TEST(PoseMeanCovariance, FallsBackToWhiteAndChecksOptions) {
  NoiseProcessOptions o;
  o.white_noise = 2e-3;
  ImuLog log;
  std::vector<StaticInterval> intervals;
  Pose(o, 1, 0.3, &log, &intervals);  // 30 samples < 2 x 20 batches
  PoseNoiseOptions options;
  options.method = PoseNoise::kBatchMeans;
  const std::vector<Position> before = PositionsFromIntervals(intervals);
  std::vector<Position> after = before;
  std::vector<std::string> notes;
  std::string error;
  ASSERT_TRUE(SetPoseMeanCovariance(log, intervals, options, &after, &notes, &error));
  EXPECT_EQ(after[0].raw_mean_cov, before[0].raw_mean_cov);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("keep the white-noise covariance"), std::string::npos);
  options.batches = 2;
  EXPECT_FALSE(SetPoseMeanCovariance(log, intervals, options, &after, &notes, &error));
  EXPECT_NE(error.find("pose_noise_batches"), std::string::npos);
}

}  // namespace
}  // namespace gravcal
