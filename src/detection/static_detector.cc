#include "gravcal/detection/static_detector.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <sstream>

#include "detection/cut_poses.h"
#include "detection/static_detector_internal.h"
#include "util/units.h"

namespace gravcal {
namespace {

using internal::MedianSampleInterval;
using internal::NoiseFloor;
using internal::QuietRun;
using internal::RateScale;
using internal::SplitOrFlagSpread;
using internal::SplitRunsAtSteps;
using internal::StridedQuantile;
using internal::WindowTrend;
using internal::WindowVariance;

std::string Num(double v) { return internal::DetectorNumber(v); }

// MakeInterval looks for the accelerometer resolution in this many samples.
constexpr size_t kResolutionSamples = 256;

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double na = a.norm();
  const double nb = b.norm();
  if (na <= 0.0 || nb <= 0.0) return 180.0;
  return std::atan2(a.cross(b).norm(), a.dot(b)) * internal::kRadToDeg;
}

bool Fail(StaticDetection* detection, const std::string& message) {
  detection->message = message;
  return false;
}

}  // namespace

StaticInterval MakeInterval(const ImuLog& log, size_t begin, size_t end) {
  StaticInterval s;
  end = std::min(end, log.size());
  begin = std::min(begin, end);
  s.begin = begin;
  s.end = end;
  s.temperature_mean = std::numeric_limits<double>::quiet_NaN();
  if (begin >= end || log.accel.size() < end) return s;
  s.t_begin = log.t[begin];
  s.t_end = log.t[end - 1];
  const double count = static_cast<double>(end - begin);

  // One pass of sums of deviations from the first sample: within an interval
  // they are of the order of the spread, so there is no cancellation even
  // with raw counts far from zero.
  auto stats = [&](const std::vector<Eigen::Vector3d>& x, Eigen::Vector3d* mean,
                   Eigen::Matrix3d* cov, Eigen::Vector3d* step) {
    using A2 = Eigen::Array2d;  // x and y packed, z scalar
    const double* p = x[0].data();
    const A2 r01 = Eigen::Map<const A2>(p + 3 * begin);
    const double r2 = p[3 * begin + 2];
    A2 s01 = A2::Zero(), c_diag01 = A2::Zero(), c_z01 = A2::Zero();
    double s2 = 0.0, c01 = 0.0, c22 = 0.0;
    for (size_t i = begin; i < end; ++i) {
      const A2 d01 = Eigen::Map<const A2>(p + 3 * i) - r01;
      const double d2 = p[3 * i + 2] - r2;
      s01 += d01;
      c_diag01 += d01 * d01;
      c_z01 += d01 * d2;
      s2 += d2;
      c01 += d01[0] * d01[1];
      c22 += d2 * d2;
    }
    const double s0 = s01[0], s1 = s01[1];
    const double c00 = c_diag01[0], c11 = c_diag01[1], c02 = c_z01[0], c12 = c_z01[1];
    const double inf = std::numeric_limits<double>::infinity();
    double m0 = inf, m1 = inf, m2 = inf;
    if (step) {
      // The resolution shows within a few hundred samples: scan no more.
      for (size_t i = begin + 1; i < std::min(end, begin + kResolutionSamples); ++i) {
        const double a0 = std::abs(p[3 * i] - p[3 * i - 3]);
        const double a1 = std::abs(p[3 * i + 1] - p[3 * i - 2]);
        const double a2 = std::abs(p[3 * i + 2] - p[3 * i - 1]);
        m0 = (a0 > 0.0 && a0 < m0) ? a0 : m0;
        m1 = (a1 > 0.0 && a1 < m1) ? a1 : m1;
        m2 = (a2 > 0.0 && a2 < m2) ? a2 : m2;
      }
      *step = Eigen::Vector3d(m0 < inf ? m0 : 0.0, m1 < inf ? m1 : 0.0, m2 < inf ? m2 : 0.0);
    }
    const Eigen::Vector3d s(s0, s1, s2);
    *mean = Eigen::Vector3d(r01[0], r01[1], r2) + s / count;
    Eigen::Matrix3d c;
    c << c00, c01, c02, c01, c11, c12, c02, c12, c22;
    c -= s * s.transpose() / count;
    *cov = end - begin > 1 ? Eigen::Matrix3d(c / (count - 1.0)) : Eigen::Matrix3d::Zero();
  };
  stats(log.accel, &s.accel_mean, &s.accel_cov, &s.accel_resolution);
  if (log.gyro.size() >= end) stats(log.gyro, &s.gyro_mean, &s.gyro_cov, nullptr);
  if (log.temperature.size() >= end) {
    double sum = 0.0;
    for (size_t i = begin; i < end; ++i) sum += log.temperature[i];
    s.temperature_mean = sum / count;
  }
  return s;
}

