#include "gravcal/estimation/allan_deviation.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>

#include "util/statistics.h"

namespace gravcal {

using internal::Median;

namespace internal {
namespace {

constexpr int kTerms = 4;  // quantisation, white noise, bias instability, random walk

// g_j(tau): the Allan variance per unit coefficient of each term.
double Shape(int term, double tau) {
  switch (term) {
    case 0:
      return 3.0 / (tau * tau);
    case 1:
      return 1.0 / tau;
    case 2:
      return kFlickerAllanFactor;
    default:
      return tau / 3.0;
  }
}

AllanNoiseType TypeOf(int term) { return static_cast<AllanNoiseType>(term); }

NoiseTerm* TermOf(int term, AxisNoiseModel* model) {
  switch (term) {
    case 0:
      return &model->quantisation;
    case 1:
      return &model->white_noise;
    case 2:
      return &model->bias_instability;
    default:
      return &model->random_walk;
  }
}

using Coefficients = std::array<double, kTerms>;

double ModelVariance(const Coefficients& c, double tau) {
  double v = 0.0;
  for (int j = 0; j < kTerms; ++j) v += c[j] * Shape(j, tau);
  return v;
}

// Non-negative weighted least squares of avar_i = sum_j c_j g_j(tau_i),
// residuals divided by sd_i: every subset of terms is solved and the best
// one with all coefficients positive kept.
Coefficients NonNegativeFit(const std::vector<double>& tau, const std::vector<double>& avar,
                            const std::vector<double>& sd) {
  const int n = static_cast<int>(tau.size());
  Coefficients best{0.0, 0.0, 0.0, 0.0};
  double best_cost = std::numeric_limits<double>::infinity();
  for (int mask = 1; mask < (1 << kTerms); ++mask) {
    std::vector<int> terms;
    for (int j = 0; j < kTerms; ++j) {
      if (mask & (1 << j)) terms.push_back(j);
    }
    const int k = static_cast<int>(terms.size());
    if (k > n) continue;
    Eigen::MatrixXd a(n, k);
    Eigen::VectorXd b(n);
    for (int i = 0; i < n; ++i) {
      for (int c = 0; c < k; ++c) a(i, c) = Shape(terms[c], tau[i]) / sd[i];
      b(i) = avar[i] / sd[i];
    }
    // Columns span many decades: scale them to unit norm first.
    const Eigen::VectorXd norms = a.colwise().norm().transpose();
    if ((norms.array() <= 0.0).any()) continue;
    const Eigen::MatrixXd scaled = a * norms.cwiseInverse().asDiagonal();
    const Eigen::VectorXd y = scaled.colPivHouseholderQr().solve(b);
    const Eigen::VectorXd x = y.cwiseQuotient(norms);
    if ((x.array() <= 0.0).any() || !x.allFinite()) continue;
    const double cost = (a * x - b).squaredNorm();
    if (cost < best_cost) {
      best_cost = cost;
      best = {0.0, 0.0, 0.0, 0.0};
      for (int c = 0; c < k; ++c) best[terms[c]] = x(c);
    }
  }
  return best;
}

int DominantTerm(const Coefficients& c, double tau) {
  int best = 1;
  double largest = -1.0;
  for (int j = 0; j < kTerms; ++j) {
    const double v = c[j] * Shape(j, tau);
    if (v > largest) {
      largest = v;
      best = j;
    }
  }
  return best;
}

std::string TauText(double tau) {
  std::ostringstream s;
  s.precision(3);
  s << tau << " s";
  return s.str();
}

// The points a fit uses: tau >= min_tau and a positive deviation, with
// their taus and Allan variances.
struct FitPoints {
  std::vector<size_t> used;
  std::vector<double> tau;
  std::vector<double> avar;
};

FitPoints SelectFitPoints(const AllanDeviation& curve, double min_tau) {
  FitPoints p;
  for (size_t i = 0; i < curve.points.size(); ++i) {
    if (curve.points[i].tau >= min_tau * (1.0 - 1e-9) && curve.points[i].adev > 0.0) {
      p.used.push_back(i);
    }
  }
  for (size_t i : p.used) {
    p.tau.push_back(curve.points[i].tau);
    p.avar.push_back(curve.points[i].adev * curve.points[i].adev);
  }
  return p;
}

// Step 1: the non-negative fit, its weights and each point's edf from the
// model, iterated. Returns the coefficients; *model gets the fitted Allan
// variance at the points and *curve its confidence intervals by the
// dominating term's edf.
Coefficients FitAndWeigh(const FitPoints& p, double confidence, AllanDeviation* curve,
                         std::vector<double>* model) {
  const size_t n = p.used.size();
  std::vector<AllanNoiseType> types(curve->points.size(), AllanNoiseType::kWhiteNoise);
  Coefficients c{0.0, 0.0, 0.0, 0.0};
  std::vector<double> sd(n);
  *model = p.avar;
  for (int iteration = 0; iteration < 6; ++iteration) {
    for (size_t k = 0; k < n; ++k) {
      sd[k] = (*model)[k] * std::sqrt(2.0 / curve->points[p.used[k]].edf);
    }
    c = NonNegativeFit(p.tau, p.avar, sd);
    for (size_t k = 0; k < n; ++k) (*model)[k] = std::max(ModelVariance(c, p.tau[k]), 1e-300);
    for (size_t i = 0; i < curve->points.size(); ++i) {
      types[i] = TypeOf(DominantTerm(c, curve->points[i].tau));
    }
    SetAllanConfidence(types, confidence, curve);
  }
  return c;
}

// The point where term j is read (bias instability at its largest share,
// the flat minimum; quantisation at the shortest tau; the slopes where the
// predicted relative uncertainty is smallest), among those where it
// dominates; -1 when it dominates nowhere, with term->reason saying so.
// Sets the term's tau range.
int ChooseReadingPoint(int j, const Coefficients& c, const FitPoints& p,
                       const std::vector<double>& model, const AllanDeviation& curve,
                       double dominance, NoiseTerm* term) {
  double best_share = 0.0, best_tau = 0.0;
  int chosen = -1;
  double chosen_score = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < p.used.size(); ++k) {
    const double share = c[j] * Shape(j, p.tau[k]) / model[k];
    if (share > best_share) {
      best_share = share;
      best_tau = p.tau[k];
    }
    if (share < dominance) continue;
    term->tau_min = std::isnan(term->tau_min) ? p.tau[k] : std::min(term->tau_min, p.tau[k]);
    term->tau_max = std::isnan(term->tau_max) ? p.tau[k] : std::max(term->tau_max, p.tau[k]);
    const double edf = curve.points[p.used[k]].edf;
    const double score = j == 2 ? -share : j == 0 ? p.tau[k] : std::sqrt(2.0 / edf) / share;
    if (score < chosen_score) {
      chosen_score = score;
      chosen = static_cast<int>(k);
    }
  }
  if (chosen < 0) {
    const char* names[kTerms] = {"quantisation (tau^-1)", "white noise (tau^-1/2)",
                                 "bias instability (flat part)", "random walk (tau^+1/2)"};
    term->reason = std::string(names[j]) +
                   (c[j] > 0.0 ? " never dominates the curve: at most " +
                                     std::to_string(static_cast<int>(100.0 * best_share)) +
                                     " % of the Allan variance, at tau " + TauText(best_tau)
                               : " is not in the fitted curve (tau " + TauText(p.tau.front()) +
                                     " to " + TauText(p.tau.back()) + ")");
  }
  return chosen;
}

// Step 2: each dominating term read at one point, the others subtracted;
// twice, the second time with the first readings' values and variances.
// Only terms that dominate somewhere are subtracted: a term the fit gives a
// small share everywhere is not determined by the curve (quantisation and
// white noise, both falling, trade against each other), and subtracting it
// would bias the reading.
void ReadTerms(const Coefficients& c, const FitPoints& p, const std::vector<double>& model,
               double dominance, NoiseFit* fit) {
  const size_t n = p.used.size();
  Coefficients value{0.0, 0.0, 0.0, 0.0};
  for (int j = 0; j < kTerms; ++j) {
    for (size_t k = 0; k < n; ++k) {
      if (c[j] * Shape(j, p.tau[k]) >= dominance * model[k]) value[j] = c[j];
    }
  }
  Coefficients variance{0.0, 0.0, 0.0, 0.0};
  for (int pass = 0; pass < 2; ++pass) {
    Coefficients next{0.0, 0.0, 0.0, 0.0};
    Coefficients next_variance{0.0, 0.0, 0.0, 0.0};
    for (int j = 0; j < kTerms; ++j) {
      NoiseTerm* term = TermOf(j, &fit->model);
      *term = NoiseTerm();
      const int chosen = ChooseReadingPoint(j, c, p, model, fit->curve, dominance, term);
      if (chosen < 0) continue;
      const size_t k = static_cast<size_t>(chosen);
      const double g = Shape(j, p.tau[k]);
      double rest = 0.0, rest_variance = 0.0;
      for (int o = 0; o < kTerms; ++o) {
        if (o == j) continue;
        const double go = Shape(o, p.tau[k]);
        rest += value[o] * go;
        rest_variance += variance[o] * go * go;
      }
      const double edf = fit->curve.points[p.used[k]].edf;
      const double coefficient = (p.avar[k] - rest) / g;
      const double coefficient_variance =
          (2.0 / edf * model[k] * model[k] + rest_variance) / (g * g);
      term->tau = p.tau[k];
      if (!(coefficient > 0.0)) {
        term->reason = "the reading at tau " + TauText(p.tau[k]) +
                       " leaves nothing once the other terms are subtracted";
        next[j] = 0.0;
        continue;
      }
      next[j] = coefficient;
      next_variance[j] = coefficient_variance;
      term->value = std::sqrt(coefficient);
      term->std = std::sqrt(coefficient_variance) / (2.0 * term->value);
    }
    value = next;
    variance = next_variance;
  }
}

}  // namespace
}  // namespace internal

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

