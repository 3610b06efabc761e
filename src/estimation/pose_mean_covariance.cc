#include "gravcal/estimation/pose_mean_covariance.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/enum_names.h"
#include "gravcal/core/gravity.h"
#include "gravcal/estimation/coarse_fit.h"
#include "util/matrix_checks.h"

namespace gravcal {
namespace internal {
namespace {

// The pose's duration: n samples at the interval's mean step.
double PoseSeconds(const StaticInterval& s) {
  const size_t n = s.count();
  if (n < 2) return 0.0;
  return (s.t_end - s.t_begin) * static_cast<double>(n) / static_cast<double>(n - 1);
}

// The model's covariance of the mean for one pose, raw units; false when an
// axis is not shown. *ratio gets the largest disagreement factor between the
// model's white noise per sample and the pose's own sample deviation.
bool ModelCovariance(const StaticInterval& s, const Position& white, const ImuNoiseModel& model,
                     double nominal_scale, Eigen::Matrix3d* cov, double* ratio) {
  const double seconds = PoseSeconds(s);
  if (!(seconds > 0.0)) return false;
  const Eigen::Vector3d var = StillMeanVariance(model.accel, seconds);
  if (!var.allFinite()) return false;
  const double s2 = nominal_scale * nominal_scale;
  const double n = static_cast<double>(s.count());
  *ratio = 1.0;
  for (int a = 0; a < 3; ++a) {
    const double rate = n / seconds;
    const double model_sample = model.accel[a].white_noise.value * std::sqrt(rate);
    const double own_sample = nominal_scale * std::sqrt(s.accel_cov(a, a));
    if (own_sample > 0.0 && model_sample > 0.0) {
      const double r = model_sample / own_sample;
      *ratio = std::max(*ratio, std::max(r, 1.0 / r));
    }
  }
  // Off-diagonal terms of the white value, rescaled to the model's diagonal.
  const Eigen::Vector3d white_sd = white.raw_mean_cov.diagonal().cwiseSqrt();
  const Eigen::Vector3d model_sd = (var / s2).cwiseSqrt();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      const double rho = i == j ? 1.0
                                : (white_sd[i] > 0.0 && white_sd[j] > 0.0
                                       ? white.raw_mean_cov(i, j) / (white_sd[i] * white_sd[j])
                                       : 0.0);
      (*cov)(i, j) = rho * model_sd[i] * model_sd[j];
    }
  }
  return true;
}

// m/s^2 per raw unit, and how it was found. The coarse fit's scale (the
// cube root of |det| of its matrix) when the poses allow one: it separates an
// offset (unsigned counts around 32768, volts around 1.65) from gravity.
// Else standard gravity over the median |raw mean|, which assumes no offset;
// 0 when there is no pose with a nonzero mean.
double ScaleFromPoses(const std::vector<Position>& positions, std::string* how) {
  CoarseFitResult coarse;
  if (CoarseFit(positions, kStandardGravity, AccelParameterization::kScale, CoarseFitOptions(),
                &coarse)) {
    const double scale = std::cbrt(std::abs(coarse.model.matrix().determinant()));
    if (std::isfinite(scale) && scale > 0.0) {
      *how = "the coarse fit's scale";
      return scale;
    }
  }
  std::vector<double> norms;
  for (const Position& p : positions) {
    if (p.raw_mean.norm() > 0.0) norms.push_back(p.raw_mean.norm());
  }
  if (norms.empty()) return 0.0;
  std::nth_element(norms.begin(), norms.begin() + norms.size() / 2, norms.end());
  *how = "g over the median |raw pose mean| (no coarse fit: " + coarse.message +
         "; a raw offset would make it wrong)";
  return kStandardGravity / norms[norms.size() / 2];
}

}  // namespace
}  // namespace internal

namespace {
const internal::EnumName<PoseNoise> kPoseNoises[] = {{PoseNoise::kWhite, "white"},
                                                     {PoseNoise::kBatchMeans, "batch_means"}};
}  // namespace

