// The moving-window statistics the static detector thresholds: windowed
// variance and level change of a 3-axis signal, its noise floor, the median
// time step and the scale of the gyroscope's turns
// (detection/static_detector_internal.h).
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "detection/static_detector_internal.h"

namespace gravcal {
namespace internal {

// Moving-window variance of one 3-axis signal: var[k] = sum over the axes of
// the (population) variance of x[k, k+w), for k in [0, n - w]. One pass of
// running sums of deviations from a reference sample that is renewed every
// block (so neither cancellation nor rounding drift builds up; the block
// restarts cost 1/16 extra). Returns false when the signal is not finite.
bool WindowVariance(const std::vector<Eigen::Vector3d>& x, size_t w, float* var) {
  // x and y in one SSE2 register pair (Array2d), z scalar.
  using A2 = Eigen::Array2d;
  const size_t num_windows = x.size() - w + 1;
  const double* p = x[0].data();  // contiguous: 3 doubles per sample
  const size_t block = std::max<size_t>(16 * w, 4096);
  const double inv_w = 1.0 / static_cast<double>(w);
  const double inv_w2 = inv_w * inv_w;
  for (size_t k0 = 0; k0 < num_windows; k0 += block) {
    const A2 r01 = Eigen::Map<const A2>(p + 3 * k0);
    const double r2 = p[3 * k0 + 2];
    A2 s01 = A2::Zero(), q01 = A2::Zero();
    double s2 = 0.0, q2 = 0.0;
    for (size_t i = k0; i < k0 + w; ++i) {
      const A2 d01 = Eigen::Map<const A2>(p + 3 * i) - r01;
      const double d2 = p[3 * i + 2] - r2;
      s01 += d01;
      q01 += d01 * d01;
      s2 += d2;
      q2 += d2 * d2;
    }
    const size_t k_last = std::min(num_windows, k0 + block) - 1;
    for (size_t k = k0;; ++k) {
      const A2 m = s01 * s01;
      const double v = (q01[0] + q01[1] + q2) * inv_w - (m[0] + m[1] + s2 * s2) * inv_w2;
      var[k] = static_cast<float>(v > 0.0 ? v : 0.0);
      if (k == k_last) break;
      const double* out = p + 3 * k;
      const double* in = p + 3 * (k + w);
      const A2 o01 = Eigen::Map<const A2>(out) - r01;
      const A2 i01 = Eigen::Map<const A2>(in) - r01;
      const double o2 = out[2] - r2, i2 = in[2] - r2;
      s01 += i01 - o01;
      q01 += (i01 - o01) * (i01 + o01);
      s2 += i2 - o2;
      q2 += (i2 - o2) * (i2 + o2);
    }
    // Every sample of the block entered the sums, and NaN and infinity stick.
    if (!std::isfinite(s01.sum() + s2 + q01.sum() + q2)) return false;
  }
  return true;
}

// Moving-window level change of one 3-axis signal: trend[k] = |m2 - m1|^2
// (summed over the axes), m1 and m2 the means of x[k, k+h) and x[k+h, k+w),
// h = w / 2, for k in [0, n - w]. Running sums of deviations from a
// reference renewed every block, as WindowVariance.
void WindowTrend(const std::vector<Eigen::Vector3d>& x, size_t w, float* trend) {
  const size_t num_windows = x.size() - w + 1;
  const size_t h = w / 2;
  const double inv1 = 1.0 / static_cast<double>(h);
  const double inv2 = 1.0 / static_cast<double>(w - h);
  const size_t block = std::max<size_t>(16 * w, 4096);
  for (size_t k0 = 0; k0 < num_windows; k0 += block) {
    const Eigen::Vector3d r = x[k0];
    Eigen::Vector3d s1 = Eigen::Vector3d::Zero(), s2 = Eigen::Vector3d::Zero();
    for (size_t i = k0; i < k0 + h; ++i) s1 += x[i] - r;
    for (size_t i = k0 + h; i < k0 + w; ++i) s2 += x[i] - r;
    const size_t k_last = std::min(num_windows, k0 + block) - 1;
    for (size_t k = k0;; ++k) {
      trend[k] = static_cast<float>((s2 * inv2 - s1 * inv1).squaredNorm());
      if (k == k_last) break;
      s1 += x[k + h] - x[k];
      s2 += x[k + w] - x[k + h];
    }
  }
}

// Half the mean squared sample-to-sample difference (summed over the axes) in
// non-overlapping blocks of w samples, at most kMaxWhiteBlocks of them evenly
// spread: the white-noise variance, which smooth motion barely raises.
constexpr size_t kMaxWhiteBlocks = 1024;
void WhiteNoise(const std::vector<Eigen::Vector3d>& x, size_t w, std::vector<double>* white) {
  const size_t num_blocks = x.size() / w;
  const size_t stride = std::max<size_t>(1, (num_blocks + kMaxWhiteBlocks - 1) / kMaxWhiteBlocks);
  const double scale = 0.5 / static_cast<double>(w - 1);
  white->clear();
  for (size_t b = 0; b < num_blocks; b += stride) {
    double sum = 0.0;
    for (size_t i = b * w + 1; i < (b + 1) * w; ++i) sum += (x[i] - x[i - 1]).squaredNorm();
    white->push_back(sum * scale);
  }
}

// Smallest nonzero step between consecutive samples, per axis (0 if none).
Eigen::Vector3d SmallestStep(const std::vector<Eigen::Vector3d>& x, size_t begin, size_t end) {
  Eigen::Array3d step = Eigen::Array3d::Constant(std::numeric_limits<double>::infinity());
  for (size_t i = begin + 1; i < end; ++i) {
    const Eigen::Array3d d = (x[i] - x[i - 1]).array().abs();
    step = (d > 0.0).select(d.min(step), step);
  }
  return (step.isFinite()).select(step, 0.0).matrix();
}

// The noise floor of one signal: the quantile of the windowed variance, at
// most max_floor_ratio times the white-noise level, and never zero while the
// data change at all.
double NoiseFloor(const float* var, size_t num_windows, const std::vector<Eigen::Vector3d>& x,
                  size_t w, const StaticDetectorOptions& options, std::vector<double>* scratch) {
  double floor = StridedQuantile(var, num_windows, options.noise_quantile, scratch);
  if (options.max_floor_ratio > 0.0) {
    std::vector<double> white;
    WhiteNoise(x, w, &white);
    const double white_floor =
        StridedQuantile(white.data(), white.size(), options.noise_quantile, scratch);
    if (white_floor > 0.0) floor = std::min(floor, options.max_floor_ratio * white_floor);
  }
  if (floor <= 0.0) {
    // Quantised data with many identical samples: the variance of uniform
    // quantisation error, step^2 / 12 per axis.
    const Eigen::Vector3d step = SmallestStep(x, 0, x.size());
    floor = step.squaredNorm() / 12.0;
  }
  return floor;
}

// Median sample interval (on a strided subsample of the intervals).
double MedianSampleInterval(const std::vector<double>& t, std::vector<double>* scratch) {
  const size_t n = t.size();
  scratch->clear();
  const size_t stride = std::max<size_t>(1, (n - 1 + kMaxQuantileValues - 1) / kMaxQuantileValues);
  for (size_t i = 1; i < n; i += stride) scratch->push_back(t[i] - t[i - 1]);
  std::nth_element(scratch->begin(), scratch->begin() + scratch->size() / 2, scratch->end());
  return (*scratch)[scratch->size() / 2];
}

// The 99th percentile of |x - median| (median per axis), on a strided
// subsample: the scale of the gyroscope's turns.
double RateScale(const std::vector<Eigen::Vector3d>& x, std::vector<double>* scratch) {
  Eigen::Vector3d median;
  std::vector<double> axis;
  const size_t stride = std::max<size_t>(1, x.size() / kMaxQuantileValues);
  for (int a = 0; a < 3; ++a) {
    axis.clear();
    for (size_t i = 0; i < x.size(); i += stride) axis.push_back(x[i][a]);
    median[a] = StridedQuantile(axis.data(), axis.size(), 0.5, scratch);
  }
  axis.clear();
  for (size_t i = 0; i < x.size(); i += stride) axis.push_back((x[i] - median).norm());
  return StridedQuantile(axis.data(), axis.size(), 0.99, scratch);
}

}  // namespace internal
}  // namespace gravcal
