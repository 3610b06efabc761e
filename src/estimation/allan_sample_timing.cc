// The sampling of a series for the Allan deviation (allan_deviation.h):
// whether it is uniform, and the rate and the bias bound of treating
// jittered time stamps as a uniform grid.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "gravcal/estimation/allan_deviation.h"
#include "util/statistics.h"

namespace gravcal {

using internal::Median;

bool CheckUniformSampling(const std::vector<double>& t, size_t begin, size_t end, double tolerance,
                          double* rate_hz, std::string* error) {
  if (end > t.size() || end < begin + 2) {
    *error = "fewer than two samples";
    return false;
  }
  std::vector<double> steps(end - begin - 1);
  for (size_t i = begin + 1; i < end; ++i) steps[i - begin - 1] = t[i] - t[i - 1];
  const double step = Median(steps);
  if (!(step > 0.0)) {
    *error = "time does not increase (median step " + std::to_string(step) + " s)";
    return false;
  }
  for (size_t i = begin + 1; i < end; ++i) {
    const double d = t[i] - t[i - 1];
    if (std::abs(d - step) > tolerance * step) {
      std::ostringstream s;
      s.precision(6);
      s << "time step at sample " << i << " (t = " << t[i] << " s) is " << d << " s, " << d / step
        << " times the median " << step
        << " s: the Allan deviation needs uniform sampling (tolerance " << 100.0 * tolerance
        << " %)";
      *error = s.str();
      return false;
    }
  }
  *rate_hz = 1.0 / step;
  return true;
}

bool ResolveSampleTiming(const std::vector<double>& t, size_t begin, size_t end,
                         double nominal_rate_hz, double tolerance, double max_bias,
                         double longest_tau, SampleTiming* timing, std::string* error) {
  *timing = SampleTiming();
  if (end > t.size() || end < begin + 2) {
    *error = "fewer than two samples";
    return false;
  }
  const size_t n = end - begin;
  std::vector<double> steps(n - 1);
  size_t off_median = 0;
  for (size_t i = begin + 1; i < end; ++i) steps[i - begin - 1] = t[i] - t[i - 1];
  const double median = Median(steps);
  timing->median_step = median;
  if (!(median > 0.0)) {
    *error = "time does not increase (median step " + std::to_string(median) + " s)";
    return false;
  }
  for (size_t i = begin + 1; i < end; ++i) {
    const double d = t[i] - t[i - 1];
    if (std::abs(d - median) > tolerance * median) ++off_median;
    if (d > timing->largest_step) {
      timing->largest_step = d;
      timing->largest_step_at = i;
    }
  }
  // The rate, then t0 by least squares for it: departures d_i = t_i - t0 - i / rate.
  double rate = 1.0 / median;
  timing->rate_source = "uniform time stamps (1 / median step)";
  if (nominal_rate_hz > 0.0) {
    rate = nominal_rate_hz;
    timing->rate_source = "nominal rate (noise_rate)";
  } else if (off_median > 0) {
    const double mean_index = 0.5 * static_cast<double>(n - 1);
    double mean_t = 0.0;
    for (size_t i = begin; i < end; ++i) mean_t += t[i] - t[begin];
    mean_t /= static_cast<double>(n);
    double sxx = 0.0, sxy = 0.0;
    for (size_t i = 0; i < n; ++i) {
      const double di = static_cast<double>(i) - mean_index;
      sxx += di * di;
      sxy += di * (t[begin + i] - t[begin] - mean_t);
    }
    if (!(sxy > 0.0)) {
      *error = "time does not increase over the log";
      return false;
    }
    rate = sxx / sxy;
    timing->rate_source = "least squares of time on sample index (the time stamps jitter)";
  }
  double mean_departure = 0.0;
  for (size_t i = 0; i < n; ++i) mean_departure += t[begin + i] - t[begin] - i / rate;
  mean_departure /= static_cast<double>(n);
  for (size_t i = 0; i < n; ++i) {
    const double d = std::abs(t[begin + i] - t[begin] - i / rate - mean_departure);
    timing->largest_departure = std::max(timing->largest_departure, d);
  }
  timing->rate_hz = rate;
  timing->unbiased_tau =
      off_median == 0 && nominal_rate_hz <= 0.0 ? 0.0 : timing->largest_departure / max_bias;
  std::ostringstream s;
  s.precision(4);
  s << "samples taken as uniform at " << rate << " Hz from " << timing->rate_source;
  if (off_median > 0 || nominal_rate_hz > 0.0) {
    s << "; " << off_median << " of " << n - 1 << " steps are off the median " << median
      << " s by more than " << 100.0 * tolerance << " %, the largest " << timing->largest_step
      << " s at t = " << t[timing->largest_step_at] << " s; the time stamps depart from the grid "
      << "by up to " << timing->largest_departure << " s: if they were the sample times, the "
      << "Allan deviation would be biased by at most " << 100.0 * max_bias
      << " % for tau >= " << timing->unbiased_tau << " s";
  }
  timing->message = s.str();
  if (longest_tau > 0.0 && timing->unbiased_tau > longest_tau) {
    std::ostringstream e;
    e.precision(4);
    e << "the time stamps depart from a uniform grid at " << rate << " Hz (" << timing->rate_source
      << ") by up to " << timing->largest_departure
      << " s: treating the samples as uniform could bias the Allan deviation by more than "
      << 100.0 * max_bias << " % at every tau up to the longest, " << longest_tau
      << " s (largest step " << timing->largest_step << " s at t = " << t[timing->largest_step_at]
      << " s; noise_max_time_bias sets the bound)";
    *error = e.str();
    return false;
  }
  return true;
}

}  // namespace gravcal