GRAVCAL_ENUM_STRINGS(PoseNoise, kPoseNoises)

bool PoseNoiseOptions::IsValid(std::string* error) const {
  if (batches < 5) {
    *error = "pose_noise_batches: must be at least 5";
    return false;
  }
  return true;
}

bool BatchMeansCovariance(const std::vector<Eigen::Vector3d>& x, size_t begin, size_t end,
                          int batches, Eigen::Matrix3d* covariance) {
  const size_t n = end - begin;
  const size_t b = static_cast<size_t>(batches);
  if (batches < 2 || end > x.size() || begin >= end || n < 2 * b) return false;
  const size_t m = n / b;
  std::vector<Eigen::Vector3d> means(b, Eigen::Vector3d::Zero());
  Eigen::Vector3d grand = Eigen::Vector3d::Zero();
  for (size_t j = 0; j < b; ++j) {
    for (size_t i = 0; i < m; ++i) means[j] += x[begin + j * m + i];
    means[j] /= static_cast<double>(m);
    grand += means[j];
  }
  grand /= static_cast<double>(b);
  Eigen::Matrix3d s = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& y : means) s += (y - grand) * (y - grand).transpose();
  s /= static_cast<double>(b - 1);
  const double dof = static_cast<double>(b - 1);
  const double unbiased_weight = dof / (dof - 2.0);
  *covariance = s * (unbiased_weight * static_cast<double>(m) / static_cast<double>(n));
  return true;
}

bool SetPoseMeanCovariance(const ImuLog& log, const std::vector<StaticInterval>& intervals,
                           const PoseNoiseOptions& options, std::vector<Position>* positions,
                           std::vector<std::string>* notes, std::string* error) {
  if (!options.IsValid(error)) return false;
  if (positions->size() != intervals.size()) {
    *error = "pose covariance: positions and intervals differ in number";
    return false;
  }
  if (options.model == nullptr && options.method == PoseNoise::kWhite) return true;
  std::string scale_source;
  const double nominal_scale = internal::ScaleFromPoses(*positions, &scale_source);
  int fallbacks = 0;
  double worst_ratio = 1.0;
  for (size_t k = 0; k < intervals.size(); ++k) {
    const StaticInterval& s = intervals[k];
    Position& p = (*positions)[k];
    Eigen::Matrix3d cov;
    bool ok = false;
    if (options.model != nullptr && nominal_scale > 0.0) {
      double ratio = 1.0;
      ok = internal::ModelCovariance(s, p, *options.model, nominal_scale, &cov, &ratio);
      if (ok) worst_ratio = std::max(worst_ratio, ratio);
    } else if (options.model == nullptr) {
      ok = BatchMeansCovariance(log.accel, s.begin, s.end, options.batches, &cov);
    }
    if (ok && internal::IsSafelyPositiveDefinite(cov)) {
      p.raw_mean_cov = cov;
    } else {
      ++fallbacks;
    }
  }
  std::ostringstream s;
  s.precision(3);
  if (fallbacks > 0) {
    s << fallbacks << " of " << intervals.size() << " positions keep the white-noise covariance "
      << "of the mean (sample covariance / n): "
      << (options.model != nullptr
              ? "the noise model does not show white noise on every accelerometer axis"
              : "fewer than 2 x pose_noise_batches samples or constant data");
    notes->push_back(s.str());
  }
  if (worst_ratio > 2.0) {
    std::ostringstream r;
    r.precision(3);
    r << "the noise model's accelerometer white noise per sample differs from the poses' own "
         "by a factor up to "
      << worst_ratio << " (raw unit " << nominal_scale << " m/s^2 from " << scale_source
      << "): check that the noise model is of this sensor and that gravcal noise had the right "
         "nominal_scale and gyro_nominal_scale";
    notes->push_back(r.str());
  }
  return true;
}

}  // namespace gravcal
