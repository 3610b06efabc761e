// gravcal/detection/static_detector.h: finds the intervals in which the IMU was still.
//
// A window_seconds window is quiet when the variance of the accelerometer in
// it (summed over the three axes, raw units squared) is below threshold_factor
// times the noise floor the data itself shows, and so is the gyroscope's
// (gyro_threshold_factor) where the log has one: the `noise_quantile` quantile
// of the windowed variance over the whole log, at most max_floor_ratio times
// the white noise seen in sample-to-sample differences (so that a log with no
// still period yields none). The samples of quiet windows are static. No
// threshold is in physical units, so raw counts, volts and m/s^2 all work with
// the defaults. Runs of static samples, with settle seconds trimmed from each
// edge, at least min_duration long, are the static intervals. Neighbouring
// intervals whose mean accelerometer vectors point the same way (within
// merge_angle_deg), less than merge_gap_windows windows apart, are merged when
// the merged interval as a whole is still below the thresholds: a brief bump
// does not split a pose in two, but a real pick-up-and-put-down in the same
// orientation leaves two intervals rather than averaging the motion in.
// The gyroscope only vetoes clear rotation: a hand-held pose shows tremor of
// 100-250 times the gyroscope's table noise floor (while its accelerometer
// variance stays within 2-5 times the floor), so its factor is much larger.
//
// The detector also reports the stretches that looked like a pose but did
// not become a static interval (StaticDetection::rejected), each with its
// reason: still but too short once trimmed, or nearly still (variances below
// candidate_factor times the thresholds) but moving or rotating too much
// for at least min_duration. Reporting them never changes the intervals.
//
// Variance alone misses slow motion: the slow start and end of a turn, and a
// step between two poses published with the motion cut out, change the
// window's level, not its spread. So the level is judged too, on the
// gyroscope when the log has one (a hand-held pose sways the
// accelerometer's level, not the rate's), else on the accelerometer:
// - a window is still only when the means of its two halves agree: the
//   squared difference summed over the axes is below trend_factor times
//   what noise gives it, |m2 - m1|^2 <= trend_factor * 4 max(var, floor) / w,
//   with var the window's variance and w its length in samples;
// - the ends of each still run whose window means are away from the run's
//   own level (the median of its window means) by more than trend_factor
//   times the noise of a window mean are cut off (the slow ends of a turn).
// A gyroscope's level is far more precise than a hand holds a pose still,
// so for it a change below 1 % of the log's turn rate (the 99th percentile
// of |rate - median|) is never motion. Without a gyroscope, a window of low
// variance whose level changes cuts the run at its centre.
// A still run holds one pose only when its accelerometer level has no step
// (poses published with the motion cut out touch with a step and nothing
// between): at each sample s, a straight line is fitted on each side to the
// w samples [s - w, s) and [s, s + w) (w the window length) and the step is
// the difference d of the two lines at the boundary (so a slow drift, which
// both lines follow, is no step). With r1, r2 the residual variances of the
// lines (summed over the axes: each side's own noise, however it differs
// between poses) and c = (4w - 2) / (w (w + 1)) the variance factor of a
// line's end value, and likewise for the two sides' means m1, m2 and
// variances v1, v2 (a wobble within a pose, which lines extrapolate, shows
// in neither), the step statistic is
//   T(s) = min(|d|^2 / (c (r1 + r2)), w |m2 - m1|^2 / (v1 + v2)).
// The run is split at the s of largest T while T > step_factor and the two
// levels differ by at least step_min_deg, recursively on both parts.
// Each interval is then checked as a whole: when its variance (summed over
// the axes) is above spread_factor times the accelerometer's noise floor, it
// is split at its largest steps in the mean (recursively; parts shorter than
// min_duration are dropped) when every part then lies within the spread;
// otherwise it is kept and named in StaticDetection::warnings as not one
// still pose. Neighbours are merged only when their means agree within
// trend_factor times the noise of a window's mean.
// Time units are checked too: a median time step so long that a window holds
// fewer than 8 samples is refused, naming the unit (ms, us, ns) the time
// column is likely in and the time_scale that fixes it (a 4 kHz log in ms
// reads as 4 Hz), or the window_seconds a log that slow needs.
#ifndef GRAVCAL_DETECTION_STATIC_DETECTOR_H_
#define GRAVCAL_DETECTION_STATIC_DETECTOR_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "gravcal/core/imu_log.h"
#include "gravcal/core/position.h"
#include "gravcal/core/types.h"

