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
                                const std::vector<double>& interpolation_std,
                                std::vector<ThermalWindow>* windows) {
  if (!(step > 0.0) || !log.has_temperature()) return;
  const double rounding_var = step * step / 12.0;
  int group = 0;
  double previous = NAN;  // The previous window's single reading.
  for (ThermalWindow& w : *windows) {
    // Samples whose temperature is interpolated, and their mean deviation.
    size_t interpolated = 0;
    double std_sum = 0.0;
    for (size_t i = w.begin; i < w.end && i < interpolation_std.size(); ++i) {
      if (interpolation_std[i] >= 0.0) {
        ++interpolated;
        std_sum += interpolation_std[i];
      }
    }
    if (interpolated > 0) {
      const double f = static_cast<double>(interpolated) / static_cast<double>(w.end - w.begin);
      const double sd =
          f * std_sum / static_cast<double>(interpolated) + (1.0 - f) * std::sqrt(rounding_var);
      w.temperature_group = -1;
      w.temperature_variance = std::max(sd * sd, 1e-12);
      previous = NAN;
      continue;
    }
    const auto [lo, hi] =
        std::minmax_element(log.temperature.begin() + w.begin, log.temperature.begin() + w.end);
    const double crossed = std::round((*hi - *lo) / step);
    if (crossed < 0.5) {
      if (!(std::abs(*lo - previous) < 0.5 * step)) ++group;
      w.temperature_group = group;
      w.temperature_variance = rounding_var;
      previous = *lo;
    } else {
      w.temperature_group = -1;
      w.temperature_variance = rounding_var / ((crossed + 1.0) * (crossed + 1.0));
      previous = NAN;
    }
  }
}

void DequantiseTemperature(const std::vector<double>& t, double step,
                           std::vector<double>* temperature,
                           std::vector<double>* interpolation_std) {
  std::vector<double>& v = *temperature;
  const size_t n = v.size();
  interpolation_std->assign(n, -1.0);
  if (!(step > 0.0) || n < 2 || t.size() != n) return;
  // A dated boundary: the crossings of one boundary in a row (one, or a
  // flicker), dated at the middle of the first and last; `direction` +1 /
  // -1 when the readings go through it, 0 when they come back to the same
  // side or jump by several steps (no pass runs through it).
  struct Anchor {
    double boundary = 0.0;
    double first = 0.0;
    double last = 0.0;
    double spacing = 0.0;  // the sample spacing at the crossings
    double before = 0.0;   // the readings before and after
    double after = 0.0;
    int direction = 0;
    double Time() const { return 0.5 * (first + last); }
    // The dating's deviation: uniform over the flicker and a sample spacing.
    double TimeStd() const {
      const double w = (last - first) + spacing;
      return w / std::sqrt(12.0);
    }
  };
  std::vector<Anchor> anchors;
  for (size_t i = 1; i < n; ++i) {
    const double change = v[i] - v[i - 1];
    if (!(std::abs(change) > 0.5 * step)) continue;
    const double time = 0.5 * (t[i] + t[i - 1]);
    const double spacing = t[i] - t[i - 1];
    if (std::abs(std::round(change / step)) != 1.0) {
      Anchor jump;  // several steps at once: a break
      jump.boundary = NAN;
      jump.first = jump.last = time;
      anchors.push_back(jump);
      continue;
    }
    const double boundary = 0.5 * (v[i] + v[i - 1]);
    if (!anchors.empty() && std::abs(anchors.back().boundary - boundary) < 0.25 * step) {
      anchors.back().last = time;
      anchors.back().spacing = std::max(anchors.back().spacing, spacing);
      anchors.back().after = v[i];
      continue;
    }
    Anchor a;
    a.boundary = boundary;
    a.first = a.last = time;
    a.spacing = spacing;
    a.before = v[i - 1];
    a.after = v[i];
    anchors.push_back(a);
  }
  for (Anchor& a : anchors) {
    if (std::isfinite(a.boundary) && (a.after - a.boundary) * (a.before - a.boundary) < 0.0) {
      a.direction = a.after > a.before ? 1 : -1;
    }
  }
  // Interval k runs from anchor k to k + 1: a pass when both are crossed
  // the way it goes (a level traversed from one boundary to the next).
  const size_t intervals = anchors.size() < 2 ? 0 : anchors.size() - 1;
  std::vector<int> direction(intervals, 0);
  std::vector<double> duration(intervals, 0.0);
  for (size_t k = 0; k < intervals; ++k) {
    const Anchor& a = anchors[k];
    const Anchor& b = anchors[k + 1];
    duration[k] = b.Time() - a.Time();
    const int d = b.boundary > a.boundary ? 1 : -1;
    if (a.direction == d && b.direction == d && duration[k] > 0.0 &&
        std::abs(std::abs(b.boundary - a.boundary) - step) < 0.25 * step) {
      direction[k] = d;
    }
  }
  constexpr double kRegularity = 2.0;
  size_t i = 0;
  for (size_t k = 1; k + 1 < intervals; ++k) {
    const int d = direction[k];
    if (d == 0 || direction[k - 1] != d || direction[k + 1] != d) continue;
    const double h0 = duration[k - 1], h = duration[k], h1 = duration[k + 1];
    if (std::max({h0, h, h1}) > kRegularity * std::min({h0, h, h1})) continue;
    const Anchor& a = anchors[k];
    const Anchor& b = anchors[k + 1];
    const double slope = (b.boundary - a.boundary) / h;
    // T'' from the neighbouring intervals' slopes (one step each).
    const double curvature = d * step * (1.0 / h1 - 1.0 / h0) / (0.5 * h0 + h + 0.5 * h1);
    const double bow = std::abs(curvature) * h * h / 8.0;
    const double sa = slope * a.TimeStd(), sb = slope * b.TimeStd();
    const double t0 = a.Time();
    while (i < n && t[i] < t0) ++i;
    for (; i < n && t[i] < b.Time(); ++i) {
      const double u = (t[i] - t0) / h;
      const double shape = 4.0 * u * (1.0 - u) * bow;
      v[i] = a.boundary + slope * (t[i] - t0);
      (*interpolation_std)[i] =
          std::sqrt((1.0 - u) * (1.0 - u) * sa * sa + u * u * sb * sb + shape * shape);
    }
  }
}

}  // namespace gravcal
