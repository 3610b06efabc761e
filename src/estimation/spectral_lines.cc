#include "gravcal/estimation/spectral_lines.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <iomanip>
#include <limits>
#include <sstream>

#include "estimation/nyquist_flatness.h"
#include "util/statistics.h"

namespace gravcal {
namespace internal {
namespace {

constexpr double kPi = 3.14159265358979323846;

// In-place iterative radix-2 FFT; data.size() a power of two. The twiddle
// factors of each stage are made once, by the same recurrence w *= step as
// each block would repeat (so the result is bit for bit the same), into
// `twiddle`.
void Fft(std::vector<std::complex<double>>* data, std::vector<std::complex<double>>* twiddle) {
  std::vector<std::complex<double>>& a = *data;
  std::vector<std::complex<double>>& tw = *twiddle;
  const size_t n = a.size();
  for (size_t i = 1, j = 0; i < n; ++i) {
    size_t bit = n >> 1;
    for (; j & bit; bit >>= 1) j ^= bit;
    j ^= bit;
    if (i < j) std::swap(a[i], a[j]);
  }
  for (size_t len = 2; len <= n; len <<= 1) {
    const double angle = -2.0 * kPi / static_cast<double>(len);
    const std::complex<double> step(std::cos(angle), std::sin(angle));
    const size_t half = len / 2;
    tw.resize(half);
    std::complex<double> w(1.0, 0.0);
    for (size_t k = 0; k < half; ++k) {
      tw[k] = w;
      w *= step;
    }
    for (size_t i = 0; i < n; i += len) {
      std::complex<double>* lo = a.data() + i;
      std::complex<double>* hi = lo + half;
      for (size_t k = 0; k < half; ++k) {
        // v = hi[k] * tw[k] written out (the product std::complex takes for
        // finite values, without its check for infinities: the data are
        // finite).
        const double hr = hi[k].real(), hm = hi[k].imag();
        const double wr = tw[k].real(), wm = tw[k].imag();
        const std::complex<double> v(hr * wr - hm * wm, hr * wm + hm * wr);
        const std::complex<double> u = lo[k];
        lo[k] = u + v;
        hi[k] = u - v;
      }
    }
  }
}

// Welch's one-sided PSD with segments of `length`; *segments gets their
// number.
std::vector<double> WelchPsd(const std::vector<double>& x, size_t begin, size_t end, double rate_hz,
                             size_t length, size_t* segments) {
  std::vector<double> window(length);
  double w2 = 0.0;
  for (size_t i = 0; i < length; ++i) {
    window[i] = 0.5 - 0.5 * std::cos(2.0 * kPi * static_cast<double>(i) / length);
    w2 += window[i] * window[i];
  }
  std::vector<double> psd(length / 2 + 1, 0.0);
  std::vector<std::complex<double>> buffer(length), twiddle;
  *segments = 0;
  for (size_t start = begin; start + length <= end; start += length / 2) {
    double mean = 0.0;
    for (size_t i = 0; i < length; ++i) mean += x[start + i];
    mean /= static_cast<double>(length);
    for (size_t i = 0; i < length; ++i) buffer[i] = window[i] * (x[start + i] - mean);
    Fft(&buffer, &twiddle);
    for (size_t k = 0; k < psd.size(); ++k) psd[k] += std::norm(buffer[k]);
    ++*segments;
  }
  for (double& p : psd) p *= 2.0 / (rate_hz * w2 * static_cast<double>(*segments));
  return psd;
}

}  // namespace
}  // namespace internal

std::vector<SpectralLine> FindSpectralLines(const std::vector<double>& x, size_t begin, size_t end,
                                            double rate_hz, size_t max_lines) {
  std::vector<SpectralLine> lines;
  std::vector<double> resolution;  // bin width each line was last seen at, Hz
  const size_t n = end > begin && end <= x.size() ? end - begin : 0;
  // 256, 4096, 65536 and the longest 2^k with eight segments in the log.
  std::vector<size_t> lengths;
  for (size_t length : {size_t{256}, size_t{4096}, size_t{65536}}) {
    if (n >= 8 * length) lengths.push_back(length);
  }
  size_t longest = 256;
  while (2 * longest * 8 <= n) longest *= 2;
  if (n >= 8 * 256 && longest > lengths.back()) lengths.push_back(longest);
  for (size_t length : lengths) {
    size_t segments = 0;
    const std::vector<double> psd = internal::WelchPsd(x, begin, end, rate_hz, length, &segments);
    const double df = rate_hz / static_cast<double>(length);
    // Half-overlapping Hann segments: about 1.8 independent averages each.
    const double dof = 2.0 * std::max(1.0, 0.9 * static_cast<double>(segments));
    const double threshold =
        internal::ChiSquareQuantile(1.0 - 1e-3 / static_cast<double>(psd.size()), dof) / dof;
    for (size_t k = 8; k + 8 < psd.size(); ++k) {
      bool peak = true;
      for (size_t j = k - 3; j <= k + 3 && peak; ++j) peak = j == k || psd[j] < psd[k];
      if (!peak) continue;
      // The background: the geometric mean of the medians of the bins 4 to
      // D away on each side (D = 24, less near the ends), which follows a
      // sloping spectrum (a 1/f^2 random walk at low frequency) without
      // calling its low side a line.
      const size_t reach = std::min<size_t>({24, k - 1, psd.size() - 1 - k});
      std::vector<double> left, right;
      for (size_t d = 4; d <= reach; ++d) {
        left.push_back(psd[k - d]);
        right.push_back(psd[k + d]);
      }
      const double background = std::sqrt(internal::Median(left) * internal::Median(right));
      // The median of a chi-square average is below its mean by about 2 / (3 dof) relative.
      const double mean_background = background / (1.0 - 2.0 / (3.0 * dof));
      if (!(psd[k] > threshold * mean_background)) continue;
      double power = 0.0;
      for (size_t j = k - 2; j <= k + 2; ++j) power += psd[j] - mean_background;
      power *= df;  // the window's normalisation puts the line's power in its main lobe
      if (!(power > 0.0)) continue;
      SpectralLine line;
      line.frequency_hz = static_cast<double>(k) * df;
      line.amplitude = std::sqrt(2.0 * power);
      line.prominence = psd[k] / mean_background;
      // Seen at a coarser resolution already: keep the finer frequency.
      bool merged = false;
      for (size_t j = 0; j < lines.size() && !merged; ++j) {
        if (resolution[j] > df &&
            std::abs(lines[j].frequency_hz - line.frequency_hz) <= 2.0 * resolution[j]) {
          lines[j].frequency_hz = line.frequency_hz;
          lines[j].amplitude = std::max(lines[j].amplitude, line.amplitude);
          lines[j].prominence = std::max(lines[j].prominence, line.prominence);
          resolution[j] = df;
          merged = true;
        }
      }
      if (!merged) {
        lines.push_back(line);
        resolution.push_back(df);
      }
    }
  }
  std::sort(lines.begin(), lines.end(),
            [](const SpectralLine& a, const SpectralLine& b) { return a.amplitude > b.amplitude; });
  if (lines.size() > max_lines) lines.resize(max_lines);
  return lines;
}

namespace internal {

double NyquistFlatness(const std::vector<double>& x, size_t begin, size_t end, double rate_hz) {
  constexpr size_t kLength = 256;
  if (!(end > begin) || end > x.size() || end - begin < 8 * kLength || !(rate_hz > 0.0)) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  size_t segments = 0;
  const std::vector<double> psd = internal::WelchPsd(x, begin, end, rate_hz, kLength, &segments);
  // Bin k is at k / (kLength / 2) of Nyquist.
  auto band = [&psd](double from, double to) {
    const double half = static_cast<double>(kLength / 2);
    std::vector<double> bins;
    for (size_t k = static_cast<size_t>(std::ceil(from * half));
         k <= static_cast<size_t>(std::floor(to * half)) && k < psd.size(); ++k) {
      bins.push_back(psd[k]);
    }
    return internal::Median(bins);
  };
  const double middle = band(0.2, 0.4);
  if (!(middle > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  return std::sqrt(band(0.8, 0.97) / middle);
}

}  // namespace internal

double LineAllanVariance(const SpectralLine& line, double tau, double rate_hz) {
  const double m = tau * rate_hz;
  const double s = std::sin(internal::kPi * line.frequency_hz * tau);
  const double d = m * std::sin(internal::kPi * line.frequency_hz / rate_hz);
  return d != 0.0 ? line.amplitude * line.amplitude * s * s * s * s / (d * d) : 0.0;
}

double LineAllanBound(const SpectralLine& line, double tau) {
  const double x = internal::kPi * line.frequency_hz * tau;
  return line.amplitude * line.amplitude * std::min(x * x, 1.0 / (x * x));
}

std::string LineText(const SpectralLine& line) {
  std::ostringstream s;
  s.precision(4);
  s << line.frequency_hz << " Hz (amplitude " << std::setprecision(3) << line.amplitude << ")";
  return s.str();
}

}  // namespace gravcal