bool NoiseFitOptions::IsValid(std::string* error) const {
  if (!(min_tau_samples >= 1.0) || !std::isfinite(min_tau_samples)) {
    *error = "noise fit min_tau_samples must be >= 1";
  } else if (!(dominance > 0.0 && dominance < 1.0)) {
    *error = "noise fit dominance must be in (0, 1)";
  } else {
    return true;
  }
  return false;
}

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

bool FitNoiseTerms(const AllanDeviation& curve, const NoiseFitOptions& options, NoiseFit* fit) {
  using internal::kTerms;
  std::string error;
  if (!options.IsValid(&error)) {
    fit->message = error;
    return false;
  }
  fit->curve = curve;
  fit->model = AxisNoiseModel();
  const double min_tau = options.min_tau_samples / curve.rate_hz;
  const internal::FitPoints points = internal::SelectFitPoints(curve, min_tau);
  if (points.used.empty()) {
    fit->message = "no Allan deviation point at tau >= " + internal::TauText(min_tau);
    return false;
  }
  std::vector<double> model;
  const internal::Coefficients c =
      internal::FitAndWeigh(points, curve.confidence, &fit->curve, &model);
  internal::ReadTerms(c, points, model, options.dominance, fit);

  std::ostringstream s;
  s << "fitted on " << points.used.size() << " taus from " << internal::TauText(points.tau.front())
    << " to " << internal::TauText(points.tau.back()) << ":";
  for (int j = 0; j < kTerms; ++j) {
    const NoiseTerm& term = *internal::TermOf(j, &fit->model);
    s << " " << ToString(internal::TypeOf(j)) << "="
      << (term.visible() ? std::to_string(term.value) : std::string("n/a"));
  }
  fit->message = s.str();
  return true;
}

}  // namespace gravcal
