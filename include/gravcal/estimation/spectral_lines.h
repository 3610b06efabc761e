// gravcal/estimation/spectral_lines.h: tones and lines in the spectrum of a
// still log's axis (a 17 Hz line from a fan or a motor, a slow line from a
// heater's cycle), named with their frequency and amplitude, and the span of
// Allan averaging times they disturb.
//
// The one-sided power spectral density is estimated by Welch's method
// (Hann window, half-overlapping segments of L = 2^k samples),
//   P(f_k) = 2 |sum_i w_i x_i e^(-2 pi i k i / L)|^2 / (f_s sum_i w_i^2),
// averaged over the segments, at several resolutions (L = 256, 4096, 65536
// and the longest 2^k, where the log holds at least eight segments of that
// length). A bin is a
// line when it is the largest within +-3 bins and exceeds the local
// background (the geometric mean of the medians of the bins 4 to 24 away on
// each side, which follows a sloping 1/f, random-walk or filter spectrum) by
// the chi-square quantile of the Welch average at a false-alarm probability
// of 1e-3 over all bins. The line's
// power is the sum over its +-2 bins (the Hann window's main lobe) less the
// background; a sinusoid of amplitude A has power A^2 / 2.
//
// The Allan variance of a sinusoid A sin(2 pi f t) is
//   sigma^2(tau) = A^2 sin^4(pi f tau) / (pi f tau)^2 <= A^2 min(x^2, 1 / x^2), x = pi f tau,
// which rises like a drift below tau = 1 / (pi f) and falls like tau^-2
// above it: LineAllanBound gives the bound. Sampled at f_s and averaged over
// m = tau f_s samples, pi f tau in the denominator becomes
// m sin(pi f / f_s) (LineAllanVariance).
#ifndef GRAVCAL_ESTIMATION_SPECTRAL_LINES_H_
#define GRAVCAL_ESTIMATION_SPECTRAL_LINES_H_

#include <string>
#include <vector>

namespace gravcal {

struct SpectralLine {
  double frequency_hz = 0.0;
  // Amplitude of the equivalent sinusoid, the series' unit.
  double amplitude = 0.0;
  // Peak power over the local background.
  double prominence = 0.0;
};

// Lines in samples [begin, end) of x at rate_hz, strongest first, at most
// max_lines. An empty result for a series without lines or too short for
// the coarsest resolution (8 x 256 samples).
std::vector<SpectralLine> FindSpectralLines(const std::vector<double>& x, size_t begin, size_t end,
                                            double rate_hz, size_t max_lines = 8);

// The Allan variance the line adds at tau = m / rate_hz, sampled.
double LineAllanVariance(const SpectralLine& line, double tau, double rate_hz);

// The bound above on the Allan variance a line adds at tau.
double LineAllanBound(const SpectralLine& line, double tau);

// "17.0 Hz (amplitude 0.0012)", for messages.
std::string LineText(const SpectralLine& line);

}  // namespace gravcal

#endif  // GRAVCAL_ESTIMATION_SPECTRAL_LINES_H_
