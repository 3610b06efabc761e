// The temperature column of a thermal session: its range and quantisation
// (thermal_calibration.h, InspectTemperatureColumn).
#include <algorithm>
#include <cmath>
#include <sstream>

#include "gravcal/methods/thermal_calibration.h"

namespace gravcal {
namespace {

// The plausible range of a MEMS part's temperature in degrees C (the
// parts' operating ranges are about -40 to 125).
constexpr double kLowestPlausible = -80.0;
constexpr double kHighestPlausible = 200.0;
// Quantisation (header): readings per distinct value, smallest step.
constexpr double kReadingsPerValue = 20.0;
constexpr double kSmallestStep = 0.05;

std::string Text(double v) {
  std::ostringstream s;
  s.precision(4);
  s << v;
  return s.str();
}

}  // namespace

TemperatureColumn InspectTemperatureColumn(const ImuLog& log) {
  TemperatureColumn out;
  if (!log.has_temperature() || log.temperature.empty()) return out;
  std::vector<double> v = log.temperature;
  std::sort(v.begin(), v.end());
  out.min = v.front();
  out.max = v.back();
  out.implausible = out.min < kLowestPlausible || out.max > kHighestPlausible;
  if (out.implausible) {
    out.warnings.push_back(
        "the temp column reads " + Text(out.min) + " to " + Text(out.max) +
        ", not degrees C (raw register counts?): set temp_scale and temp_offset (temp = "
        "temp_offset + temp_scale * value, e.g. 1/132.48 and 25 for an ICM-42688)");
  }
  // The distinct values (equal within a relative 1e-9).
  std::vector<double> distinct;
  for (double t : v) {
    if (distinct.empty() || t - distinct.back() > 1e-9 * std::max(1.0, std::abs(t))) {
      distinct.push_back(t);
    }
  }
  out.distinct = distinct.size();
  if (distinct.size() < 2 ||
      static_cast<double>(v.size()) < kReadingsPerValue * static_cast<double>(distinct.size())) {
    return out;
  }
  double gap = INFINITY;
  for (size_t i = 1; i < distinct.size(); ++i) gap = std::min(gap, distinct[i] - distinct[i - 1]);
  if (!(gap >= kSmallestStep) || out.implausible) return out;
  for (double d : distinct) {
    const double steps = (d - distinct.front()) / gap;
    if (std::abs(steps - std::round(steps)) > 1e-3) return out;
  }
  out.step = gap;
  out.warnings.push_back("the temp column is quantised: " + std::to_string(distinct.size()) +
                         " distinct readings in steps of " + Text(gap) +
                         " degC; each reading is off by up to half a step, which the fit "
                         "carries as an error of step / sqrt(12) = " +
                         Text(gap / std::sqrt(12.0)) +
                         " degC where the temperature holds still (log the temperature with "
                         "its register's full resolution if you can)");
  return out;
}

void SetTemperatureQuantisation(const ImuLog& log, double step,
                                std::vector<ThermalWindow>* windows) {
  if (!(step > 0.0) || !log.has_temperature()) return;
  int group = 0;
  double previous = NAN;  // The previous window's single reading.
  for (ThermalWindow& w : *windows) {
    const auto [lo, hi] =
        std::minmax_element(log.temperature.begin() + w.begin, log.temperature.begin() + w.end);
    const double crossed = std::round((*hi - *lo) / step);
    if (crossed < 0.5) {
      if (!(std::abs(*lo - previous) < 0.5 * step)) ++group;
      w.temperature_group = group;
      w.temperature_variance = step * step / 12.0;
      previous = *lo;
    } else {
      w.temperature_group = -1;
      w.temperature_variance = step * step / (12.0 * (crossed + 1.0) * (crossed + 1.0));
      previous = NAN;
    }
  }
}

}  // namespace gravcal
