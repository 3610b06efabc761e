// The static windows of a thermal session (thermal_calibration.h, ThermalWindows).
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "gravcal/methods/thermal_calibration.h"

namespace gravcal {
namespace {

// Slope of the temperature against time over samples [a, b), degrees C/s.
double TemperatureSlope(const ImuLog& log, size_t a, size_t b) {
  if (b <= a + 1) return 0.0;
  double st = 0.0, sy = 0.0;
  for (size_t i = a; i < b; ++i) {
    st += log.t[i];
    sy += log.temperature[i];
  }
  const double n = static_cast<double>(b - a);
  const double mt = st / n, my = sy / n;
  double num = 0.0, den = 0.0;
  for (size_t i = a; i < b; ++i) {
    num += (log.t[i] - mt) * (log.temperature[i] - my);
    den += (log.t[i] - mt) * (log.t[i] - mt);
  }
  return den > 0.0 ? num / den : 0.0;
}

// Mean and covariance of the mean of samples [a, b) of `v`, the covariance
// from the residuals of a straight line in time (a slow drift is not noise).
void DetrendedMean(const std::vector<double>& t, const std::vector<Eigen::Vector3d>& v, size_t a,
                   size_t b, Eigen::Vector3d* mean, Eigen::Matrix3d* mean_cov) {
  const double n = static_cast<double>(b - a);
  double mt = 0.0;
  Eigen::Vector3d mv = Eigen::Vector3d::Zero();
  for (size_t i = a; i < b; ++i) {
    mt += t[i];
    mv += v[i];
  }
  mt /= n;
  mv /= n;
  double stt = 0.0;
  Eigen::Vector3d stv = Eigen::Vector3d::Zero();
  for (size_t i = a; i < b; ++i) {
    stt += (t[i] - mt) * (t[i] - mt);
    stv += (t[i] - mt) * (v[i] - mv);
  }
  const Eigen::Vector3d slope = stt > 0.0 ? Eigen::Vector3d(stv / stt) : Eigen::Vector3d::Zero();
  Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
  for (size_t i = a; i < b; ++i) {
    const Eigen::Vector3d r = v[i] - mv - slope * (t[i] - mt);
    c += r * r.transpose();
  }
  *mean = mv;
  *mean_cov = c / ((n - 2.0) * n);
}

}  // namespace

std::vector<ThermalWindow> ThermalWindows(const ImuLog& log,
                                          const std::vector<StaticInterval>& intervals,
                                          const ThermalCalibrationOptions& options) {
  std::vector<ThermalWindow> windows;
  if (!log.has_temperature()) return windows;
  for (size_t k = 0; k < intervals.size(); ++k) {
    const StaticInterval& in = intervals[k];
    const size_t count = in.end - in.begin;
    if (count < static_cast<size_t>(options.min_window_samples)) continue;
    const double duration = log.t[in.end - 1] - log.t[in.begin];
    const auto [lo, hi] =
        std::minmax_element(log.temperature.begin() + in.begin, log.temperature.begin() + in.end);
    const double change = *hi - *lo;
    int parts =
        static_cast<int>(std::max(std::ceil(duration / options.window_seconds),
                                  std::ceil(change / options.max_window_temperature_change)));
    parts = std::max(1, std::min(parts, static_cast<int>(count / options.min_window_samples)));
    for (int p = 0; p < parts; ++p) {
      ThermalWindow w;
      w.interval = static_cast<int>(k);
      w.begin = in.begin + count * p / parts;
      w.end = in.begin + count * (p + 1) / parts;
      double sum_t = 0.0, sum_temperature = 0.0;
      for (size_t i = w.begin; i < w.end; ++i) {
        sum_t += log.t[i];
        sum_temperature += log.temperature[i];
      }
      const double n = static_cast<double>(w.end - w.begin);
      w.time = sum_t / n;
      w.t_begin = log.t[w.begin];
      w.t_end = log.t[w.end - 1];
      w.temperature = sum_temperature / n;
      // The rate over rate_seconds around the window, all samples.
      const double half = 0.5 * options.rate_seconds;
      const size_t a = std::lower_bound(log.t.begin(), log.t.end(), w.time - half) - log.t.begin();
      const size_t b = std::upper_bound(log.t.begin(), log.t.end(), w.time + half) - log.t.begin();
      w.rate = TemperatureSlope(log, a, b);
      DetrendedMean(log.t, log.accel, w.begin, w.end, &w.accel_mean, &w.accel_mean_cov);
      if (log.has_gyro()) {
        Eigen::Matrix3d c;
        DetrendedMean(log.t, log.gyro, w.begin, w.end, &w.gyro_mean, &c);
        w.gyro_mean_var = c.diagonal().cwiseMax(1e-30);
      }
      windows.push_back(w);
    }
  }
  return windows;
}

}  // namespace gravcal
