// detection/static_detector_internal.h (private): the pieces the files of
// the static detector share. static_detector.cc runs the detection (quiet
// windows -> runs -> trimmed, merged intervals); window_statistics.cc holds
// the moving-window statistics and noise floors it thresholds;
// step_split.cc splits still runs and intervals at steps in the level.
#ifndef GRAVCAL_SRC_DETECTION_STATIC_DETECTOR_INTERNAL_H_
#define GRAVCAL_SRC_DETECTION_STATIC_DETECTOR_INTERNAL_H_

#include <Eigen/Core>
#include <algorithm>
#include <cstddef>
#include <cstdio>
#include <string>
#include <vector>

#include "gravcal/core/imu_log.h"
#include "gravcal/detection/static_detector.h"

namespace gravcal {
namespace internal {

// The median interval and the quantiles are taken on at most this many
// evenly strided values: exact for logs up to this size, a close estimate
// (and much faster) beyond.
constexpr size_t kMaxQuantileValues = size_t{1} << 14;

// A number as the detector's messages write it (6 significant digits). Not
// called Num: in a unity build other files' anonymous Num share the batch.
inline std::string DetectorNumber(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.6g", v);
  return buf;
}

// The q quantile of values[0, stride, 2 stride, ...] (all of them when there
// are at most kMaxQuantileValues); uses `scratch`.
template <typename T>
double StridedQuantile(const T* values, size_t size, double q, std::vector<double>* scratch) {
  if (size == 0) return 0.0;
  const size_t stride = std::max<size_t>(1, (size + kMaxQuantileValues - 1) / kMaxQuantileValues);
  scratch->clear();
  for (size_t i = 0; i < size; i += stride) scratch->push_back(values[i]);
  const size_t k =
      std::min(scratch->size() - 1, static_cast<size_t>(q * static_cast<double>(scratch->size())));
  std::nth_element(scratch->begin(), scratch->begin() + k, scratch->end());
  return (*scratch)[k];
}

// Samples [begin, end) covered by consecutive quiet windows.
struct QuietRun {
  size_t begin, end;
};

// window_statistics.cc

// Moving-window variance of one 3-axis signal (sum over the axes of the
// population variance of x[k, k+w), k in [0, n - w]) into var[0, n - w].
// Returns false when the signal is not finite.
bool WindowVariance(const std::vector<Eigen::Vector3d>& x, size_t w, float* var);
// Moving-window level change |m2 - m1|^2 of the two half-window means.
void WindowTrend(const std::vector<Eigen::Vector3d>& x, size_t w, float* trend);
// The noise floor of one signal from its windowed variance `var`.
double NoiseFloor(const float* var, size_t num_windows, const std::vector<Eigen::Vector3d>& x,
                  size_t w, const StaticDetectorOptions& options, std::vector<double>* scratch);
// The median time step of `t`.
double MedianSampleInterval(const std::vector<double>& t, std::vector<double>* scratch);
// The scale of the gyroscope's turns (99th percentile of |x - median|).
double RateScale(const std::vector<Eigen::Vector3d>& x, std::vector<double>* scratch);

// step_split.cc

// Every run split at its accelerometer steps; returns the number of steps.
size_t SplitRunsAtSteps(const std::vector<Eigen::Vector3d>& x, size_t w, double floor,
                        double min_change2, const StaticDetectorOptions& options,
                        std::vector<QuietRun>* runs);
// Intervals spread beyond spread_factor times the noise floor split at their
// steps, or kept and named in detection->warnings; returns how many split.
size_t SplitOrFlagSpread(const ImuLog& log, size_t min_count, const StaticDetectorOptions& options,
                         StaticDetection* detection);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_DETECTION_STATIC_DETECTOR_INTERNAL_H_
