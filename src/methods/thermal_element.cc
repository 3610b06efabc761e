// The sensing element's temperature for the thermal fit's lag term
// (ThermalElementSeries, methods/thermal_residual.h).
#include <algorithm>
#include <cmath>

#include "methods/thermal_residual.h"

namespace gravcal {
namespace internal {

ThermalElementSeries::ThermalElementSeries(const ImuLog& log, double step) : h_(step) {
  if (log.t.empty() || !log.has_temperature() || !(step > 0.0)) return;
  t0_ = log.t.front();
  const size_t bins = static_cast<size_t>(std::floor((log.t.back() - t0_) / h_)) + 1;
  std::vector<double> sum(bins, 0.0);
  std::vector<int> count(bins, 0);
  for (size_t i = 0; i < log.size(); ++i) {
    const size_t b = std::min(bins - 1, static_cast<size_t>(std::floor((log.t[i] - t0_) / h_)));
    if (!std::isfinite(log.temperature[i])) continue;
    sum[b] += log.temperature[i];
    ++count[b];
  }
  // Bin means; an empty bin (a gap) repeats the one before.
  s_.resize(bins);
  double last = NAN;
  for (size_t b = 0; b < bins; ++b) {
    if (count[b] > 0) last = sum[b] / count[b];
    s_[b] = last;
  }
  // Leading empty bins take the first mean.
  const auto first = std::find_if(s_.begin(), s_.end(), [](double v) { return std::isfinite(v); });
  if (first == s_.end()) {
    s_.clear();
    return;
  }
  std::fill(s_.begin(), first, *first);
}

void ThermalElementSeries::Update(double tau) const {
  if (tau == tau_ && e_.size() == s_.size()) return;
  tau_ = tau;
  e_.assign(s_.size(), 0.0);
  de_.assign(s_.size(), 0.0);
  if (s_.empty()) return;
  e_[0] = s_[0];
  const double a = tau > 0.0 ? std::exp(-h_ / tau) : 0.0;
  const double da = tau > 0.0 ? a * h_ / (tau * tau) : 0.0;
  for (size_t i = 1; i < s_.size(); ++i) {
    const double m = (s_[i] - s_[i - 1]) / h_;
    const double lead = e_[i - 1] - s_[i - 1] + tau * m;
    e_[i] = s_[i] - tau * m + lead * a;
    de_[i] = -m + (de_[i - 1] + m) * a + lead * da;
  }
}

void ThermalElementSeries::WindowShift(double tau, double t_begin, double t_end, double* shift,
                                       double* derivative) const {
  *shift = 0.0;
  *derivative = 0.0;
  if (s_.empty()) return;
  Update(tau);
  const double last = static_cast<double>(s_.size() - 1);
  const double lo = std::clamp(std::ceil((t_begin - t0_) / h_), 0.0, last);
  const double hi = std::clamp(std::floor((t_end - t0_) / h_), lo, last);
  double sum_shift = 0.0, sum_derivative = 0.0;
  for (size_t i = static_cast<size_t>(lo); i <= static_cast<size_t>(hi); ++i) {
    sum_shift += e_[i] - s_[i];
    sum_derivative += de_[i];
  }
  const double n = hi - lo + 1.0;
  *shift = sum_shift / n;
  *derivative = sum_derivative / n;
}

}  // namespace internal
}  // namespace gravcal
