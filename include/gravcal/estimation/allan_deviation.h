// gravcal/estimation/allan_deviation.h: the overlapping Allan deviation of a
// uniformly sampled series, its confidence intervals, and the fit of the
// standard noise terms (core/noise_model.h) to it.
//
// For a series x_0..x_{n-1} sampled every tau_0 seconds and the averaging
// time tau = m tau_0, with X_k = sum_{i<k} x_i the running sum, the
// overlapping Allan variance is
//   sigma^2(tau) = 1 / (2 m^2 (n - 2m + 1)) sum_{j=0}^{n-2m} (X_{j+2m} - 2 X_{j+m} + X_j)^2,
// half the mean squared difference of adjacent tau-averages, every start
// sample used: O(n) per tau from the running sums. The taus are
// m = round(2^(k / points_per_octave)), k = 0, 1, ..., distinct.
//
// Confidence intervals: sigma^2_hat edf / sigma^2 is taken as chi-square
// with edf equivalent degrees of freedom, which depend on the noise type
// dominating at that tau (AllanEquivalentDof); the curve is first given the
// white-noise edf, and the fit re-derives each point's from the term that
// dominates it.
#ifndef GRAVCAL_ESTIMATION_ALLAN_DEVIATION_H_
#define GRAVCAL_ESTIMATION_ALLAN_DEVIATION_H_

#include <cstddef>
#include <string>
#include <vector>

#include "gravcal/core/noise_model.h"
#include "gravcal/estimation/spectral_lines.h"

namespace gravcal {

// Noise types of the EDF formulas, named by the time-and-frequency
// convention (the sensor's rate output plays the role of frequency):
// quantisation = white phase, white noise = white frequency, bias
// instability = flicker frequency, rate random walk = random-walk frequency.
enum class AllanNoiseType {
  kQuantisation,
  kWhiteNoise,
  kBiasInstability,
  kRandomWalk,
};

const char* ToString(AllanNoiseType type);

// Equivalent degrees of freedom of the overlapping Allan variance of
// `samples` samples at averaging factor m (>= 1, 2m <= samples), at least 1.
// The simple approximations of Howe, Allan and Barnes (1981), as tabulated
// in NIST SP 1065 (Riley, "Handbook of Frequency Stability Analysis"), with
// N = samples + 1 phase points:
//   white phase     (N+1)(N-2m) / (2(N-m))
//   white freq.     (3(N-1)/(2m) - 2(N-2)/N) 4m^2 / (4m^2 + 5)
//   flicker freq.   2(N-2)^2 / (2.3N - 4.9) for m = 1, 5N^2 / (4m(N+3m)) for m >= 2
//   random walk     (N-2)/m ((N-1)^2 - 3m(N-1) + 4m^2) / (N-3)^2
double AllanEquivalentDof(AllanNoiseType type, size_t samples, size_t m);

struct AllanOptions {
  // Averaging times per octave of tau: 1 = octave spacing, more = finer.
  int points_per_octave = 2;
  // Largest tau as a fraction of the series' duration (beyond it the curve
  // rests on too few independent averages).
  double max_tau_fraction = 0.2;
  // Largest tau asked for, seconds; 0 = as far as max_tau_fraction allows.
  // A series shorter than max_tau / max_tau_fraction is refused.
  double max_tau = 0.0;
  // Largest tolerated relative deviation of a time step from the median
  // step; a larger one is a gap or a clock jump, and the series is refused.
  double time_step_tolerance = 0.05;
  // Two-sided probability of the confidence intervals [lo, hi].
  double confidence = 0.683;

