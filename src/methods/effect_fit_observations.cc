// The observations of the effect fit (effect_fit.h): one per static
// interval, with its gyroscope mean and, from the log's samples, its
// within-pose trend.
#include <Eigen/Core>
#include <algorithm>
#include <string>
#include <vector>

#include "gravcal/methods/effect_fit.h"
#include "methods/within_pose_trend.h"

namespace gravcal {

std::vector<StaticObservation> ObservationsFromIntervals(
    const std::vector<StaticInterval>& intervals, bool has_gyro) {
  const std::vector<Position> positions = PositionsFromIntervals(intervals);
  std::vector<StaticObservation> out(positions.size());
  for (size_t k = 0; k < positions.size(); ++k) {
    out[k].accel = positions[k];
    out[k].has_gyro = has_gyro;
    if (!has_gyro) continue;
    const StaticInterval& s = intervals[k];
    out[k].gyro_mean = s.gyro_mean;
    const double count = static_cast<double>(std::max<size_t>(1, s.count()));
    Eigen::Matrix3d cov = s.gyro_cov / count;
    // A constant (quantised) gyroscope: its mean is known to the rounding,
    // a twelfth of a step squared; the step is a count when the means are
    // integers, else about a millionth of the largest mean.
    const bool integers = (s.gyro_mean.array() == s.gyro_mean.array().round()).all();
    const double step = integers ? 1.0 : 1e-6 * std::max(1.0, s.gyro_mean.cwiseAbs().maxCoeff());
    for (int a = 0; a < 3; ++a) {
      if (!(cov(a, a) > 0.0)) cov(a, a) = step * step / 12.0 / count;
    }
    out[k].gyro_mean_cov = cov;
  }
  return out;
}

bool WithinPoseTrendOptions::IsValid(std::string* error) const {
  if (batches < 4) {
    *error = "within-pose trends: batches must be at least 4";
    return false;
  }
  if (min_batch_samples < 1) {
    *error = "within-pose trends: min_batch_samples must be at least 1";
    return false;
  }
  if (!(min_seconds > 0.0)) {
    *error = "within-pose trends: min_seconds must be positive";
    return false;
  }
  return true;
}

std::vector<StaticObservation> ObservationsFromIntervals(
    const ImuLog& log, const std::vector<StaticInterval>& intervals,
    const WithinPoseTrendOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) return {};
  std::vector<StaticObservation> out = ObservationsFromIntervals(intervals, log.has_gyro());
  const std::vector<internal::PoseTrend> trends =
      internal::WithinPoseTrends(log, intervals, options.batches, options.min_batch_samples,
                                 options.min_seconds, options.along_gravity_only);
  for (size_t k = 0; k < out.size(); ++k) {
    if (!trends[k].valid) continue;
    out[k].has_trend = true;
    out[k].accel_slope = trends[k].accel_slope;
    out[k].accel_slope_cov = trends[k].accel_slope_cov;
    out[k].temperature_slope = trends[k].temperature_slope;
    out[k].trend_along_gravity = options.along_gravity_only;
  }
  return out;
}

WithinPoseTrendOptions GravityTrendOptions(double min_seconds) {
  WithinPoseTrendOptions o;
  o.batches = 5;
  o.along_gravity_only = true;
  o.min_seconds = min_seconds;
  return o;
}

}  // namespace gravcal
