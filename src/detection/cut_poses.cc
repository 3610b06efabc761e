#include "detection/cut_poses.h"

#include <algorithm>
#include <cstdio>
#include <vector>

namespace gravcal {
namespace internal {
namespace {

std::string Seconds(double s) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.3g s", s);
  return text;
}

double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// Whether fewer than kCutPoseMinSteps changes can be large (above
// kCutPoseJumpFactor times the median, FitToCutPoses), proved without the
// median: the quarter quantile of a strided sample, L, is at most the
// median when at most size / 2 changes are below it, and then every large
// change is above kCutPoseJumpFactor L. Most logs (continuous motion) have
// none, and skip the median of every change.
bool FewLargeChanges(const std::vector<double>& change) {
  constexpr size_t kStride = 64;
  if (change.size() < 16 * kStride) return false;
  std::vector<double> sample;
  for (size_t i = 0; i < change.size(); i += kStride) sample.push_back(change[i]);
  std::nth_element(sample.begin(), sample.begin() + sample.size() / 4, sample.end());
  const double low = sample[sample.size() / 4];
  if (!(low > 0.0)) return false;
  const double cut = kCutPoseJumpFactor * low;
  size_t below = 0, above = 0;
  bool nan = false;  // (then the median is nth_element's to say)
  for (const double c : change) {
    below += c < low ? 1 : 0;
    above += c > cut ? 1 : 0;
    nan |= c != c;
  }
  return !nan && below <= change.size() / 2 && above < static_cast<size_t>(kCutPoseMinSteps);
}

}  // namespace

std::string FitToCutPoses(const ImuLog& log, double dt, StaticDetectorOptions* options) {
  if (log.size() < 3 || !(dt > 0.0)) return "";
  // |a(i+1) - a(i)|^2 and its median (over the nonzero ones when quantised
  // data repeats samples).
  std::vector<double> change(log.size() - 1);
  bool any_nonzero = false;
  for (size_t i = 0; i + 1 < log.size(); ++i) {
    change[i] = (log.accel[i + 1] - log.accel[i]).squaredNorm();
    any_nonzero |= change[i] > 0.0;
  }
  if (!any_nonzero) return "";
  if (FewLargeChanges(change)) return "";
  double typical = Median(change);
  if (!(typical > 0.0)) {
    std::vector<double> nonzero;
    for (const double c : change) {
      if (c > 0.0) nonzero.push_back(c);
    }
    typical = Median(nonzero);
  }
  auto large = [&](size_t i) { return change[i] > kCutPoseJumpFactor * typical; };
  size_t count = 0;
  std::vector<size_t> steps;  // the isolated ones
  for (size_t i = 0; i < change.size(); ++i) {
    if (!large(i)) continue;
    ++count;
    if ((i == 0 || !large(i - 1)) && (i + 1 == change.size() || !large(i + 1))) steps.push_back(i);
  }
  if (steps.size() < static_cast<size_t>(kCutPoseMinSteps) ||
      static_cast<double>(steps.size()) < kCutPoseIsolatedFraction * static_cast<double>(count)) {
    return "";
  }
  std::vector<double> spacing;
  for (size_t k = 0; k + 1 < steps.size(); ++k) {
    spacing.push_back(static_cast<double>(steps[k + 1] - steps[k]));
  }
  const double samples = Median(spacing);
  if (samples < kCutPoseMinHoldSamples) return "";
  const double hold = samples * dt;
  if (hold - 2.0 * options->settle_seconds >= options->min_duration_seconds &&
      hold >= 2.0 * options->window_seconds) {
    return "";  // the options keep such holds as they are
  }
  options->window_seconds = std::min(options->window_seconds, 0.3 * hold);
  options->min_duration_seconds = std::min(options->min_duration_seconds, 0.5 * hold);
  options->settle_seconds = std::min(options->settle_seconds, 0.05 * hold);
  options->threshold_factor = std::max(options->threshold_factor, kCutPoseThresholdFactor);
  char factor[32];
  std::snprintf(factor, sizeof(factor), "%g", options->threshold_factor);
  return "poses published with the motion cut out (" + std::to_string(steps.size()) +
         " steps and no motion between them, holds of " + Seconds(hold) +
         "): fitted to the holds with window " + Seconds(options->window_seconds) +
         ", min_duration " + Seconds(options->min_duration_seconds) + ", settle " +
         Seconds(options->settle_seconds) + " and threshold_factor " + factor +
         " (the steps alone separate the holds)";
}

}  // namespace internal
}  // namespace gravcal