  bool IsValid(std::string* error) const;
};

// One point of the curve.
struct AllanPoint {
  double tau = 0.0;  // seconds
  size_t m = 0;      // samples averaged
  double adev = 0.0;
  // Equivalent degrees of freedom and the confidence interval of adev.
  double edf = 0.0;
  double lo = 0.0;
  double hi = 0.0;
  // The noise type whose EDF formula was used.
  AllanNoiseType edf_noise = AllanNoiseType::kWhiteNoise;
};

struct AllanDeviation {
  double rate_hz = 0.0;
  size_t samples = 0;
  double confidence = 0.0;
  std::vector<AllanPoint> points;
  std::string message = "ComputeAllanDeviation was not called";
};

// Checks that t[begin, end) is uniformly sampled (every step within
// tolerance of the median step); sets *rate_hz = 1 / median step. On failure
// returns false and says where: "time step at sample 1234 (t = 12.34 s) is
// 0.05 s, 5 times the median 0.01 s".
bool CheckUniformSampling(const std::vector<double>& t, size_t begin, size_t end, double tolerance,
                          double* rate_hz, std::string* error);

// How the samples of a still log are placed in time for the Allan
// deviation (ResolveSampleTiming).
struct SampleTiming {
  // The rate the samples are taken at, Hz, and where it came from:
  // "uniform time stamps" (every step within tolerance of the median step:
  // 1 / median step), "nominal rate" (given), or "least squares of time on
  // sample index" (the time stamps jitter or have gaps: a host PC's reading
  // times; the sensor's own clock is taken as uniform).
  double rate_hz = 0.0;
  std::string rate_source;
  double median_step = 0.0;    // s
  double largest_step = 0.0;   // s
  size_t largest_step_at = 0;  // sample index
  // The largest departure of a time stamp from the uniform grid
  // t0 + i / rate_hz (t0 by least squares), s. If the time stamps were the
  // true sample times, treating the samples as uniform would misplace an
  // Allan average of length tau by up to twice this, a relative bias of the
  // Allan deviation of at most departure / tau; none if the sensor samples
  // uniformly and only the host's reading times jitter.
  double largest_departure = 0.0;
  // The shortest tau whose worst-case bias is within max_bias: departure /
  // max_bias (0 for uniform time stamps).
  double unbiased_tau = 0.0;
  // One line saying what was done.
  std::string message;
};

// The timing of samples [begin, end) of t. nominal_rate_hz > 0 is used as
// the rate; else uniform time stamps give 1 / median step, and jittering
// ones (a step off the median by more than `tolerance` of it) the least-
// squares rate. Returns false with *error when time does not increase
// (median step <= 0) or when the departures would bias the Allan deviation
// by more than max_bias even at the longest tau, longest_tau (s).
bool ResolveSampleTiming(const std::vector<double>& t, size_t begin, size_t end,
                         double nominal_rate_hz, double tolerance, double max_bias,
                         double longest_tau, SampleTiming* timing, std::string* error);

// The Allan deviation of x sampled at times t (same size, uniform). Returns
// false with result->message on invalid options, non-uniform time, or a
// series too short for the tau asked.
bool ComputeAllanDeviation(const std::vector<double>& t, const std::vector<double>& x,
                           const AllanOptions& options, AllanDeviation* result);

// The same for samples [begin, end) of x, known to be uniform at rate_hz.
bool ComputeAllanDeviation(const std::vector<double>& x, size_t begin, size_t end, double rate_hz,
                           const AllanOptions& options, AllanDeviation* result);

// Re-derives each point's edf and interval with the EDF formula of
// types[i] (one per point).
void SetAllanConfidence(const std::vector<AllanNoiseType>& types, double confidence,
                        AllanDeviation* curve);

struct NoiseFitOptions {
  // Points at tau below this many samples are left out of the fit: a
  // sensor's anti-aliasing filter lowers the curve there below the white
  // noise line.
  double min_tau_samples = 4.0;
  // A term is read, and called visible, where it carries at least this
  // share of the fitted Allan variance.
  double dominance = 0.5;
  // Spectral lines' Allan variance is subtracted from each point (with a
  // fifth of its bound as uncertainty); a point is left out of the fit
  // when the lines' bound (spectral_lines.h) there exceeds this share of
  // the point's.
  double line_share = 0.3;

  bool IsValid(std::string* error) const;
};

// The fitted model of one axis and the curve with the EDF of the term that
// dominates each point.
struct NoiseFit {
  AxisNoiseModel model;
  AllanDeviation curve;
  std::string message = "FitNoiseTerms was not called";
};

// Fits the four terms of core/noise_model.h to the curve:
// 1. sigma^2(tau) = 3 Q^2 / tau^2 + N^2 / tau + (2 ln 2 / pi) B^2 + K^2 tau / 3
//    by non-negative weighted least squares in (Q^2, N^2, B^2, K^2) (every
//    subset of terms tried), weights edf / (2 sigma^4) from the model itself,
//    iterated; each point's edf from the term dominating it there;
// 2. each term that dominates (share >= dominance) somewhere is read at one
//    point, with the other terms' fitted contributions subtracted, where
//    the curve shows it:
//      white noise on the -1/2 slope it dominates, at the tau with the
//      smallest predicted uncertainty (the classic reading at tau = 1 s
//      when that is it), clear of spectral lines (the overload below);
//      random walk likewise on the +1/2 rise, and only where the rise's
//      slope is near +1/2 (within 0.3; a slope of +1 is a drift), the
//      curve rises significantly above the white-noise line through its
//      lowest point, and the rise does not turn over (a slow line's bump);
//      NaN when its sd exceeds it;
//      bias instability at the curve's floor whether or not the flicker
//      term dominates it, the conventional reading B = sigma_floor / 0.664
//      (IEEE Std 952; what datasheets state): the floor is the vertex of a
//      parabola through the points within an octave of the lowest one, and
//      is seen only when the curve falls to it and leaves the white-noise
//      slope there (estimation/allan_floor.h), else B is NaN with its upper
//      bound; B is determined only when the floor shows flicker, lying
//      above the fitted white noise, random walk and quantisation there by
//      half at least and four of its relative sigmas: a floor they explain
//      is where their slopes meet, and B is NaN with the floor as its
//      upper_bound (a model holding N, K and that B would count the floor
//      twice); a determined B holds the other terms' share of the floor
//      too, which AxisNoiseModel::AllanVariance takes off;
//      quantisation at its smallest dominated tau;
//    its variance is that of the Allan variance at that point, 2 sigma^4 /
//    dof with dof the point's edf but at most its independent clusters less
//    one (n / m - 1), plus the other terms' subtracted variances, plus the
//    model's error: the between-reading variance (DerSimonian-Laird) of the
//    term's readings over its dominated range (the curve departs from the
//    term's slope); B's is the floor's: the lowest point's and the
//    distance between it and the vertex.
// A term that never dominates is NaN with the reason. Returns false only on
// invalid options or an empty curve.
bool FitNoiseTerms(const AllanDeviation& curve, const NoiseFitOptions& options, NoiseFit* fit);

// The same, with the lines' Allan variance subtracted and the points a line
// dominates (line_share) left out: the terms are then read on the slopes
// clear of the lines.
bool FitNoiseTerms(const AllanDeviation& curve, const NoiseFitOptions& options,
                   const std::vector<SpectralLine>& lines, NoiseFit* fit);

}  // namespace gravcal

#endif  // GRAVCAL_ESTIMATION_ALLAN_DEVIATION_H_
