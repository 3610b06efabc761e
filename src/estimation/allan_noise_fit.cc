// The noise terms read from an Allan deviation curve (FitNoiseTerms,
// allan_deviation.h): quantisation, white noise, bias instability and random
// walk by a non-negative weighted fit, each then read where it dominates.
#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>

#include "estimation/allan_floor.h"
#include "gravcal/estimation/allan_deviation.h"

namespace gravcal {

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
// their taus and Allan variances, each spectral line's Allan variance
// subtracted (LineAllanVariance) and a fifth of its bound counted as the
// subtraction's standard deviation (extra, a variance of the Allan
// variance); a point where the lines' bound exceeds line_share of its
// Allan variance is left out (*line_excluded counts them).
struct FitPoints {
  std::vector<size_t> used;
  std::vector<double> tau;
  std::vector<double> avar;
  std::vector<double> extra;
};

FitPoints SelectFitPoints(const AllanDeviation& curve, double min_tau,
                          const std::vector<SpectralLine>& lines, double line_share,
                          int* line_excluded) {
  FitPoints p;
  *line_excluded = 0;
  for (size_t i = 0; i < curve.points.size(); ++i) {
    const AllanPoint& point = curve.points[i];
    if (point.tau < min_tau * (1.0 - 1e-9) || !(point.adev > 0.0)) continue;
    const double avar = point.adev * point.adev;
    double bound = 0.0, line_variance = 0.0;
    for (const SpectralLine& line : lines) {
      bound += LineAllanBound(line, point.tau);
      line_variance += LineAllanVariance(line, point.tau, curve.rate_hz);
    }
    if (bound > line_share * avar || !(avar - line_variance > 0.0)) {
      ++*line_excluded;
      continue;
    }
    p.used.push_back(i);
    p.tau.push_back(point.tau);
    p.avar.push_back(avar - line_variance);
    p.extra.push_back(0.04 * bound * bound);
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
      sd[k] =
          std::sqrt((*model)[k] * (*model)[k] * 2.0 / curve->points[p.used[k]].edf + p.extra[k]);
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

const char* const kTermNames[kTerms] = {"quantisation (tau^-1)", "white noise (tau^-1/2)",
                                        "bias instability (flat part)", "random walk (tau^+1/2)"};

// Term j's reading at point k with the other terms' values subtracted, and
// its variance: the Allan variance's own, 2 sigma^4 / edf (model sigma), and
// the subtracted terms'.
struct Reading {
  double value = 0.0;
  double variance = 0.0;
  double statistical = 0.0;
};

Reading ReadAt(int j, size_t k, const Coefficients& value, const Coefficients& variance,
               const FitPoints& p, const std::vector<double>& model, const AllanDeviation& curve) {
  const double g = Shape(j, p.tau[k]);
  double rest = 0.0, rest_variance = 0.0;
  for (int o = 0; o < kTerms; ++o) {
    if (o == j) continue;
    const double go = Shape(o, p.tau[k]);
    rest += value[o] * go;
    rest_variance += variance[o] * go * go;
  }
  const double edf = ReadingDof(curve, p.used[k]);
  Reading r;
  r.value = (p.avar[k] - rest) / g;
  r.statistical = (2.0 / edf * model[k] * model[k] + p.extra[k]) / (g * g);
  r.variance = r.statistical + rest_variance / (g * g);
  return r;
}

// Step 2: each term read where the curve shows it, the others subtracted;
// twice, the second time with the first readings' values and variances.
//   white noise and random walk: among the points the term dominates
//     (share >= dominance), the one with the smallest predicted
//     uncertainty; the random walk only where the rising end has a slope
//     near +1/2 (a steeper one is a drift or a slow line);
//   bias instability: at the curve's floor (ReadAllanFloor, allan_floor.h),
//     the conventional reading B = sigma_floor / 0.664 (IEEE Std 952), with
//     nothing subtracted: where white noise and random walk also add at the
//     floor it is their meeting level, which is what a datasheet's "bias
//     instability" states; undetermined when the curve shows no floor;
//   quantisation: its smallest dominated tau.
// The variance is the reading's; when the readings over the term's whole
// dominated range scatter more than their own variances say (chi-square per
// degree of freedom above 1: the curve departs from the term's slope), it
// is inflated by that ratio. Only terms that dominate somewhere are
// subtracted: a term the fit gives a small share everywhere is not
// determined by the curve.
void ReadTerms(const Coefficients& c, const FitPoints& p, const std::vector<double>& model,
               double dominance, NoiseFit* fit) {
  const size_t n = p.used.size();
  Coefficients value{0.0, 0.0, 0.0, 0.0};
  for (int j = 0; j < kTerms; ++j) {
    for (size_t k = 0; k < n; ++k) {
      if (c[j] * Shape(j, p.tau[k]) >= dominance * model[k]) value[j] = c[j];
    }
  }
  const AllanFloor floor = ReadAllanFloor(fit->curve, p.used, p.avar);
  Coefficients variance{0.0, 0.0, 0.0, 0.0};
  for (int pass = 0; pass < 2; ++pass) {
    Coefficients next{0.0, 0.0, 0.0, 0.0};
    Coefficients next_variance{0.0, 0.0, 0.0, 0.0};
    for (int j = 0; j < kTerms; ++j) {
      NoiseTerm* term = TermOf(j, &fit->model);
      *term = NoiseTerm();
      if (j == 2) {
        // The other readings subtract the fitted flicker coefficient (not
        // the floor, which holds the other terms too), as uncertain as the
        // floor, when the floor shows flicker: it lies significantly above
        // the fitted white noise, random walk and quantisation there, and
        // by half at least (else it is where they meet, and the fit's
        // flicker is the curvature of a V). Without that, only a flicker the fit
        // finds dominant somewhere is subtracted, with its whole size as
        // its standard deviation: the curve does not say it is there.
        Coefficients others = c;
        others[2] = 0.0;
        const bool flicker =
            floor.seen && floor.adev * floor.adev > std::max(1.5, 1.0 + 4.0 * floor.relative) *
                                                        ModelVariance(others, floor.tau);
        next[j] = flicker ? c[j] : value[j];
        next_variance[j] = std::pow((flicker ? 2.0 * floor.relative : 1.0) * next[j], 2);
        if (!floor.seen) {
          term->reason = "bias instability: " + floor.reason;
          if (floor.lowest_tau > 0.0) term->upper_bound = floor.bound;
          continue;
        }
        term->tau = floor.tau;
        term->tau_min = floor.tau_min;
        term->tau_max = floor.tau_max;
        if (!flicker) {
          // A floor that white noise, random walk and quantisation explain
          // is where their slopes meet: B is not shown, only bounded (a
          // model that added B to N and K would count the floor twice).
          term->upper_bound = floor.adev / std::sqrt(kFlickerAllanFactor);
          std::ostringstream r;
          r.precision(3);
          r << "bias instability: the curve's floor (tau " << floor.tau << " s, Allan deviation "
            << floor.adev << ") is where white noise and random walk meet, not above them: no "
            << "flicker shows; B is at most " << term->upper_bound;
          term->reason = r.str();
          continue;
        }
        term->value = floor.adev / std::sqrt(kFlickerAllanFactor);
        term->std = floor.relative * term->value;
        continue;
      }
      std::vector<size_t> dominated;
      double best_share = 0.0, best_tau = 0.0;
      for (size_t k = 0; k < n; ++k) {
        const double share = c[j] * Shape(j, p.tau[k]) / model[k];
        if (share > best_share) {
          best_share = share;
          best_tau = p.tau[k];
        }
        if (share < dominance) continue;
        dominated.push_back(k);
        term->tau_min = std::isnan(term->tau_min) ? p.tau[k] : std::min(term->tau_min, p.tau[k]);
        term->tau_max = std::isnan(term->tau_max) ? p.tau[k] : std::max(term->tau_max, p.tau[k]);
      }
      if (dominated.empty()) {
        term->reason = std::string(kTermNames[j]) +
                       (c[j] > 0.0 ? " never dominates the curve: at most " +
                                         std::to_string(static_cast<int>(100.0 * best_share)) +
                                         " % of the Allan variance, at tau " + TauText(best_tau)
                                   : " is not in the fitted curve (tau " + TauText(p.tau.front()) +
                                         " to " + TauText(p.tau.back()) + ")");
        continue;
      }
      int chosen = -1;
      if (j == 0) {
        chosen = static_cast<int>(dominated.front());
      } else {
        double best = std::numeric_limits<double>::infinity();
        for (size_t k : dominated) {
          const Reading r = ReadAt(j, k, value, variance, p, model, fit->curve);
          const double score = std::sqrt(r.variance) * Shape(j, p.tau[k]) / model[k];
          if (score < best) {
            best = score;
            chosen = static_cast<int>(k);
          }
        }
      }
      if (j == 3 && dominated.size() >= 4 &&
          p.tau[dominated.back()] >= 4.0 * p.tau[dominated.front()]) {
        // Slope of log adev on log tau over the rising end, weighted least
        // squares: var(log adev) = 1 / (2 edf). A rise off +1/2 by more than
        // 0.3 plus twice the slope's standard deviation is not a random walk
        // (a drift rises at +1).
        double sw = 0.0, sx = 0.0, sy = 0.0;
        for (size_t k : dominated) {
          const double w = 2.0 * ReadingDof(fit->curve, p.used[k]);
          sw += w;
          sx += w * std::log(p.tau[k]);
          sy += w * 0.5 * std::log(p.avar[k]);
        }
        double sxx = 0.0, sxy = 0.0;
        for (size_t k : dominated) {
          const double w = 2.0 * ReadingDof(fit->curve, p.used[k]);
          const double dx = std::log(p.tau[k]) - sx / sw;
          sxx += w * dx * dx;
          sxy += w * dx * (0.5 * std::log(p.avar[k]) - sy / sw);
        }
        // Overlapping averages make neighbouring points correlated: the
        // independent points are about one per half octave, so the
        // regression's standard deviation is scaled by sqrt(2 x points per
        // octave).
        const double per_octave =
            std::max(1.0, (dominated.size() - 1.0) /
                              std::log2(p.tau[dominated.back()] / p.tau[dominated.front()]));
        const double slope = sxy / sxx;
        const double slope_sd = std::sqrt(2.0 * per_octave / sxx);
        if (std::abs(slope - 0.5) > 0.3 + 2.0 * slope_sd) {
          std::ostringstream r;
          r.precision(2);
          r << "the rising end (tau " << TauText(p.tau[dominated.front()]) << " to "
            << TauText(p.tau[dominated.back()]) << ") has slope " << slope << " +- " << slope_sd
            << ", not +1/2: a drift or a slow line, not a random walk";
          term->reason = r.str();
          continue;
        }
      }
      if (j == 3 && !floor.rises) {
        term->reason = floor.lowest_tau > 0.0
                           ? "random walk (tau^+1/2): the curve does not rise significantly "
                             "above the white-noise line through its lowest point (tau " +
                                 TauText(floor.lowest_tau) + ")"
                           : "random walk (tau^+1/2): " + floor.reason;
        continue;
      }
      if (j == 3) {
        // The rise starts at the floor (or where the walk dominates, if
        // earlier or without a floor).
        size_t from = dominated.front();
        while (floor.seen && from > 0 && p.tau[from - 1] >= floor.tau) --from;
        if (RiseTurnsOver(fit->curve, p.used, p.avar, from, &term->reason)) continue;
      }
      const size_t k = static_cast<size_t>(chosen);
      const Reading reading = ReadAt(j, k, value, variance, p, model, fit->curve);
      term->tau = p.tau[k];
      if (!(reading.value > 0.0)) {
        term->reason = "the reading at tau " + TauText(p.tau[k]) +
                       " leaves nothing once the other terms are subtracted";
        next[j] = 0.0;
        continue;
      }
      // Where on its range the term is read is a choice: the readings over
      // the dominated range scatter beyond their own variances where the
      // curve departs from the term's slope. That scatter (the between-
      // reading variance of a random-effects mean, DerSimonian-Laird, about
      // the chosen reading) is added as the model's error.
      double q = 0.0, sw = 0.0, sww = 0.0;
      for (size_t o : dominated) {
        const Reading r = ReadAt(j, o, value, variance, p, model, fit->curve);
        const double w = 1.0 / r.statistical;
        q += w * (r.value - reading.value) * (r.value - reading.value);
        sw += w;
        sww += w * w;
      }
      const double model_error =
          dominated.size() >= 3
              ? std::max(0.0, (q - static_cast<double>(dominated.size() - 1)) / (sw - sww / sw))
              : 0.0;
      next[j] = reading.value;
      next_variance[j] = reading.variance + model_error;
      term->value = std::sqrt(reading.value);
      term->std = std::sqrt(next_variance[j]) / (2.0 * term->value);
      if (j == 3 && !(term->std < term->value)) {
        std::ostringstream r;
        r.precision(3);
        r << "random walk (tau^+1/2) read at tau " << p.tau[k] << " s is " << term->value << " +- "
          << term->std << ": the uncertainty exceeds the value";
        *term = NoiseTerm();
        term->reason = r.str();
      }
    }
    value = next;
    variance = next_variance;
  }
}

}  // namespace
}  // namespace internal

bool NoiseFitOptions::IsValid(std::string* error) const {
  if (!(min_tau_samples >= 1.0) || !std::isfinite(min_tau_samples)) {
    *error = "noise fit min_tau_samples must be >= 1";
  } else if (!(dominance > 0.0 && dominance < 1.0)) {
    *error = "noise fit dominance must be in (0, 1)";
  } else if (!(line_share > 0.0 && line_share < 1.0)) {
    *error = "noise fit line_share must be in (0, 1)";
  } else {
    return true;
  }
  return false;
}

bool FitNoiseTerms(const AllanDeviation& curve, const NoiseFitOptions& options, NoiseFit* fit) {
  return FitNoiseTerms(curve, options, {}, fit);
}

bool FitNoiseTerms(const AllanDeviation& curve, const NoiseFitOptions& options,
                   const std::vector<SpectralLine>& lines, NoiseFit* fit) {
  using internal::kTerms;
  std::string error;
  if (!options.IsValid(&error)) {
    fit->message = error;
    return false;
  }
  fit->curve = curve;
  fit->model = AxisNoiseModel();
  const double min_tau = options.min_tau_samples / curve.rate_hz;
  int line_excluded = 0;
  const internal::FitPoints points =
      internal::SelectFitPoints(curve, min_tau, lines, options.line_share, &line_excluded);
  if (points.used.empty()) {
    fit->message = "no Allan deviation point at tau >= " + internal::TauText(min_tau) +
                   (line_excluded > 0 ? " clear of the spectral lines" : "");
    return false;
  }
  std::vector<double> model;
  const internal::Coefficients c =
      internal::FitAndWeigh(points, curve.confidence, &fit->curve, &model);
  internal::ReadTerms(c, points, model, options.dominance, fit);

  std::ostringstream s;
  s << "fitted on " << points.used.size() << " taus from " << internal::TauText(points.tau.front())
    << " to " << internal::TauText(points.tau.back());
  if (!lines.empty()) {
    s << " (the Allan variance of the line";
    for (const SpectralLine& line : lines) s << " at " << LineText(line);
    s << " subtracted, " << line_excluded << " taus it dominates left out)";
  }
  s << ":";
  for (int j = 0; j < kTerms; ++j) {
    const NoiseTerm& term = *internal::TermOf(j, &fit->model);
    s << " " << ToString(internal::TypeOf(j)) << "="
      << (term.visible() ? std::to_string(term.value) : std::string("n/a"));
  }
  fit->message = s.str();
  return true;
}

}  // namespace gravcal