namespace {

// The log's columns have one length, at least 3 samples and increasing
// finite time; the message names the log.
bool CheckDetectionInput(const ImuLog& log, const std::string& name, std::string* message) {
  const size_t n = log.size();
  if (log.accel.size() != n) {
    *message = name + ": accelerometer and time have different lengths";
  } else if (!log.gyro.empty() && log.gyro.size() != n) {
    *message = name + ": gyroscope and time have different lengths";
  } else if (!log.temperature.empty() && log.temperature.size() != n) {
    *message = name + ": temperature and time have different lengths";
  } else if (n < 3) {
    *message = name + ": " + std::to_string(n) + " samples are too few";
  } else {
    for (size_t i = 1; i < n; ++i) {
      if (!(log.t[i] > log.t[i - 1]) || !std::isfinite(log.t[i])) {
        *message =
            name + ": sample " + std::to_string(i) + ": time is not finite or does not increase";
        return false;
      }
    }
    return true;
  }
  return false;
}

// The windowed statistics of one sensor: variance, level change (null when
// trend_factor is 0) and the noise floor.
struct SensorWindows {
  const float* var = nullptr;
  const float* trend = nullptr;
  double floor = 0.0;
  // Level changes (squared, summed over the axes) up to this are no motion
  // whatever the noise (see kGyroLevelFraction).
  double min_change2 = 0.0;
};

// See TrimLevelEnds' use.
constexpr double kGyroLevelFraction = 0.01;
// A step of the rate splits a still run only when the two levels differ by
// at least this fraction of the log's turn rate (RateScale): a constant turn
// started or stopped is a large part of it, a hand's sway within a pose a
// few percent at most (measured: 1 % split a hand-held MPU-6050 pose).
constexpr double kGyroStepFraction = 0.1;
// TrimLevelEnds trims at most this many windows from each end of a run.
constexpr size_t kMaxTrimWindows = 5;

// The ends of each run where the sensor's level (its window mean) is away
// from the run's own (the median of its window means, per axis) by more
// than trend_factor times the noise of a window mean are cut off: the slow
// start and end of a turn, whose rate is small but not zero. The run's
// level, not a global one, so that a bias that differs from pose to pose
// (g-sensitivity, drift) is no motion. Runs left shorter than a window are
// dropped.
void TrimLevelEnds(const std::vector<Eigen::Vector3d>& x, const SensorWindows& s, size_t w,
                   double trend_factor, std::vector<QuietRun>* runs) {
  const double min_change2 = s.min_change2;
  std::vector<QuietRun> kept;
  std::vector<Eigen::Vector3d> means;
  std::vector<double> scratch;
  for (const QuietRun& run : *runs) {
    // Windows k in [run.begin, run.end - w] lie inside the run.
    means.clear();
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    const Eigen::Vector3d r = x[run.begin];
    for (size_t i = run.begin; i < run.begin + w; ++i) sum += x[i] - r;
    for (size_t k = run.begin;; ++k) {
      means.push_back(sum / static_cast<double>(w));
      if (k + w >= run.end) break;
      sum += x[k + w] - x[k];
    }
    Eigen::Vector3d level;
    for (int a = 0; a < 3; ++a) {
      scratch.clear();
      for (const Eigen::Vector3d& m : means) scratch.push_back(m[a]);
      std::nth_element(scratch.begin(), scratch.begin() + scratch.size() / 2, scratch.end());
      level[a] = scratch[scratch.size() / 2];
    }
    auto steady = [&](size_t j) {
      const double var = std::max<double>(s.var[run.begin + j], s.floor);
      const double change2 = (means[j] - level).squaredNorm();
      return change2 <= min_change2 || change2 * static_cast<double>(w) <= trend_factor * var;
    };
    // At most kMaxTrimWindows windows from each end: a turn's slow end, not
    // the wander of a long still log's bias.
    const size_t max_trim = kMaxTrimWindows * w;
    size_t first = 0, last = means.size();
    while (first < means.size() && first < max_trim && !steady(first)) ++first;
    while (last > first && means.size() - last < max_trim && !steady(last - 1)) --last;
    if (last > first) kept.push_back({run.begin + first, run.begin + last - 1 + w});
  }
  *runs = std::move(kept);
}

// Whether window j of the sensor has its two halves' means within
// `trend_factor` times their noise (top of static_detector.h).
bool LevelSteady(const SensorWindows& s, size_t j, size_t w, double trend_factor) {
  if (s.trend == nullptr) return true;
  const double var = std::max<double>(s.var[j], s.floor);
  return s.trend[j] <= s.min_change2 ||
         static_cast<double>(s.trend[j]) * static_cast<double>(w) <= trend_factor * 4.0 * var;
}

// Static runs: the union of the quiet windows' samples (window k covers
// samples [k, k + w)); gyro.var is null when the gyroscope is not used.
std::vector<QuietRun> FindQuietRuns(const SensorWindows& accel, const SensorWindows& gyro,
                                    size_t num_windows, size_t w, double accel_threshold,
                                    double gyro_threshold, double trend_factor,
                                    bool split_at_steps) {
  std::vector<QuietRun> runs;
  auto low_variance = [&](size_t j) {
    return accel.var[j] <= accel_threshold &&
           (gyro.var == nullptr || gyro.var[j] <= gyro_threshold);
  };
  auto steady = [&](size_t j) {
    return LevelSteady(accel, j, w, trend_factor) &&
           (gyro.var == nullptr || LevelSteady(gyro, j, w, trend_factor));
  };
  // Without a gyroscope, a window of low variance whose accelerometer level
  // changes cuts the runs at its centre: only the windows centred on a step
  // (poses published with the motion cut out) show it, so unlike a variance
  // jump it leaves no gap of w windows between the runs. When the runs are
  // split at their steps afterwards (split_at_steps), which places the split
  // at the step itself, not at a window's centre, the runs are not cut.
  const bool cuts = accel.trend != nullptr && gyro.var == nullptr && !split_at_steps;
  size_t cut = 0;
  for (size_t k = 0; k < num_windows;) {
    if (!(low_variance(k) && steady(k))) {
      if (cuts && low_variance(k)) cut = k + w / 2;
      ++k;
      continue;
    }
    const size_t first = k;
    while (k < num_windows && low_variance(k) && steady(k)) ++k;
    const size_t end = k - 1 + w;
    // Quiet windows less than w apart share samples: one run, unless a
    // level change cut it; then the two meet at the cut.
    if (!runs.empty() && first <= runs.back().end) {
      if (cut <= runs.back().begin) {
        runs.back().end = end;
        continue;
      }
      const size_t begin = std::max(first, cut);
      runs.back().end = std::min(runs.back().end, begin);
      runs.push_back({begin, end});
    } else {
      runs.push_back({first, end});
    }
  }
  // Runs cut to nothing are dropped.
  runs.erase(
      std::remove_if(runs.begin(), runs.end(), [](const QuietRun& r) { return r.end <= r.begin; }),
      runs.end());
  return runs;
}

RejectedStretch MakeRejected(const ImuLog& log, size_t begin, size_t end, RejectionReason reason,
                             const std::string& detail) {
  RejectedStretch r;
  r.begin = begin;
  r.end = end;
  r.t_begin = log.t[begin];
  r.t_end = log.t[end - 1];
  r.reason = reason;
  r.detail = detail;
  return r;
}

// Trim the settling time at each end, merge neighbours that are the same pose
// across a short gap (when the merged interval still looks still as a whole,
// so that a real pick-up-and-put-down is not averaged in), keep what has at
// least min_count samples; the runs that are too short go to *rejected
// (with the samples of the whole run, settling time included).
std::vector<StaticInterval> TrimAndMerge(const ImuLog& log, const std::vector<QuietRun>& runs,
                                         size_t settle, size_t min_count, size_t w,
                                         const StaticDetectorOptions& options,
                                         const StaticDetection& detection, bool use_gyro,
                                         std::vector<RejectedStretch>* rejected) {
  const double max_gap = options.merge_gap_windows * static_cast<double>(w);
  std::vector<StaticInterval> pieces;
  std::vector<QuietRun> piece_runs;
  for (const QuietRun& run : runs) {
    if (run.end - run.begin <= 2 * settle) {
      rejected->push_back(
          MakeRejected(log, run.begin, run.end, RejectionReason::kTooShort,
                       "still for " + Num(log.t[run.end - 1] - log.t[run.begin]) +
                           " s, no longer than the settling time trimmed from its two ends (2 x " +
                           Num(options.settle_seconds) + " s)"));
      continue;
    }
    pieces.push_back(MakeInterval(log, run.begin + settle, run.end - settle));
    piece_runs.push_back(run);
  }
  std::vector<StaticInterval> intervals;
  for (size_t i = 0; i < pieces.size(); ++i) {
    StaticInterval current = pieces[i];
    const size_t first = i;
    while (i + 1 < pieces.size()) {
      const StaticInterval& next = pieces[i + 1];
      if (!(static_cast<double>(next.begin - current.end) < max_gap) ||
          !(AngleDeg(current.accel_mean, next.accel_mean) < options.merge_angle_deg)) {
        break;
      }
      // A step in the mean across the gap is a new pose, however small the
      // turn: the means must agree within trend_factor times the noise of a
      // window's mean (no finer: hand-held noise is not white).
      if (options.trend_factor > 0.0) {
        // The windows on either side of the gap, not the whole intervals:
        // a long still log's bias wanders between distant samples.
        const size_t na = std::min(current.count(), w);
        const size_t nb = std::min(next.count(), w);
        const Eigen::Vector3d ma = MakeInterval(log, current.end - na, current.end).accel_mean;
        const Eigen::Vector3d mb = MakeInterval(log, next.begin, next.begin + nb).accel_mean;
        const double noise = detection.accel_noise_floor *
                             (1.0 / static_cast<double>(na) + 1.0 / static_cast<double>(nb));
        if (!((ma - mb).squaredNorm() <= options.trend_factor * noise)) break;
      }
      StaticInterval merged = MakeInterval(log, current.begin, next.end);
      if (!(merged.accel_cov.trace() <= detection.accel_threshold) ||
          (use_gyro && !(merged.gyro_cov.trace() <= detection.gyro_threshold))) {
        break;
      }
      current = merged;
      ++i;
    }
    if (current.count() >= min_count) {
      intervals.push_back(current);
    } else {
      rejected->push_back(MakeRejected(
          log, piece_runs[first].begin, piece_runs[i].end, RejectionReason::kTooShort,
          "still for " + Num(current.t_end - current.t_begin) + " s after trimming " +
              Num(options.settle_seconds) + " s at each end, shorter than min_duration_seconds (" +
              Num(options.min_duration_seconds) + " s)"));
    }
  }
  return intervals;
}

// The nearly still stretches that are not static: runs of windows whose
// variances are below candidate_factor times the thresholds, less the quiet
// runs inside them; what is left and at least min_count samples long once
// trimmed goes to *rejected as too much motion (the accelerometer was above
// its threshold somewhere) or rotating (only the gyroscope was). `quiet` are
// the quiet runs, in time order.
void NearlyStillStretches(const ImuLog& log, const SensorWindows& accel, const SensorWindows& gyro,
                          size_t num_windows, size_t w, const std::vector<QuietRun>& quiet,
                          size_t settle, size_t min_count, const StaticDetectorOptions& options,
                          const StaticDetection& detection,
                          std::vector<RejectedStretch>* rejected) {
  const double f = options.candidate_factor;
  const float* accel_var = accel.var;
  const float* gyro_var = gyro.var;
  const std::vector<QuietRun> loose = FindQuietRuns(
      accel, gyro, num_windows, w, f * detection.accel_threshold, f * detection.gyro_threshold,
      f * options.trend_factor, options.step_factor > 0.0);
  std::vector<double> scratch;
  auto report = [&](size_t begin, size_t end) {
    if (end < begin + w || end - begin < min_count + 2 * settle) return;
    // Not inside an interval merged across a gap.
    for (const StaticInterval& s : detection.intervals) {
      if (begin < s.end && s.begin < end) return;
    }
    // No window inside [begin, end) is quiet: the typical (median) ratios
    // of the variances to their thresholds say why (the ends of the
    // stretch are the ends of motions).
    std::vector<double> accel_ratio, gyro_ratio, accel_level, gyro_level;
    // The level change over what noise gives it, as in LevelSteady.
    auto level = [&](const SensorWindows& sw, size_t k) {
      const double var = std::max<double>(sw.var[k], sw.floor);
      return static_cast<double>(sw.trend[k]) * static_cast<double>(w) /
             (options.trend_factor * 4.0 * var);
    };
    for (size_t k = begin; k + w <= end; ++k) {
      accel_ratio.push_back(accel_var[k] / detection.accel_threshold);
      if (gyro_var) gyro_ratio.push_back(gyro_var[k] / detection.gyro_threshold);
      if (accel.trend) accel_level.push_back(level(accel, k));
      if (gyro.trend) gyro_level.push_back(level(gyro, k));
    }
    auto median = [&](const std::vector<double>& v) {
      return StridedQuantile(v.data(), v.size(), 0.5, &scratch);
    };
    const double accel_median = median(accel_ratio);
    const double gyro_median = median(gyro_ratio);
    const double accel_level_median = median(accel_level);
    const double gyro_level_median = median(gyro_level);
    const std::string seconds = Num(log.t[end - 1] - log.t[begin]);
    if (accel_median > 1.0 || (gyro_var == nullptr && accel_level_median <= 1.0)) {
      rejected->push_back(MakeRejected(log, begin, end, RejectionReason::kTooMuchMotion,
                                       "nearly still for " + seconds +
                                           " s, but the accelerometer variance was typically " +
                                           Num(accel_median) + " times its threshold"));
    } else if (accel_level_median > 1.0) {
      rejected->push_back(MakeRejected(
          log, begin, end, RejectionReason::kTooMuchMotion,
          "nearly still for " + seconds +
              " s, but the accelerometer's level was changing (slow motion): its half-window "
              "means differed by typically " +
              Num(accel_level_median) + " times the trend threshold"));
    } else if (gyro_median > 1.0 || gyro_level_median <= 1.0) {
      rejected->push_back(MakeRejected(log, begin, end, RejectionReason::kRotating,
                                       "the accelerometer was nearly still for " + seconds +
                                           " s, but the gyroscope variance was typically " +
                                           Num(gyro_median) + " times its threshold"));
    } else {
      rejected->push_back(MakeRejected(
          log, begin, end, RejectionReason::kRotating,
          "the accelerometer was nearly still for " + seconds +
              " s, but the gyroscope showed a slow turn: its half-window means differed by "
              "typically " +
              Num(gyro_level_median) + " times the trend threshold"));
    }
  };
  size_t q = 0;
  for (const QuietRun& run : loose) {
    // A quiet run can reach into this loose run from the previous one.
    size_t cursor = q > 0 ? std::max(run.begin, quiet[q - 1].end) : run.begin;
    for (; q < quiet.size() && quiet[q].begin < run.end; ++q) {
      if (quiet[q].begin > cursor) report(cursor, quiet[q].begin);
      cursor = std::max(cursor, quiet[q].end);
    }
    if (run.end > cursor) report(cursor, run.end);
  }
}

// A window holds at least this many samples: fewer give no usable
// variance or level (the detector's statistics), and a time column in ms
// read as seconds shows as a rate 1000 times too low (a 4 kHz log as 4 Hz:
// four samples per 1 s window, which made 1064 "positions" of a 12-pose
// session before this check).
constexpr double kMinWindowSamples = 8.0;

// A time step so long that a window holds fewer than kMinWindowSamples is
// most likely a time column in another unit; the message names the likely
// one, or the window a slow log needs.
std::string TimeUnitMessage(const std::string& name, double dt, double window_seconds) {
  std::string message = name + ": the median time step is " + Num(dt) + " s (" + Num(1.0 / dt) +
                        " Hz), too long for the " + Num(window_seconds) +
                        " s window (it would hold " + Num(std::floor(window_seconds / dt)) +
                        " samples, fewer than " + Num(kMinWindowSamples) + ")";
  const std::string slow = "; or, for a log this slow, give window_seconds: " +
                           Num(std::ceil(kMinWindowSamples * dt * 10.0) / 10.0) + " or more";
  const struct {
    double scale;
    const char* unit;
  } units[] = {{1e-3, "milliseconds"}, {1e-6, "microseconds"}, {1e-9, "nanoseconds"}};
  for (const auto& u : units) {
    const double rate = 1.0 / (dt * u.scale);
    if (rate >= 5.0 && rate <= 1e5) {
      return message + ": the time column looks like " + u.unit + " (" + Num(rate) +
             " Hz if so); set time_scale: " + Num(u.scale) + slow;
    }
  }
  return message + ": check the time column's unit (time_scale)" + slow;
}

}  // namespace

