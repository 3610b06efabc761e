#include "gravcal/detection/static_detector.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "gravcal/core/position.h"
#include "gravcal/io/log_reader.h"
#include "gravcal/methods/twelve_position.h"
#include "gravcal/simulation/simulator.h"
#include "gravcal/workflows/config.h"
#include "test_util.h"
#include "util/random_vector.h"

namespace gravcal {
namespace {

constexpr double kGravity = 9.80665;

// One still segment of a synthetic log: the gravity direction in the body
// frame, held for `seconds`, followed by a smooth rotation to the next pose
// lasting `move_seconds` (none after the last).
struct Pose {
  Eigen::Vector3d up;  // body axis pointing up (need not be unit)
  double seconds;
};

struct Truth {
  size_t begin, end;  // samples [begin, end) held still
};

struct SyntheticOptions {
  double rate = 100.0;
  double move_seconds = 2.0;
  bool counts = false;        // raw int16-like counts instead of SI units
  double accel_noise = 0.02;  // m/s^2
  double gyro_noise = 0.002;  // rad/s
  bool with_gyro = true;
  bool with_temperature = false;
  unsigned seed = 1;
};

// Builds a log of still poses joined by smooth rotations (cosine velocity
// profile) with white noise; in counts mode with a bias, a scale of 16384
// counts per g and quantisation, like an MPU-6050.
ImuLog MakeLog(const std::vector<Pose>& poses, const SyntheticOptions& o,
               std::vector<Truth>* truth) {
  std::mt19937 rng(o.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  ImuLog log;
  log.source = "synthetic";
  const Eigen::Vector3d accel_bias(0.12, -0.08, 0.3);   // m/s^2
  const Eigen::Vector3d gyro_bias(0.01, -0.02, 0.005);  // rad/s
  auto emit = [&](const Eigen::Vector3d& f, const Eigen::Vector3d& w) {
    log.t.push_back(static_cast<double>(log.t.size()) / o.rate + 1000.0);
    Eigen::Vector3d a = f + accel_bias;
    Eigen::Vector3d g = w + gyro_bias;
    for (int k = 0; k < 3; ++k) {
      a[k] += o.accel_noise * normal(rng);
      g[k] += o.gyro_noise * normal(rng);
    }
    if (o.counts) {
      a = (a * 16384.0 / kGravity).array().round().matrix();
      g = (g * 180.0 / M_PI * 131.0).array().round().matrix();
    }
    log.accel.push_back(a);
    if (o.with_gyro) log.gyro.push_back(g);
    if (o.with_temperature) log.temperature.push_back(25.0 + 0.001 * log.t.size());
  };
  for (size_t p = 0; p < poses.size(); ++p) {
    const Eigen::Vector3d f = poses[p].up.normalized() * kGravity;
    const size_t still = static_cast<size_t>(std::lround(poses[p].seconds * o.rate));
    if (truth) truth->push_back({log.size(), log.size() + still});
    for (size_t i = 0; i < still; ++i) emit(f, Eigen::Vector3d::Zero());
    if (p + 1 == poses.size()) break;
    // Rotate f onto the next pose's direction about the common normal.
    const Eigen::Vector3d to = poses[p + 1].up.normalized() * kGravity;
    Eigen::Vector3d axis = f.cross(to);
    double angle = std::atan2(axis.norm(), f.dot(to));
    if (axis.norm() < 1e-9) axis = f.unitOrthogonal();
    axis.normalize();
    const size_t move = static_cast<size_t>(std::lround(o.move_seconds * o.rate));
    for (size_t i = 0; i < move; ++i) {
      const double tau = (i + 0.5) / static_cast<double>(move);
      const double s = 0.5 * (1.0 - std::cos(M_PI * tau));
      const double s_dot = 0.5 * M_PI * std::sin(M_PI * tau) / o.move_seconds;
      // The body turns by -angle*s about `axis`, so gravity appears to turn
      // by +angle*s.
      const Eigen::Vector3d fi = Eigen::AngleAxisd(angle * s, axis) * f;
      emit(fi, -axis * angle * s_dot);
    }
  }
  return log;
}

std::vector<Pose> SixPoses(double seconds) {
  return {{{0, 0, 1}, seconds},  {{1, 0, 0}, seconds},  {{0, 1, 0}, seconds},
          {{0, 0, -1}, seconds}, {{-1, 0, 0}, seconds}, {{0, -1, 0}, seconds}};
}

// Each truth segment matches exactly one interval that lies within it (give or
// take `slack` samples) and covers all of it but the settling margins.
void ExpectMatches(const StaticDetection& d, const std::vector<Truth>& truth, size_t settle,
                   size_t slack) {
  ASSERT_EQ(d.intervals.size(), truth.size()) << d.message;
  for (size_t i = 0; i < truth.size(); ++i) {
    const StaticInterval& s = d.intervals[i];
    SCOPED_TRACE("interval " + std::to_string(i));
    EXPECT_LT(s.begin, s.end);
    if (i > 0) EXPECT_LE(d.intervals[i - 1].end, s.begin);
    EXPECT_GE(s.begin + slack, truth[i].begin);
    EXPECT_LE(s.end, truth[i].end + slack);
    EXPECT_LE(s.begin, truth[i].begin + settle + slack);
    EXPECT_GE(s.end + settle + slack, truth[i].end);
  }
}

TEST(StaticDetector, FindsPosesInSiAndCountsWithTheSameOptions) {
  const StaticDetectorOptions options;
  for (bool counts : {false, true}) {
    SCOPED_TRACE(counts ? "counts" : "SI");
    SyntheticOptions so;
    so.counts = counts;
    std::vector<Truth> truth;
    const ImuLog log = MakeLog(SixPoses(5.0), so, &truth);
    StaticDetection d;
    ASSERT_TRUE(DetectStaticIntervals(log, options, &d)) << d.message;
    // Settle 0.3 s = 30 samples; up to 0.3 s of the slow end of a move may
    // pass for still and is trimmed too.
    ExpectMatches(d, truth, 30, 30);
    EXPECT_GT(d.accel_noise_floor, 0.0);
    EXPECT_NEAR(d.accel_threshold, options.threshold_factor * d.accel_noise_floor,
                1e-12 * d.accel_threshold);
    EXPECT_GT(d.gyro_noise_floor, 0.0);
    // The floor is the sensor noise: 3 axes * sigma^2.
    const double sigma = counts ? 0.02 * 16384.0 / kGravity : 0.02;
    EXPECT_NEAR(d.accel_noise_floor, 3.0 * sigma * sigma, 0.5 * 3.0 * sigma * sigma);
    // Interval statistics: the mean is gravity plus bias, the covariance the
    // noise.
    const double scale = counts ? 16384.0 / kGravity : 1.0;
    const Eigen::Vector3d bias = Eigen::Vector3d(0.12, -0.08, 0.3) * scale;
    const auto poses = SixPoses(5.0);
    for (size_t i = 0; i < d.intervals.size(); ++i) {
      const StaticInterval& s = d.intervals[i];
      const Eigen::Vector3d expected = poses[i].up * kGravity * scale + bias;
      EXPECT_LT((s.accel_mean - expected).norm(), 0.01 * scale) << i;
      EXPECT_NEAR(s.accel_cov(0, 0), sigma * sigma, 0.25 * sigma * sigma) << i;
      EXPECT_DOUBLE_EQ(s.t_begin, log.t[s.begin]);
      EXPECT_DOUBLE_EQ(s.t_end, log.t[s.end - 1]);
      EXPECT_TRUE(std::isnan(s.temperature_mean));
    }
  }
}

TEST(StaticDetector, AccelerometerOnlyLogsWork) {
  SyntheticOptions so;
  so.with_gyro = false;
  so.counts = true;
  std::vector<Truth> truth;
  const ImuLog log = MakeLog(SixPoses(4.0), so, &truth);
  StaticDetection d;
  ASSERT_TRUE(DetectStaticIntervals(log, StaticDetectorOptions(), &d)) << d.message;
  ExpectMatches(d, truth, 30, 30);
  EXPECT_EQ(d.gyro_noise_floor, 0.0);
  EXPECT_EQ(d.gyro_threshold, 0.0);
  EXPECT_EQ(d.intervals[0].gyro_mean, Eigen::Vector3d::Zero());
}

TEST(StaticDetector, RejectsShortStillSegments) {
  SyntheticOptions so;
  std::vector<Truth> truth;
  std::vector<Pose> poses = SixPoses(5.0);
  poses[2].seconds = 1.5;  // 0.9 s after trimming: shorter than 2 s
  poses[4].seconds = 0.5;  // shorter than a window
  const ImuLog log = MakeLog(poses, so, &truth);
  StaticDetection d;
  ASSERT_TRUE(DetectStaticIntervals(log, StaticDetectorOptions(), &d)) << d.message;
  ExpectMatches(d, {truth[0], truth[1], truth[3], truth[5]}, 30, 30);
  // The 1.5 s pose is reported as rejected, too short, and no rejected
  // stretch overlaps an interval.
  size_t short_pose = 0;
  for (const RejectedStretch& r : d.rejected) {
    EXPECT_LT(r.begin, r.end);
    EXPECT_DOUBLE_EQ(r.t_begin, log.t[r.begin]);
    EXPECT_DOUBLE_EQ(r.t_end, log.t[r.end - 1]);
    for (const StaticInterval& s : d.intervals) EXPECT_TRUE(r.end <= s.begin || s.end <= r.begin);
    if (r.begin < truth[2].end && truth[2].begin < r.end) {
      ++short_pose;
      EXPECT_EQ(r.reason, RejectionReason::kTooShort);
      EXPECT_NE(r.detail.find("min_duration_seconds"), std::string::npos) << r.detail;
    }
  }
  EXPECT_EQ(short_pose, 1u);
  EXPECT_STREQ(ToString(RejectionReason::kTooShort), "too_short");
}

// A pose held with tremor (accelerometer variance a few times the
// threshold) is rejected as too much motion; a pose rocked about the
// vertical (the accelerometer still, the gyroscope's variance a few times
// its threshold) as rotating. Neither changes the intervals of the others.
TEST(StaticDetector, ReportsNearlyStillStretchesWithTheirReason) {
  SyntheticOptions so;
  std::vector<Truth> truth;
  const ImuLog clean = MakeLog(SixPoses(6.0), so, &truth);
  ImuLog log = clean;
  std::mt19937 rng(11);
  std::normal_distribution<double> tremor(0.0, 0.02 * std::sqrt(19.0));
  for (size_t i = truth[1].begin; i < truth[1].end; ++i) {
    log.accel[i] += internal::DrawVector3([&] { return tremor(rng); });
  }
  for (size_t i = truth[4].begin; i < truth[4].end; ++i) {
    // Pose 4 has x down: rocking about x leaves gravity where it is.
    log.gyro[i].x() += 0.2 * std::sin(2.0 * M_PI * (log.t[i] - log.t[truth[4].begin]));
  }
  StaticDetection d, d_clean;
  ASSERT_TRUE(DetectStaticIntervals(clean, StaticDetectorOptions(), &d_clean)) << d.message;
  ASSERT_TRUE(DetectStaticIntervals(log, StaticDetectorOptions(), &d)) << d.message;
  ExpectMatches(d, {truth[0], truth[2], truth[3], truth[5]}, 30, 30);
  EXPECT_TRUE(d_clean.rejected.empty()) << d_clean.rejected[0].detail;
  ASSERT_EQ(d.rejected.size(), 2u) << d.message;
  EXPECT_EQ(d.rejected[0].reason, RejectionReason::kTooMuchMotion) << d.rejected[0].detail;
  EXPECT_EQ(d.rejected[1].reason, RejectionReason::kRotating) << d.rejected[1].detail;
  for (int k : {0, 1}) {
    const Truth& t = truth[k == 0 ? 1 : 4];
    EXPECT_LT(d.rejected[k].begin, t.end);
    EXPECT_GT(d.rejected[k].end, t.begin);
    // The stretch is most of the pose.
    EXPECT_GT(d.rejected[k].end - d.rejected[k].begin, (t.end - t.begin) / 2);
  }
  EXPECT_NE(d.message.find("2 stretches rejected"), std::string::npos) << d.message;
  // Rejected stretches are reported only: a candidate_factor of 1 reports
  // none of the nearly still ones and leaves the intervals as they are.
  StaticDetectorOptions strict;
  strict.candidate_factor = 1.0;
  StaticDetection d_strict;
  ASSERT_TRUE(DetectStaticIntervals(log, strict, &d_strict)) << d_strict.message;
  EXPECT_TRUE(d_strict.rejected.empty());
  ASSERT_EQ(d_strict.intervals.size(), d.intervals.size());
  for (size_t i = 0; i < d.intervals.size(); ++i) {
    EXPECT_EQ(d_strict.intervals[i].begin, d.intervals[i].begin);
    EXPECT_EQ(d_strict.intervals[i].end, d.intervals[i].end);
  }
}

TEST(StaticDetector, NoStillSegmentGivesNoInterval) {
  // Continuous tumbling: gravity turns at 20-40 deg/s in the body frame.
  std::mt19937 rng(3);
  std::normal_distribution<double> normal(0.0, 1.0);
  ImuLog log;
  const double rate = 100.0;
  double angle = 0.0;
  for (int i = 0; i < 6000; ++i) {
    const double t = i / rate;
    const double w = (30.0 + 10.0 * std::sin(0.5 * t)) * M_PI / 180.0;
    angle += w / rate;
    log.t.push_back(t);
    Eigen::Vector3d f(0.0, std::sin(angle) * kGravity, std::cos(angle) * kGravity);
    Eigen::Vector3d g(w, 0.0, 0.0);
    for (int k = 0; k < 3; ++k) {
      f[k] += 0.02 * normal(rng);
      g[k] += 0.002 * normal(rng);
    }
    log.accel.push_back(f);
    log.gyro.push_back(g);
  }
  StaticDetection d;
  ASSERT_TRUE(DetectStaticIntervals(log, StaticDetectorOptions(), &d)) << d.message;
  EXPECT_TRUE(d.intervals.empty())
      << d.intervals.size() << " intervals, first at " << d.intervals[0].begin;
  // Without the white-noise cap the floor is the motion itself, and all of
  // it passes the variance test: the cap is what makes that work, and the
  // level check (the gyroscope's rate is far from still) on its own.
  StaticDetectorOptions no_cap;
  no_cap.max_floor_ratio = 0.0;
  ASSERT_TRUE(DetectStaticIntervals(log, no_cap, &d));
  EXPECT_TRUE(d.intervals.empty());
  no_cap.trend_factor = 0.0;
  ASSERT_TRUE(DetectStaticIntervals(log, no_cap, &d));
  EXPECT_FALSE(d.intervals.empty());
}

TEST(StaticDetector, MergesABriefBumpButNotAPickUp) {
  SyntheticOptions so;
  std::vector<Truth> truth;
  const ImuLog base = MakeLog({{{0, 0, 1}, 20.0}, {{1, 0, 0}, 5.0}}, so, &truth);

  // A tap: 0.1 s of a 0.3 m/s^2 rms jolt in the middle of the first pose.
  ImuLog tapped = base;
  std::mt19937 rng(7);
  std::normal_distribution<double> normal(0.0, 0.3);
  for (size_t i = 1000; i < 1010; ++i)
    tapped.accel[i] += internal::DrawVector3([&] { return normal(rng); });
  StaticDetection d;
  ASSERT_TRUE(DetectStaticIntervals(tapped, StaticDetectorOptions(), &d)) << d.message;
  ExpectMatches(d, truth, 30, 30);

  // With merging off, the tap splits the pose in two.
  StaticDetectorOptions no_merge;
  no_merge.merge_angle_deg = 0.0;
  ASSERT_TRUE(DetectStaticIntervals(tapped, no_merge, &d)) << d.message;
  EXPECT_EQ(d.intervals.size(), 3u);

  // Picked up and put back down in the same orientation: 1 s of large
  // motion. Two intervals, and neither includes the motion.
  ImuLog picked = base;
  for (size_t i = 1000; i < 1100; ++i) {
    const double s = std::sin(M_PI * (i - 1000) / 100.0);
    picked.accel[i] += Eigen::Vector3d(2.0 * s, -1.0 * s, 3.0 * s * s);
  }
  ASSERT_TRUE(DetectStaticIntervals(picked, StaticDetectorOptions(), &d)) << d.message;
  ASSERT_EQ(d.intervals.size(), 3u);
  EXPECT_LE(d.intervals[0].end, 1000u);
  EXPECT_GE(d.intervals[1].begin, 1100u);
  EXPECT_LT(d.intervals[0].accel_cov.trace(), 2.0 * 3.0 * 0.02 * 0.02);
  EXPECT_LT(d.intervals[1].accel_cov.trace(), 2.0 * 3.0 * 0.02 * 0.02);
}

TEST(StaticDetector, ConstantQuantisedDataIsStill) {
  // A quiet sensor whose counts never change in the first pose: the floor
  // must not be zero, and the positions must have a usable covariance.
  SyntheticOptions so;
  so.counts = true;
  so.accel_noise = 0.0;
  so.gyro_noise = 0.0;
  so.with_temperature = true;
  std::vector<Truth> truth;
  const ImuLog log = MakeLog(SixPoses(4.0), so, &truth);
  StaticDetection d;
  ASSERT_TRUE(DetectStaticIntervals(log, StaticDetectorOptions(), &d)) << d.message;
  ExpectMatches(d, truth, 30, 30);
  EXPECT_GT(d.accel_noise_floor, 0.0);
  EXPECT_EQ(d.intervals[0].accel_cov, Eigen::Matrix3d::Zero());
  EXPECT_FALSE(std::isnan(d.intervals[0].temperature_mean));
  const std::vector<Position> positions = PositionsFromIntervals(d.intervals);
  ASSERT_EQ(positions.size(), d.intervals.size());
  for (const Position& p : positions) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(p.raw_mean_cov);
    EXPECT_GT(eig.eigenvalues()[0], 0.0);
    EXPECT_LE(eig.eigenvalues()[2], 1.0);  // a fraction of a count^2
    EXPECT_EQ(p.temperature, d.intervals[&p - positions.data()].temperature_mean);
  }
}

TEST(StaticDetector, RejectsInvalidOptionsNamingTheField) {
  SyntheticOptions so;
  const ImuLog log = MakeLog(SixPoses(3.0), so, nullptr);
  struct Case {
    std::string field;
    void (*set)(StaticDetectorOptions*);
  };
  const std::vector<Case> cases = {
      {"window_seconds", [](StaticDetectorOptions* o) { o->window_seconds = 0.0; }},
      {"window_seconds", [](StaticDetectorOptions* o) { o->window_seconds = NAN; }},
      {"noise_quantile", [](StaticDetectorOptions* o) { o->noise_quantile = 1.0; }},
      {"noise_quantile", [](StaticDetectorOptions* o) { o->noise_quantile = 0.0; }},
      {"threshold_factor", [](StaticDetectorOptions* o) { o->threshold_factor = 0.5; }},
      {"gyro_threshold_factor", [](StaticDetectorOptions* o) { o->gyro_threshold_factor = -1; }},
      {"max_floor_ratio", [](StaticDetectorOptions* o) { o->max_floor_ratio = -1.0; }},
      {"min_duration_seconds", [](StaticDetectorOptions* o) { o->min_duration_seconds = -1; }},
      {"settle_seconds", [](StaticDetectorOptions* o) { o->settle_seconds = INFINITY; }},
      {"merge_angle_deg", [](StaticDetectorOptions* o) { o->merge_angle_deg = 200.0; }},
      {"merge_gap_windows", [](StaticDetectorOptions* o) { o->merge_gap_windows = -2.0; }},
      {"candidate_factor", [](StaticDetectorOptions* o) { o->candidate_factor = 0.5; }},
      {"trend_factor", [](StaticDetectorOptions* o) { o->trend_factor = 0.5; }},
      {"spread_factor", [](StaticDetectorOptions* o) { o->spread_factor = -1.0; }},
  };
  for (const Case& c : cases) {
    StaticDetectorOptions options;
    c.set(&options);
    std::string error;
    EXPECT_FALSE(options.IsValid(&error)) << c.field;
    EXPECT_NE(error.find(c.field), std::string::npos) << error;
    StaticDetection d;
    EXPECT_FALSE(DetectStaticIntervals(log, options, &d)) << c.field;
    EXPECT_NE(d.message.find(c.field), std::string::npos) << d.message;
    EXPECT_TRUE(d.intervals.empty());
  }
  std::string error;
  EXPECT_TRUE(StaticDetectorOptions().IsValid(&error)) << error;

  // Valid but absurd durations: no interval, no overflow.
  StaticDetection d;
  StaticDetectorOptions options;
  options.settle_seconds = 1e300;
  EXPECT_TRUE(DetectStaticIntervals(log, options, &d)) << d.message;
  EXPECT_TRUE(d.intervals.empty());
  options = StaticDetectorOptions();
  options.min_duration_seconds = 1e300;
  EXPECT_TRUE(DetectStaticIntervals(log, options, &d)) << d.message;
  EXPECT_TRUE(d.intervals.empty());
}

TEST(StaticDetector, RejectsLogsItCannotUse) {
  SyntheticOptions so;
  ImuLog log = MakeLog({{{0, 0, 1}, 0.5}}, so, nullptr);  // 50 samples < 100
  StaticDetection d;
  EXPECT_FALSE(DetectStaticIntervals(log, StaticDetectorOptions(), &d));
  EXPECT_NE(d.message.find("window"), std::string::npos) << d.message;
  EXPECT_TRUE(d.intervals.empty());

  ImuLog empty;
  EXPECT_FALSE(DetectStaticIntervals(empty, StaticDetectorOptions(), &d));
  EXPECT_FALSE(d.message.empty());

  log = MakeLog(SixPoses(3.0), so, nullptr);
  ImuLog bad = log;
  bad.accel[500][1] = NAN;
  EXPECT_FALSE(DetectStaticIntervals(bad, StaticDetectorOptions(), &d));
  EXPECT_NE(d.message.find("not finite"), std::string::npos) << d.message;
  bad = log;
  bad.t[700] = bad.t[699];
  EXPECT_FALSE(DetectStaticIntervals(bad, StaticDetectorOptions(), &d));
  EXPECT_NE(d.message.find("sample 700"), std::string::npos) << d.message;
  bad = log;
  bad.gyro.pop_back();
  EXPECT_FALSE(DetectStaticIntervals(bad, StaticDetectorOptions(), &d));
  EXPECT_NE(d.message.find("gyroscope"), std::string::npos) << d.message;
  EXPECT_FALSE(DetectStaticIntervals(log, StaticDetectorOptions(), nullptr));
}

TEST(StaticDetector, MakeIntervalComputesTheStatistics) {
  ImuLog log;
  for (int i = 0; i < 5; ++i) {
    log.t.push_back(0.1 * i);
    log.accel.push_back(Eigen::Vector3d(16000.0 + i, -3.0 * i, 7.0));
    log.gyro.push_back(Eigen::Vector3d(i % 2, 0.0, 1.0));
    log.temperature.push_back(20.0 + i);
  }
  const StaticInterval s = MakeInterval(log, 1, 4);  // samples 1, 2, 3
  EXPECT_EQ(s.count(), 3u);
  EXPECT_DOUBLE_EQ(s.t_begin, 0.1);
  EXPECT_DOUBLE_EQ(s.t_end, 0.3);
  EXPECT_TRUE(s.accel_mean.isApprox(Eigen::Vector3d(16002.0, -6.0, 7.0)));
  EXPECT_DOUBLE_EQ(s.accel_cov(0, 0), 1.0);
  EXPECT_DOUBLE_EQ(s.accel_cov(1, 1), 9.0);
  EXPECT_DOUBLE_EQ(s.accel_cov(0, 1), -3.0);
  EXPECT_DOUBLE_EQ(s.accel_cov(2, 2), 0.0);
  EXPECT_TRUE(s.accel_resolution.isApprox(Eigen::Vector3d(1.0, 3.0, 0.0)));
  EXPECT_NEAR(s.gyro_mean[0], 2.0 / 3.0, 1e-15);
  EXPECT_NEAR(s.gyro_cov(0, 0), 1.0 / 3.0, 1e-15);
  EXPECT_DOUBLE_EQ(s.temperature_mean, 22.0);

  // Out-of-range requests are clamped, never read past the log.
  const StaticInterval clamped = MakeInterval(log, 3, 99);
  EXPECT_EQ(clamped.end, 5u);
  EXPECT_EQ(clamped.count(), 2u);
  EXPECT_EQ(MakeInterval(log, 4, 2).count(), 0u);
}

TEST(StaticDetector, PositionsCarryTheCovarianceOfTheMean) {
  StaticInterval s;
  s.begin = 10;
  s.end = 110;
  s.t_begin = 1.0;
  s.t_end = 2.0;
  s.accel_mean = Eigen::Vector3d(1.0, 2.0, 3.0);
  s.accel_cov = Eigen::Vector3d(4.0, 9.0, 16.0).asDiagonal();
  s.accel_cov(0, 1) = s.accel_cov(1, 0) = 1.0;
  s.temperature_mean = 30.0;
  const std::vector<Position> p = PositionsFromIntervals({s});
  ASSERT_EQ(p.size(), 1u);
  EXPECT_EQ(p[0].raw_mean, s.accel_mean);
  EXPECT_TRUE(p[0].raw_mean_cov.isApprox(s.accel_cov / 100.0));
  EXPECT_EQ(p[0].sample_count, 100u);
  EXPECT_EQ(p[0].t_begin, 1.0);
  EXPECT_EQ(p[0].t_end, 2.0);
  EXPECT_EQ(p[0].temperature, 30.0);
  EXPECT_EQ(p[0].nominal_up, -1);

  // Singular (one axis constant): quantisation variance step^2/12 added.
  s.accel_cov(2, 2) = 0.0;
  s.accel_resolution = Eigen::Vector3d(0.5, 0.5, 0.0);
  const std::vector<Position> q = PositionsFromIntervals({s});
  EXPECT_NEAR(q[0].raw_mean_cov(2, 2), 0.25 / 12.0, 1e-15);
  EXPECT_NEAR(q[0].raw_mean_cov(0, 0), 0.04 + 0.25 / 12.0, 1e-15);
  EXPECT_TRUE(PositionsFromIntervals({}).empty());
}

TEST(StaticDetector, NominalAxes) {
  const char* names[] = {"+x", "-x", "+y", "-y", "+z", "-z"};
  for (int i = 0; i < 6; ++i) {
    const Eigen::Vector3d a = NominalAxis(i);
    EXPECT_DOUBLE_EQ(a.norm(), 1.0);
    EXPECT_DOUBLE_EQ(a[i / 2], i % 2 == 0 ? 1.0 : -1.0);
    EXPECT_EQ(NominalAxisName(i), names[i]);
  }
  EXPECT_EQ(NominalAxisName(-1), "?");
  EXPECT_EQ(NominalAxisName(6), "?");
  EXPECT_EQ(NominalAxis(-1), Eigen::Vector3d::Zero());
}

// Issue 33: turns of 40 s between 10-s holds (minimum-jerk: a slow start and
// end). Their slow ends have a small variance but a changing level: every
// interval must lie within its hold (give or take the 0.3 s settling), not
// reach seconds into the turns.
TEST(StaticDetector, SlowTurnsAreMotion) {
  SimulatorOptions sim;
  sim.rotation_seconds = 40.0;
  sim.hold_seconds = 10.0;
  sim.initial_still_seconds = 10.0;
  SimulatedSession s;
  std::string error;
  ASSERT_TRUE(Simulate(sim, 5, &s, &error)) << error;
  StaticDetection d;
  ASSERT_TRUE(DetectStaticIntervals(s.log, StaticDetectorOptions(), &d)) << d.message;
  ASSERT_EQ(d.intervals.size(), s.poses.size()) << d.message;
  // Up to 2 s of the turn's slow end may pass: its rate is then below 1 %
  // of the turns' rate (0.04 deg/s), the angle turned below 0.1 deg.
  const size_t slack = 200;
  for (size_t i = 0; i < s.poses.size(); ++i) {
    SCOPED_TRACE("pose " + std::to_string(i));
    EXPECT_GE(d.intervals[i].begin + slack, s.poses[i].begin);
    EXPECT_LE(d.intervals[i].end, s.poses[i].end + slack);
    // ... and most of the hold is kept.
    EXPECT_GT(d.intervals[i].count(), (s.poses[i].end - s.poses[i].begin) * 3 / 4);
  }
  // The same with the level checks off (the detector before issue 33): the
  // holds swallow seconds of the turns.
  StaticDetectorOptions variance_only;
  variance_only.trend_factor = 0.0;
  variance_only.spread_factor = 0.0;
  ASSERT_TRUE(DetectStaticIntervals(s.log, variance_only, &d)) << d.message;
  ASSERT_EQ(d.intervals.size(), s.poses.size()) << d.message;
  size_t worst = 0;
  for (size_t i = 0; i < s.poses.size(); ++i) {
    if (d.intervals[i].begin < s.poses[i].begin)
      worst = std::max(worst, s.poses[i].begin - d.intervals[i].begin);
    if (d.intervals[i].end > s.poses[i].end)
      worst = std::max(worst, d.intervals[i].end - s.poses[i].end);
  }
  EXPECT_GT(worst, 2 * slack);

  // What it does to the calibration: with the turns' slow ends in the holds
  // the scale factors are several sigma off (measured on seeds 1-3: 3.0 to
  // 6.5 sigma); without them, within 3 sigma.
  for (bool level : {true, false}) {
    CalibrationOptions co;
    co.gravity.gravity = s.gravity;
    if (!level) co.detector = variance_only;
    Calibration c;
    ASSERT_TRUE(CalibrateAccelerometer(s.log, co, &c)) << c.message;
    double worst_z = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double scale = c.accel.model.matrix().col(k).norm();
      const double truth = s.accel_truth.matrix().col(k).norm();
      worst_z = std::max(worst_z, std::abs(scale - truth) / c.accel.matrix_std(k, k));
    }
    if (level) {
      EXPECT_LT(worst_z, 3.0);
    } else {
      EXPECT_GT(worst_z, 3.0);
    }
  }
}

// A 40-s pose drifts slowly (0.006 m/s^2 per s on y): a level change too
// slow for any one window to show, but its spread over the pose is 8 times
// the noise. With parts of at least 2 s it is split into parts within the
// spread; when no part may be shorter than 25 s, it is kept and named.
TEST(StaticDetector, SpreadFarAboveTheNoiseIsSplitOrNamed) {
  SyntheticOptions so;
  so.accel_noise = 0.005;
  std::vector<Truth> truth;
  ImuLog log = MakeLog({{{0, 0, 1}, 10.0}, {{1, 0, 0}, 40.0}, {{0, 1, 0}, 10.0}}, so, &truth);
  for (size_t i = truth[1].begin; i < truth[1].end; ++i) {
    log.accel[i].y() += 0.006 * (log.t[i] - log.t[truth[1].begin]);
  }
  StaticDetection d;
  ASSERT_TRUE(DetectStaticIntervals(log, StaticDetectorOptions(), &d)) << d.message;
  EXPECT_GE(d.intervals.size(), 4u) << d.message;
  for (const StaticInterval& s : d.intervals) {
    EXPECT_LE(s.accel_cov.trace(), StaticDetectorOptions().spread_factor * d.accel_noise_floor);
  }
  EXPECT_TRUE(d.warnings.empty());
  StaticDetectorOptions long_parts;
  long_parts.min_duration_seconds = 25.0;
  ASSERT_TRUE(DetectStaticIntervals(log, long_parts, &d)) << d.message;
  ASSERT_EQ(d.intervals.size(), 1u) << d.message;
  ASSERT_EQ(d.warnings.size(), 1u);
  EXPECT_NE(d.warnings[0].find("not one still pose"), std::string::npos) << d.warnings[0];
  EXPECT_NE(d.warnings[0].find("t 1012"), std::string::npos) << d.warnings[0];
}

// Issue 33: a time column in ms, us or ns read as seconds gives windows of
// two samples and hundreds of "positions"; the detector refuses it and names
// the unit.
TEST(StaticDetector, TimeInOtherUnitsIsNamed) {
  SyntheticOptions so;
  const ImuLog log = MakeLog(SixPoses(5.0), so, nullptr);
  const struct {
    double scale;
    const char* unit;
    const char* time_scale;
  } cases[] = {{1e3, "milliseconds", "time_scale: 0.001"},
               {1e6, "microseconds", "time_scale: 1e-06"},
               {1e9, "nanoseconds", "time_scale: 1e-09"},
               // A 4 kHz log in ms reads as 4 Hz: four samples per window.
               {1e3 / 40.0, "milliseconds", "time_scale: 0.001"}};
  for (const auto& c : cases) {
    ImuLog scaled = log;
    for (double& t : scaled.t) t *= c.scale;
    StaticDetection d;
    EXPECT_FALSE(DetectStaticIntervals(scaled, StaticDetectorOptions(), &d)) << c.unit;
    EXPECT_NE(d.message.find(c.unit), std::string::npos) << d.message;
    EXPECT_NE(d.message.find(c.time_scale), std::string::npos) << d.message;
    EXPECT_TRUE(d.intervals.empty());
  }
  // A slow log with a window long enough is fine.
  ImuLog slow = log;
  for (double& t : slow.t) t *= 100.0;  // 1 Hz
  StaticDetectorOptions long_window;
  long_window.window_seconds = 100.0;
  long_window.min_duration_seconds = 200.0;
  long_window.settle_seconds = 30.0;
  StaticDetection d;
  EXPECT_TRUE(DetectStaticIntervals(slow, long_window, &d)) << d.message;
  EXPECT_EQ(d.intervals.size(), 6u) << d.message;
}

// Issue 33: poses published with the transitions cut out touch with a step
// and no motion between. A simulated session of 40 poses whose consecutive
// ups are 4.6-16 degrees apart (1.3-20 degrees with the simulated
// placement errors), held 4 s each (the first 8 s: the initial still period
// in the same pose), cut to its holds and concatenated (accelerometer only,
// like such files); the noise of every third pose is twice the others' (four
// times the variance) and every fourth pose drifts (0.004 m/s^2 per s, as
// much as the level trim lets pass). Every
// pose is found, and the calibration from them is within 3 sigma of the
// truth. With the step split off (the detector before it), poses merge.
ImuLog CutPoseLog(SimulatedSession* s, std::vector<size_t>* cuts) {
  SimulatorOptions sim;
  sim.raw_counts = false;
  sim.initial_still_seconds = 4.0;
  sim.rotation_seconds = 2.0;
  const int num_poses = 40;
  for (int i = 0; i < num_poses; ++i) {
    const double theta = M_PI * i / (num_poses - 1);
    const double phi = 15.0 * i * M_PI / 180.0;
    PlannedHold hold;
    hold.up = Eigen::Vector3d(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                              std::cos(theta));
    hold.hold_seconds = 4.0;
    sim.planned_poses.push_back(hold);
  }
  std::string error;
  EXPECT_TRUE(Simulate(sim, 3, s, &error)) << error;
  std::mt19937 rng(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  ImuLog cut;
  cut.source = "cut poses";
  for (size_t p = 0; p < s->poses.size(); ++p) {
    cuts->push_back(cut.size());
    const SimulatedPose& pose = s->poses[p];
    for (size_t i = pose.begin; i < pose.end; ++i) {
      Eigen::Vector3d a = s->log.accel[i];
      if (p % 3 == 1)
        a += std::sqrt(3.0) * sim.accel_noise * internal::DrawVector3([&] { return normal(rng); });
      if (p % 4 == 2) a.x() += 0.004 * static_cast<double>(i - pose.begin) / sim.sample_rate;
      cut.t.push_back(static_cast<double>(cut.size()) / sim.sample_rate);
      cut.accel.push_back(a);
    }
  }
  cuts->push_back(cut.size());
  return cut;
}

TEST(StaticDetector, CutPosesAreSplitAtTheirSteps) {
  SimulatedSession s;
  std::vector<size_t> cuts;
  const ImuLog log = CutPoseLog(&s, &cuts);
  const size_t num_poses = cuts.size() - 1;
  // Consecutive poses at least 1.2 degrees apart.
  for (size_t p = 1; p < num_poses; ++p) {
    const Eigen::Vector3d a = MakeInterval(log, cuts[p - 1], cuts[p]).accel_mean.normalized();
    const Eigen::Vector3d b = MakeInterval(log, cuts[p], cuts[p + 1]).accel_mean.normalized();
    EXPECT_GT(std::acos(std::min(1.0, a.dot(b))) * 180.0 / M_PI, 1.2) << p;
  }
  StaticDetection d;
  ASSERT_TRUE(DetectStaticIntervals(log, StaticDetectorOptions(), &d)) << d.message;
  ASSERT_EQ(d.intervals.size(), num_poses) << d.message;
  for (size_t p = 0; p < num_poses; ++p) {
    // Within its pose, and most of it (0.3 s settling trimmed at each end).
    EXPECT_GE(d.intervals[p].begin, cuts[p]) << p;
    EXPECT_LE(d.intervals[p].end, cuts[p + 1]) << p;
    EXPECT_GT(d.intervals[p].count(), (cuts[p + 1] - cuts[p]) * 3 / 4) << p;
  }
  EXPECT_TRUE(d.warnings.empty());

  CalibrationOptions co;
  co.gravity.gravity = s.gravity;
  Calibration c;
  ASSERT_TRUE(CalibrateAccelerometer(log, co, &c)) << c.message;
  for (int k = 0; k < 3; ++k) {
    const double scale = c.accel.model.matrix().col(k).norm();
    const double truth = s.accel_truth.matrix().col(k).norm();
    EXPECT_LT(std::abs(scale - truth), 3.0 * c.accel.matrix_std(k, k)) << k;
  }

  // Without the step split, touching poses merge or are lost.
  StaticDetectorOptions no_steps;
  no_steps.step_factor = 0.0;
  ASSERT_TRUE(DetectStaticIntervals(log, no_steps, &d)) << d.message;
  EXPECT_LT(d.intervals.size(), num_poses) << d.message;
}

// The same cut poses held 1 s each (the samples at four times the rate):
// shorter than the defaults keep (min_duration 2 s, settling 0.3 s at each
// end, a 1 s window). The detector sees isolated steps and no motion, fits
// its time scales to the holds and says so; every pose is found inside its
// hold.
TEST(StaticDetector, CutPosesShorterThanTheDefaultsAreFittedToTheirHolds) {
  SimulatedSession s;
  std::vector<size_t> cuts;
  ImuLog log = CutPoseLog(&s, &cuts);
  for (size_t i = 0; i < log.size(); ++i) log.t[i] = static_cast<double>(i) / 400.0;
  const size_t num_poses = cuts.size() - 1;
  StaticDetection d;
  ASSERT_TRUE(DetectStaticIntervals(log, StaticDetectorOptions(), &d)) << d.message;
  EXPECT_NE(d.message.find("motion cut out"), std::string::npos) << d.message;
  EXPECT_NE(d.message.find("holds of 1 s"), std::string::npos) << d.message;
  ASSERT_EQ(d.intervals.size(), num_poses) << d.message;
  for (size_t p = 0; p < num_poses; ++p) {
    EXPECT_GE(d.intervals[p].begin, cuts[p]) << p;
    EXPECT_LE(d.intervals[p].end, cuts[p + 1]) << p;
    EXPECT_GT(d.intervals[p].count(), (cuts[p + 1] - cuts[p]) * 3 / 4) << p;
  }
  // A session with motion between its poses is never taken for cut poses.
  std::vector<Truth> truth;
  ASSERT_TRUE(DetectStaticIntervals(MakeLog(SixPoses(3.0), SyntheticOptions(), &truth),
                                    StaticDetectorOptions(), &d))
      << d.message;
  EXPECT_EQ(d.message.find("cut out"), std::string::npos) << d.message;
  EXPECT_EQ(d.intervals.size(), 6u) << d.message;
}

// A constant turn about gravity started and stopped with the motion cut
// out: the accelerometer does not change, only the rate steps (0 -> 10
// deg/s -> 0). Each level is its own interval, its gyroscope mean one rate;
// the detector that split at accelerometer steps only made one interval of
// the three.
TEST(StaticDetector, CutRateStepsSplitOnTheGyroscope) {
  SyntheticOptions o;
  o.move_seconds = 0.0;
  std::vector<Truth> truth;
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  ImuLog log = MakeLog({{up, 6.0}, {up, 6.0}, {up, 6.0}}, o, &truth);
  ASSERT_EQ(truth.size(), 3u);
  const double rate = 10.0 * M_PI / 180.0;
  for (size_t i = truth[1].begin; i < truth[1].end; ++i) log.gyro[i].z() += rate;
  StaticDetection d;
  ASSERT_TRUE(DetectStaticIntervals(log, StaticDetectorOptions(), &d)) << d.message;
  ASSERT_EQ(d.intervals.size(), 3u) << d.message;
  for (size_t p = 0; p < 3; ++p) {
    EXPECT_GE(d.intervals[p].begin, truth[p].begin) << p;
    EXPECT_LE(d.intervals[p].end, truth[p].end) << p;
    EXPECT_GT(d.intervals[p].count(), (truth[p].end - truth[p].begin) / 2) << p;
    EXPECT_NEAR(d.intervals[p].gyro_mean.z() - 0.005, p == 1 ? rate : 0.0, 0.01 * rate) << p;
  }
}

// --- Real recordings (skipped when ../shared/data/real is missing) ---------

// A real recording read with its shipped config's input settings.
ImuLog ReadReal(const std::string& config_name, const std::string& file) {
  Config config;
  ImuLog log;
  std::string error;
  EXPECT_TRUE(testing_util::LoadRealSession(config_name, file, &config, &log, &error)) << error;
  return log;
}

bool Overlaps(const StaticInterval& s, size_t begin, size_t end) {
  return s.begin < end && begin < s.end;
}

// NilsPod, 102.4 Hz, on a table: the six labelled faces, and besides them
// seven still periods in the x-, y- and z-up orientations: before the first
// face (0.3-2.8 s, split from x_p by a pick-up-and-put-down) and before and
// after each of the three rotations. 13 intervals, 6 orientations.
TEST(StaticDetectorRealData, FerrarisNilsPod) {
  if (testing_util::RealDataDir().empty()) GTEST_SKIP() << "no real data";
  const ImuLog log = ReadReal("ferraris_nilspod.yaml", "ferraris_nilspod/session.csv");
  ASSERT_EQ(log.size(), 10376u);
  StaticDetection d;
  ASSERT_TRUE(DetectStaticIntervals(log, StaticDetectorOptions(), &d)) << d.message;
  EXPECT_EQ(d.intervals.size(), 13u) << d.message;

  std::ifstream in(testing_util::RealDataDir() + "/ferraris_nilspod/sections.json");
  ASSERT_TRUE(in.good());
  const nlohmann::json sections = nlohmann::json::parse(in);
  for (const char* face : {"x_p", "x_a", "y_p", "y_a", "z_p", "z_a"}) {
    const size_t begin = sections[face]["start"].get<size_t>();
    const size_t end = sections[face]["end"].get<size_t>();
    int found = 0;
    for (const StaticInterval& s : d.intervals) {
      if (Overlaps(s, begin, end)) {
        ++found;
        // Most of the labelled face is inside the interval.
        EXPECT_LE(s.begin, begin + 50) << face;
        EXPECT_GE(s.end + 50, end) << face;
      }
    }
    EXPECT_EQ(found, 1) << face;
  }
  for (const char* rotation : {"x_rot", "y_rot", "z_rot"}) {
    const size_t begin = sections[rotation]["start"].get<size_t>();
    const size_t end = sections[rotation]["end"].get<size_t>();
    for (const StaticInterval& s : d.intervals) EXPECT_FALSE(Overlaps(s, begin, end)) << rotation;
  }
  // On a table: every interval is quiet (accelerometer sd < 0.05 m/s^2) and
  // near gravity (the raw norms range over 9.2-10.5 m/s^2: uncalibrated).
  for (const StaticInterval& s : d.intervals) {
    EXPECT_LT(std::sqrt(s.accel_cov.trace()), 0.05) << s.begin;
    EXPECT_NEAR(s.accel_mean.norm(), 9.8, 1.0) << s.begin;
  }
}

// MPU-6050, raw counts at 100 Hz: 37 s still (z up) at the start, then nine
// hand-held poses of 2.5-7 s, each in a different orientation: ten
// orientations in all, the "ten poses" of the logger including the initial
// period.
TEST(StaticDetectorRealData, Mpu6050TenPose) {
  if (testing_util::RealDataDir().empty()) GTEST_SKIP() << "no real data";
  const ImuLog log = ReadReal("mpu6050_ten_pose.yaml", "mpu6050_ten_pose/session.csv");
  ASSERT_EQ(log.size(), 10245u);
  StaticDetection d;
  ASSERT_TRUE(DetectStaticIntervals(log, StaticDetectorOptions(), &d)) << d.message;
  ASSERT_EQ(d.intervals.size(), 10u) << d.message;
  EXPECT_GT(d.intervals[0].t_end - d.intervals[0].t_begin, 35.0);
  EXPECT_LT(d.intervals[0].t_begin - log.t[0], 1.0);
  for (size_t i = 1; i < d.intervals.size(); ++i) {
    EXPECT_GT(d.intervals[i].t_end - d.intervals[i].t_begin, 2.0) << i;
    // Distinct orientations: every pair of means more than 20 degrees apart.
    for (size_t j = 0; j < i; ++j) {
      const Eigen::Vector3d a = d.intervals[i].accel_mean.normalized();
      const Eigen::Vector3d b = d.intervals[j].accel_mean.normalized();
      EXPECT_LT(a.dot(b), std::cos(20.0 * M_PI / 180.0)) << i << " " << j;
    }
  }
  // Gravity is 16384 counts give or take the sensor's own large errors (the
  // raw norms range over 14900-18600 counts).
  for (const StaticInterval& s : d.intervals) EXPECT_NEAR(s.accel_mean.norm(), 16384, 2800);
}

// Commercial AHRS, 100 Hz, 66 s: nine still poses of 4-7 s. Two of them (at
// 25 s and 46 s) are nearly the same orientation (0.8 degrees apart) but far
// apart in time: two intervals.
TEST(StaticDetectorRealData, AhrsStaticPoses) {
  if (testing_util::RealDataDir().empty()) GTEST_SKIP() << "no real data";
  const ImuLog log = ReadReal("ahrs_static_poses.yaml", "ahrs_static_poses/imu_good1.txt");
  ASSERT_GT(log.size(), 6500u);
  StaticDetection d;
  ASSERT_TRUE(DetectStaticIntervals(log, StaticDetectorOptions(), &d)) << d.message;
  ASSERT_EQ(d.intervals.size(), 9u) << d.message;
  for (const StaticInterval& s : d.intervals) {
    EXPECT_GT(s.t_end - s.t_begin, 4.0);
    EXPECT_NEAR(s.accel_mean.norm(), 9.79871, 0.4);
  }
}

// ck_explorer_poses: 160 poses of exactly 100 samples, published with the
// transitions cut out (consecutive poses 1.5-90 degrees apart, touching
// with a step); the white noise differs 3x between poses (standard
// deviation), the spread 8x, and some poses drift. No rate is given: read
// at 100 Hz, the poses are 1 s long, so the window is 0.3 s, the shortest
// pose 0.5 s and the settling 0.05 s; every window is still (no motion in
// the file), so the variance threshold is lifted: the steps alone must
// separate the poses. Every block comes out as one position (measured: 160;
// without the step split 96, the rest merged or dropped), and the
// calibrated |a| residual is that of the file's own blocks.
TEST(StaticDetectorRealData, CkExplorerCutPoses) {
  if (testing_util::RealDataDir().empty()) GTEST_SKIP() << "no real data";
  Config config;
  std::string error;
  ImuLog log;
  ASSERT_TRUE(LoadConfigText("format: csv\nsample_rate: 100\n", "ck_explorer", &config, &error) &&
              ReadImuLog(testing_util::RealDataDir() + "/ck_explorer_poses/acc_log.csv",
                         config.input, &log, &error))
      << error;
  ASSERT_EQ(log.size(), 16000u);
  for (Eigen::Vector3d& a : log.accel) a *= kGravity;  // g to m/s^2
  StaticDetectorOptions o;
  o.window_seconds = 0.3;
  o.min_duration_seconds = 0.5;
  o.settle_seconds = 0.05;
  o.threshold_factor = 1000.0;
  StaticDetection d;
  ASSERT_TRUE(DetectStaticIntervals(log, o, &d)) << d.message;
  std::printf("ck_explorer: %s\n", d.message.c_str());
  EXPECT_EQ(d.intervals.size(), 160u) << d.message;
  size_t inside = 0;
  for (const StaticInterval& s : d.intervals) inside += s.begin / 100 == (s.end - 1) / 100;
  EXPECT_EQ(inside, d.intervals.size());

  // The rms of |a| - 1 g over the positions after a calibration.
  auto residual = [&](const std::vector<StaticInterval>& intervals) {
    CalibrationOptions co;
    co.gravity.gravity = kGravity;
    Calibration c;
    EXPECT_TRUE(CalibrateFromPositions(PositionsFromIntervals(intervals), co, &c)) << c.message;
    double sum = 0.0;
    for (const StaticInterval& s : intervals) {
      const double r = c.accel.model.Apply(s.accel_mean).norm() - kGravity;
      sum += r * r;
    }
    return std::sqrt(sum / static_cast<double>(intervals.size()));
  };
  const double split = residual(d.intervals);
  // What the file's own blocks give.
  std::vector<StaticInterval> blocks;
  for (size_t b = 0; b < 16000; b += 100) blocks.push_back(MakeInterval(log, b, b + 100));
  const double achievable = residual(blocks);
  StaticDetectorOptions no_steps = o;
  no_steps.step_factor = 0.0;
  StaticDetection merged;
  ASSERT_TRUE(DetectStaticIntervals(log, no_steps, &merged)) << merged.message;
  std::printf(
      "ck_explorer: rms |a| - g %.3g m/s^2 on %zu positions, %.3g on the 160 blocks; "
      "without the step split %zu positions\n",
      split, d.intervals.size(), achievable, merged.intervals.size());
  EXPECT_LT(split, 1.05 * achievable);
  // The detector without the step split merges or loses a third of the poses.
  EXPECT_LT(merged.intervals.size(), 110u);
  // With the default options (a 1 s window, min_duration 2 s: longer than
  // these 1 s holds) the detector fits itself to the holds: every block is
  // one position again (before: none).
  StaticDetection defaults;
  ASSERT_TRUE(DetectStaticIntervals(log, StaticDetectorOptions(), &defaults)) << defaults.message;
  std::printf("ck_explorer, default options: %s\n", defaults.message.c_str());
  EXPECT_NE(defaults.message.find("motion cut out"), std::string::npos) << defaults.message;
  EXPECT_EQ(defaults.intervals.size(), 160u) << defaults.message;
  inside = 0;
  for (const StaticInterval& s : defaults.intervals) inside += s.begin / 100 == (s.end - 1) / 100;
  EXPECT_EQ(inside, defaults.intervals.size());
}

}  // namespace
}  // namespace gravcal
