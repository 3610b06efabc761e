// Private: how far a still log's noise spectrum reaches toward the Nyquist
// frequency (for `gravcal noise`'s comparison with a datasheet density).
#ifndef GRAVCAL_SRC_ESTIMATION_NYQUIST_FLATNESS_H_
#define GRAVCAL_SRC_ESTIMATION_NYQUIST_FLATNESS_H_

#include <cstddef>
#include <vector>

namespace gravcal {
namespace internal {

// The square root of the ratio of the median Welch PSD of samples [begin,
// end) of x (segments of 256 samples, spectral_lines.h's estimate) over
// 0.8-0.97 of Nyquist to that over 0.2-0.4 of it (medians: lines do not move
// them). About 1 for noise that is white up to Nyquist, as when the
// sensor's bandwidth reaches past it and the noise above folds in
// (aliasing); well below 1 when a low-pass filter below Nyquist shapes it.
// NaN for fewer than 8 x 256 samples.
double NyquistFlatness(const std::vector<double>& x, size_t begin, size_t end, double rate_hz);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_ESTIMATION_NYQUIST_FLATNESS_H_