namespace gravcal {

struct StaticDetectorOptions {
  // Length of the moving variance window, seconds.
  double window_seconds = 1.0;
  // Quantile of the windowed variance taken as the noise floor.
  double noise_quantile = 0.1;
  // A window is static when its variance is below this times the floor.
  double threshold_factor = 6.0;
  // The same for the gyroscope variance (see above: tremor is not motion).
  double gyro_threshold_factor = 500.0;
  // The floor is at most this times the white-noise variance seen in the
  // sample-to-sample differences, so that a log with no still period at all
  // (whose quietest windows still move) yields no interval. 0 = off.
  double max_floor_ratio = 4.0;
  // Shortest static interval kept, seconds (after trimming).
  double min_duration_seconds = 2.0;
  // Trimmed from each end of a static run, seconds.
  double settle_seconds = 0.3;
  // Use the gyroscope variance as well, when the log has a gyroscope.
  bool use_gyro = true;
  // Adjacent intervals closer than this in direction are one pose, degrees.
  double merge_angle_deg = 3.0;
  // ... and only when the gap between them is shorter than this many windows
  // (and the merged interval is still quiet).
  double merge_gap_windows = 2.0;
  // Runs of windows whose variances are below this times the thresholds,
  // less the static runs inside them, at least min_duration long after
  // trimming, are reported as rejected (moving or rotating too much).
  // Reporting only: the intervals do not depend on it.
  double candidate_factor = 10.0;
  // A window is still only when its two halves' means agree within this
  // times their noise (see above; each sensor). 0 = off.
  double trend_factor = 10.0;
  // An interval whose variance is above this times the accelerometer's noise
  // floor is split at its steps or named in warnings (see above). 0 = off.
  double spread_factor = 25.0;
  // Step change-points within a still run (see above): a step whose
  // statistic is above this splits the run. 0 = off.
  double step_factor = 25.0;
  // ... and only when the two levels are at least this many degrees apart.
  double step_min_deg = 1.0;

  bool IsValid(std::string* error) const;
};

// A stretch of samples [begin, end) that is not a static interval, and why.
struct RejectedStretch {
  size_t begin = 0;
  size_t end = 0;
  // log.t[begin] and log.t[end - 1].
  double t_begin = 0.0;
  double t_end = 0.0;
  RejectionReason reason = RejectionReason::kTooShort;
  // The numbers behind the reason, in words (durations, variance ratios).
  std::string detail;
};

struct StaticDetection {
  std::vector<StaticInterval> intervals;
  // The stretches rejected (see the top of this file), in time order; none
  // overlaps an interval.
  std::vector<RejectedStretch> rejected;
  // What the detector could not resolve and the user should know: a
  // position whose spread is far above the noise (named by its time span),
  // intervals split at steps in the mean. Empty for a clean session.
  std::vector<std::string> warnings;
  // The noise floor and threshold actually used (variance, raw units^2).
  double accel_noise_floor = 0.0;
  double accel_threshold = 0.0;
  double gyro_noise_floor = 0.0;
  double gyro_threshold = 0.0;
  std::string message = "Detection was not run";
};

// Computes the statistics of samples [begin, end) of the log.
StaticInterval MakeInterval(const ImuLog& log, size_t begin, size_t end);

// Returns false (with detection->message saying why) on invalid options or a
// log too short for one window. Finding no interval is not an error.
bool DetectStaticIntervals(const ImuLog& log, const StaticDetectorOptions& options,
                           StaticDetection* detection);

}  // namespace gravcal

#endif  // GRAVCAL_DETECTION_STATIC_DETECTOR_H_