bool DetectStaticIntervals(const ImuLog& log, const StaticDetectorOptions& given,
                           StaticDetection* detection) {
  if (detection == nullptr) return false;
  *detection = StaticDetection();
  std::string error;
  if (!given.IsValid(&error)) return Fail(detection, error);
  StaticDetectorOptions options = given;
  const std::string name = log.source.empty() ? std::string("log") : log.source;
  if (!CheckDetectionInput(log, name, &error)) return Fail(detection, error);
  const size_t n = log.size();
  std::vector<double> scratch;
  const double dt = MedianSampleInterval(log.t, &scratch);
  // Holds of poses published with the motion cut out, shorter than the
  // options keep: the time scales fitted to them (detection/cut_poses.h).
  const std::string fitted = internal::FitToCutPoses(log, dt, &options);
  // Durations in samples, at most n + 1 (no overflow for absurd durations).
  auto to_samples = [dt, n](double seconds) {
    const double samples = seconds / dt;
    return samples < static_cast<double>(n) ? static_cast<size_t>(std::llround(samples)) : n + 1;
  };
  if (options.window_seconds < kMinWindowSamples * dt) {
    return Fail(detection, TimeUnitMessage(name, dt, options.window_seconds));
  }
  const size_t w = std::max<size_t>(2, to_samples(options.window_seconds));
  if (n < w) {
    return Fail(detection, name + ": " + std::to_string(n) + " samples are shorter than one " +
                               Num(options.window_seconds) + " s window (" + std::to_string(w) +
                               " samples)");
  }

  // Windowed variances (float: half the memory traffic, ample precision for
  // a threshold) and noise floors.
  const size_t num_windows = n - w + 1;
  // Not value-initialised: every element is written.
  std::unique_ptr<float[]> accel_var(new float[num_windows]);
  std::unique_ptr<float[]> gyro_var;
  if (!WindowVariance(log.accel, w, accel_var.get()))
    return Fail(detection, name + ": accelerometer values are not finite");
  detection->accel_noise_floor =
      NoiseFloor(accel_var.get(), num_windows, log.accel, w, options, &scratch);
  detection->accel_threshold = options.threshold_factor * detection->accel_noise_floor;
  const bool use_gyro = !log.gyro.empty() && options.use_gyro;
  if (use_gyro) {
    gyro_var.reset(new float[num_windows]);
    if (!WindowVariance(log.gyro, w, gyro_var.get()))
      return Fail(detection, name + ": gyroscope values are not finite");
    detection->gyro_noise_floor =
        NoiseFloor(gyro_var.get(), num_windows, log.gyro, w, options, &scratch);
    detection->gyro_threshold = options.gyro_threshold_factor * detection->gyro_noise_floor;
  }

  // Level changes (slow motion, steps).
  std::unique_ptr<float[]> accel_trend, gyro_trend;
  SensorWindows accel{accel_var.get(), nullptr, detection->accel_noise_floor};
  SensorWindows gyro{gyro_var.get(), nullptr, detection->gyro_noise_floor};
  // The level is judged on the gyroscope when there is one (a hand-held
  // pose sways the accelerometer's level, not the rate's), else on the
  // accelerometer. A gyroscope's level is far more precise than a hand
  // holds it still (a hand-held pose turns at a fraction of a degree per
  // second): a change below kGyroLevelFraction of the log's turn rate (the
  // 99th percentile of |rate - median|) is no turn.
  if (options.trend_factor > 0.0) {
    if (use_gyro) {
      gyro_trend.reset(new float[num_windows]);
      WindowTrend(log.gyro, w, gyro_trend.get());
      gyro.trend = gyro_trend.get();
      const double min_change = kGyroLevelFraction * RateScale(log.gyro, &scratch);
      gyro.min_change2 = min_change * min_change;
    } else {
      accel_trend.reset(new float[num_windows]);
      WindowTrend(log.accel, w, accel_trend.get());
      accel.trend = accel_trend.get();
    }
  }

  std::vector<QuietRun> runs =
      FindQuietRuns(accel, gyro, num_windows, w, detection->accel_threshold,
                    detection->gyro_threshold, options.trend_factor, options.step_factor > 0.0);
  size_t steps = SplitRunsAtSteps(log.accel, w, detection->accel_noise_floor, 0.0, options, &runs);
  // A step of the rate alone (a constant turn about gravity started or
  // stopped with the motion cut out) splits too.
  if (gyro.trend != nullptr && gyro.min_change2 > 0.0) {
    const double ratio = kGyroStepFraction / kGyroLevelFraction;
    steps += SplitRunsAtSteps(log.gyro, w, detection->gyro_noise_floor,
                              ratio * ratio * gyro.min_change2, options, &runs);
  }
  if (options.trend_factor > 0.0) {
    TrimLevelEnds(use_gyro ? log.gyro : log.accel, use_gyro ? gyro : accel, w, options.trend_factor,
                  &runs);
  }
  const size_t settle = to_samples(options.settle_seconds);
  const size_t min_count = std::max<size_t>(1, to_samples(options.min_duration_seconds));
  detection->intervals = TrimAndMerge(log, runs, settle, min_count, w, options, *detection,
                                      use_gyro, &detection->rejected);
  const size_t split = SplitOrFlagSpread(log, min_count, options, detection);
  NearlyStillStretches(log, accel, gyro, num_windows, w, runs, settle, min_count, options,
                       *detection, &detection->rejected);
  std::sort(detection->rejected.begin(), detection->rejected.end(),
            [](const RejectedStretch& a, const RejectedStretch& b) { return a.begin < b.begin; });

  std::ostringstream msg;
  msg << name << ": " << detection->intervals.size() << " static interval"
      << (detection->intervals.size() == 1 ? "" : "s") << " (window " << w
      << " samples, accel threshold " << Num(detection->accel_threshold);
  if (use_gyro) msg << ", gyro threshold " << Num(detection->gyro_threshold);
  msg << ")";
  if (steps > 0) {
    msg << "; " << steps << " step" << (steps == 1 ? "" : "s") << " between touching poses";
  }
  if (split > 0) {
    msg << "; " << split << " split at steps in the mean";
  }
  if (!fitted.empty()) msg << "; " << fitted;
  if (!detection->rejected.empty()) {
    msg << "; " << detection->rejected.size() << " stretch"
        << (detection->rejected.size() == 1 ? "" : "es") << " rejected";
  }
  detection->message = msg.str();
  return true;
}

}  // namespace gravcal
