// gravcal/estimation/pose_mean_covariance.h: the covariance of each static
// pose's mean raw accelerometer vector (Position::raw_mean_cov), which the
// refinement turns into the per-position sigma and, through it, into every
// reported standard deviation.
//
// Sensor noise is not white: bias instability and rate random walk make the
// samples of a pose positively correlated, and the variance of their mean
// over a pose of T seconds is larger than the white-noise value C / n
// (sample covariance over sample count). Three estimates:
//
//   white        C_mean = C / n. Right for white noise only (core/position.h,
//                PositionsFromIntervals).
//   batch_means  The pose's n samples are cut into b non-overlapping batches
//                of m = floor(n / b) samples (the last n - b m are left out of
//                the batches, not of the mean); with batch means y_j and their
//                average y,
//                  S = 1 / (b - 1) sum_j (y_j - y)(y_j - y)^T,
//                  C_mean = nu / (nu - 2) S m / n,   nu = b - 1.
//                S m / n alone is unbiased for the variance of the mean when
//                the noise is correlated over much less than m samples (white
//                included); correlation longer than a batch is partly missed
//                (biased low), still far better than C / n. It rests on nu
//                degrees of freedom, so each pose's variance is itself noisy
//                (relative sd sqrt(2 / nu), 0.32 at b = 20), and the
//                refinement uses its inverse as a weight: E[1 / chi2_nu * nu]
//                = nu / (nu - 2), so 1 / (S m / n) overweights by that factor
//                on average and the reported sigmas come out too small
//                (measured on the property harness, 400 seeds, white noise:
//                rms z 1.05-1.08 for twelve_position against 1.01 with C / n).
//                The factor nu / (nu - 2) makes the weight unbiased (rms z
//                0.98-1.03, inside the band). No floor at C / n: a floor
//                biases the variance high under white noise.
//   model        The noise model of `gravcal noise` (core/noise_model.h):
//                C_mean = diag(StillMeanVariance(axis, T)) / s^2, T the pose's
//                duration, i.e. the model's Allan variance at tau = T per
//                axis, with s (m/s^2 per raw unit) = 9.80665 / median over the
//                poses of |raw mean|: read from the data, so that no key has to
//                say the raw unit (a percent-level error of s changes the
//                variances by twice that, immaterial for a weight); the
//                off-diagonal correlations are those of C / n (the model has
//                none).
//
// When an estimate is not usable (too few samples for the batches, a
// singular or non-finite covariance, an axis the model does not show), the
// pose keeps the white-noise value and a note says so.
#ifndef GRAVCAL_ESTIMATION_POSE_MEAN_COVARIANCE_H_
#define GRAVCAL_ESTIMATION_POSE_MEAN_COVARIANCE_H_

#include <string>
#include <vector>

#include "gravcal/core/imu_log.h"
#include "gravcal/core/noise_model.h"
#include "gravcal/core/position.h"

namespace gravcal {

enum class PoseNoise {
  kWhite,
  kBatchMeans,
};

const char* ToString(PoseNoise pose_noise);
// Accepts "white", "batch_means".
bool FromString(const std::string& name, PoseNoise* pose_noise);
std::string AcceptedNames(PoseNoise);

struct PoseNoiseOptions {
  // The estimate used when no noise model is given.
  PoseNoise method = PoseNoise::kWhite;
  // Batches per pose for kBatchMeans (>= 5). A pose with fewer than
  // 2 * batches samples keeps the white-noise value.
  int batches = 20;
  // The noise model (SI units, not owned): when set, it replaces `method`
  // for every pose.
  const ImuNoiseModel* model = nullptr;

  bool IsValid(std::string* error) const;
};

// Sets positions[k].raw_mean_cov for the pose made of intervals[k] of the
// log (positions as PositionsFromIntervals made them: same size and order).
// Appends to *notes a line per kind of fallback or disagreement (the
// model's white noise per sample more than twice or less than half the
// pose's own sample standard deviation: a noise model of another sensor, or
// made with a wrong nominal_scale). Returns false (error set) only on invalid
// options or mismatched sizes.
bool SetPoseMeanCovariance(const ImuLog& log, const std::vector<StaticInterval>& intervals,
                           const PoseNoiseOptions& options, std::vector<Position>* positions,
                           std::vector<std::string>* notes, std::string* error);

// The batch-means covariance of the mean of samples [begin, end) of `x`
// (above), or false when there are fewer than 2 * batches samples.
bool BatchMeansCovariance(const std::vector<Eigen::Vector3d>& x, size_t begin, size_t end,
                          int batches, Eigen::Matrix3d* covariance);

}  // namespace gravcal

#endif  // GRAVCAL_ESTIMATION_POSE_MEAN_COVARIANCE_H_
