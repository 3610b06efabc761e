// The Allan deviation of a uniformly sampled series (allan_deviation.h):
// the overlapping estimate at octave-spaced taus, its equivalent degrees of
// freedom and confidence intervals. The timing checks are in
// allan_sample_timing.cc, the fit of the noise terms in allan_noise_fit.cc.
#include "gravcal/estimation/allan_deviation.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "util/statistics.h"

namespace gravcal {

const char* ToString(AllanNoiseType type) {
  switch (type) {
    case AllanNoiseType::kQuantisation:
      return "quantisation";
    case AllanNoiseType::kWhiteNoise:
      return "white_noise";
    case AllanNoiseType::kBiasInstability:
      return "bias_instability";
    case AllanNoiseType::kRandomWalk:
      return "random_walk";
  }
  return "unknown";
}

double AllanEquivalentDof(AllanNoiseType type, size_t samples, size_t m) {
  const double n = static_cast<double>(samples) + 1.0;  // phase points
  const double mm = static_cast<double>(std::max<size_t>(m, 1));
  double edf = 1.0;
  switch (type) {
    case AllanNoiseType::kQuantisation:
      edf = (n + 1.0) * (n - 2.0 * mm) / (2.0 * (n - mm));
      break;
    case AllanNoiseType::kWhiteNoise:
      edf = (3.0 * (n - 1.0) / (2.0 * mm) - 2.0 * (n - 2.0) / n) * 4.0 * mm * mm /
            (4.0 * mm * mm + 5.0);
      break;
    case AllanNoiseType::kBiasInstability:
      edf = mm == 1.0 ? 2.0 * (n - 2.0) * (n - 2.0) / (2.3 * n - 4.9)
                      : 5.0 * n * n / (4.0 * mm * (n + 3.0 * mm));
      break;
    case AllanNoiseType::kRandomWalk:
      edf = (n - 2.0) / mm * ((n - 1.0) * (n - 1.0) - 3.0 * mm * (n - 1.0) + 4.0 * mm * mm) /
            ((n - 3.0) * (n - 3.0));
      break;
  }
  return std::isfinite(edf) ? std::max(edf, 1.0) : 1.0;
}

bool AllanOptions::IsValid(std::string* error) const {
  if (points_per_octave < 1 || points_per_octave > 64) {
    *error = "allan points_per_octave must be in 1..64";
  } else if (!(max_tau_fraction > 0.0 && max_tau_fraction <= 0.5)) {
    *error = "allan max_tau_fraction must be in (0, 0.5]";
  } else if (!(max_tau >= 0.0) || !std::isfinite(max_tau)) {
    *error = "allan max_tau must be >= 0 seconds";
  } else if (!(time_step_tolerance > 0.0 && time_step_tolerance < 1.0)) {
    *error = "allan time_step_tolerance must be in (0, 1)";
  } else if (!(confidence > 0.0 && confidence < 1.0)) {
    *error = "allan confidence must be in (0, 1)";
  } else {
    return true;
  }
  return false;
}

bool ComputeAllanDeviation(const std::vector<double>& t, const std::vector<double>& x,
                           const AllanOptions& options, AllanDeviation* result) {
  std::string error;
  if (!options.IsValid(&error)) {
    result->message = error;
    return false;
  }
  if (t.size() != x.size()) {
    result->message = "time and value series differ in length";
    return false;
  }
  double rate = 0.0;
  if (!CheckUniformSampling(t, 0, t.size(), options.time_step_tolerance, &rate, &error)) {
    result->message = error;
    return false;
  }
  return ComputeAllanDeviation(x, 0, x.size(), rate, options, result);
}

bool ComputeAllanDeviation(const std::vector<double>& x, size_t begin, size_t end, double rate_hz,
                           const AllanOptions& options, AllanDeviation* result) {
  std::string error;
  if (!options.IsValid(&error)) {
    result->message = error;
    return false;
  }
  if (!(rate_hz > 0.0) || end > x.size() || begin > end) {
    result->message = "invalid sample range or rate";
    return false;
  }
  const size_t n = end - begin;
  const double duration = n / rate_hz;
  size_t m_max = static_cast<size_t>(options.max_tau_fraction * n);
  if (options.max_tau > 0.0) {
    const size_t m_asked = static_cast<size_t>(std::ceil(options.max_tau * rate_hz - 1e-9));
    if (m_asked > m_max) {
      std::ostringstream s;
      s.precision(4);
      s << "the series lasts " << duration << " s, too short for tau up to " << options.max_tau
        << " s: that needs at least " << options.max_tau / options.max_tau_fraction
        << " s (max_tau_fraction " << options.max_tau_fraction << ")";
      result->message = s.str();
      return false;
    }
    m_max = m_asked;
  }
  m_max = std::min(m_max, (n - 1) / 2);
  if (n < 4 || m_max < 1) {
    std::ostringstream s;
    s << "the series has " << n << " samples, too few for one Allan deviation point";
    result->message = s.str();
    return false;
  }

  // Running sums of the mean-removed series (the mean cancels in the second
  // difference; removing it keeps the sums small and exact).
  double mean = 0.0;
  for (size_t i = begin; i < end; ++i) mean += x[i];
  mean /= n;
  std::vector<double> sums(n + 1);
  sums[0] = 0.0;
  for (size_t i = 0; i < n; ++i) sums[i + 1] = sums[i] + (x[begin + i] - mean);

  result->rate_hz = rate_hz;
  result->samples = n;
  result->confidence = options.confidence;
  result->points.clear();
  std::vector<AllanNoiseType> types;
  size_t last_m = 0;
  for (int k = 0;; ++k) {
    const size_t m = static_cast<size_t>(
        std::llround(std::pow(2.0, static_cast<double>(k) / options.points_per_octave)));
    if (m > m_max) break;
    if (m == last_m) continue;
    last_m = m;
    const size_t count = n - 2 * m + 1;
    const double* s = sums.data();
    // Four accumulators: independent chains the compiler can pipeline.
    double acc[4] = {0.0, 0.0, 0.0, 0.0};
    size_t j = 0;
    for (; j + 4 <= count; j += 4) {
      for (int u = 0; u < 4; ++u) {
        const double d = s[j + u + 2 * m] - 2.0 * s[j + u + m] + s[j + u];
        acc[u] += d * d;
      }
    }
    for (; j < count; ++j) {
      const double d = s[j + 2 * m] - 2.0 * s[j + m] + s[j];
      acc[0] += d * d;
    }
    const double total = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    AllanPoint p;
    p.m = m;
    p.tau = m / rate_hz;
    p.adev = std::sqrt(total / (2.0 * static_cast<double>(m) * m * count));
    result->points.push_back(p);
    types.push_back(AllanNoiseType::kWhiteNoise);
  }
  SetAllanConfidence(types, options.confidence, result);
  std::ostringstream s;
  s << result->points.size() << " taus from " << result->points.front().tau << " to "
    << result->points.back().tau << " s over " << n << " samples";
  result->message = s.str();
  return true;
}

void SetAllanConfidence(const std::vector<AllanNoiseType>& types, double confidence,
                        AllanDeviation* curve) {
  const double tail = 0.5 * (1.0 - confidence);
  curve->confidence = confidence;
  for (size_t i = 0; i < curve->points.size() && i < types.size(); ++i) {
    AllanPoint& p = curve->points[i];
    p.edf_noise = types[i];
    p.edf = AllanEquivalentDof(types[i], curve->samples, p.m);
    p.lo = p.adev * std::sqrt(p.edf / internal::ChiSquareQuantile(1.0 - tail, p.edf));
    p.hi = p.adev * std::sqrt(p.edf / internal::ChiSquareQuantile(tail, p.edf));
  }
}

}  // namespace gravcal
