#include "methods/within_pose_trend.h"

#include <Eigen/LU>
#include <cmath>

namespace gravcal {
namespace internal {
namespace {

// One pose's line through its batch means, before pooling.
struct BatchLine {
  bool valid = false;
  Eigen::Vector3d slope = Eigen::Vector3d::Zero();
  double temperature_slope = 0.0;
  // Sum of squared deviations of the batch times (D_k), samples per batch
  // (m_k) and the scatter about the line (R_k).
  double time_spread = 0.0;
  int batch_samples = 0;
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
};

BatchLine FitBatchLine(const ImuLog& log, const StaticInterval& s, int batches) {
  BatchLine line;
  const int m = static_cast<int>(s.count()) / batches;
  const bool has_temperature = log.has_temperature();
  std::vector<Eigen::Vector3d> y(batches, Eigen::Vector3d::Zero());
  std::vector<double> tau(batches, 0.0), theta(batches, 0.0);
  for (int j = 0; j < batches; ++j) {
    const size_t first = s.begin + static_cast<size_t>(j) * m;
    for (size_t i = first; i < first + m; ++i) {
      y[j] += log.accel[i];
      tau[j] += log.t[i];
      if (has_temperature) theta[j] += log.temperature[i];
    }
    y[j] /= m;
    tau[j] /= m;
    theta[j] /= m;
  }
  Eigen::Vector3d y_mean = Eigen::Vector3d::Zero();
  double tau_mean = 0.0, theta_mean = 0.0;
  for (int j = 0; j < batches; ++j) {
    y_mean += y[j] / batches;
    tau_mean += tau[j] / batches;
    theta_mean += theta[j] / batches;
  }
  Eigen::Vector3d cross = Eigen::Vector3d::Zero();
  double spread = 0.0, theta_cross = 0.0;
  for (int j = 0; j < batches; ++j) {
    const double d = tau[j] - tau_mean;
    spread += d * d;
    cross += d * (y[j] - y_mean);
    theta_cross += d * (theta[j] - theta_mean);
  }
  if (!(spread > 0.0)) return line;
  line.slope = cross / spread;
  line.temperature_slope = has_temperature ? theta_cross / spread : 0.0;
  for (int j = 0; j < batches; ++j) {
    const Eigen::Vector3d e = y[j] - y_mean - line.slope * (tau[j] - tau_mean);
    line.scatter += e * e.transpose();
  }
  line.time_spread = spread;
  line.batch_samples = m;
  line.valid =
      line.slope.allFinite() && line.scatter.allFinite() && std::isfinite(line.temperature_slope);
  return line;
}

}  // namespace

std::vector<PoseTrend> WithinPoseTrends(const ImuLog& log,
                                        const std::vector<StaticInterval>& intervals, int batches,
                                        int min_batch_samples, double min_seconds,
                                        bool along_gravity) {
  std::vector<PoseTrend> trends(intervals.size());
  std::vector<BatchLine> lines(intervals.size());
  Eigen::Matrix3d pooled = Eigen::Matrix3d::Zero();
  double dof = 0.0;
  int usable = 0;
  for (size_t k = 0; k < intervals.size(); ++k) {
    const StaticInterval& s = intervals[k];
    if (s.end > log.accel.size() || s.end > log.t.size() ||
        static_cast<int>(s.count()) < batches * min_batch_samples ||
        !(s.t_end - s.t_begin >= min_seconds)) {
      continue;
    }
    lines[k] = FitBatchLine(log, s, batches);
    if (!lines[k].valid) continue;
    pooled += lines[k].batch_samples * lines[k].scatter;
    dof += batches - 2;
    ++usable;
  }
  // Fewer than two poses, or too few degrees of freedom for the factor:
  // no trends (the fit keeps the magnitudes alone).
  if (usable < 2 || !(dof > 8.0)) return trends;
  const Eigen::Matrix3d per_sample = pooled / (dof - (along_gravity ? 2.0 : 4.0));
  for (size_t k = 0; k < intervals.size(); ++k) {
    if (!lines[k].valid) continue;
    Eigen::Matrix3d batch_cov = per_sample / lines[k].batch_samples;
    for (int a = 0; a < 3; ++a) {
      const double step = intervals[k].accel_resolution(a);
      if (!(batch_cov(a, a) > 0.0)) batch_cov(a, a) = step * step / 12.0;
    }
    if (!(batch_cov.determinant() > 0.0)) continue;
    trends[k].valid = true;
    trends[k].accel_slope = lines[k].slope;
    trends[k].accel_slope_cov = batch_cov / lines[k].time_spread;
    trends[k].temperature_slope = lines[k].temperature_slope;
  }
  return trends;
}

}  // namespace internal
}  // namespace gravcal
