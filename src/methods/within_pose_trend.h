// Private: the trend of the raw accelerometer mean within each static pose,
// against time, and of the temperature, for the effect fit's trend residual
// (gravcal/residuals/accel_trend_residual.h).
//
// Pose k's samples are cut into B batches of m_k = floor(n_k / B) samples
// (the last n_k - B m_k are left out), as the batch-means estimate of
// pose_mean_covariance.h does; with batch means y_j of the raw vector, tau_j
// of the time and theta_j of the temperature, the least-squares line
//
//   y_j = ybar + g_k (tau_j - taubar) + e_j
//
// gives the slope g_k = sum_j (tau_j - taubar) (y_j - ybar) / D_k,
// D_k = sum_j (tau_j - taubar)^2, and the temperature slope Tdot_k likewise.
// The noise is read from the scatter of the batch means about their line,
// R_k = sum_j e_j e_j^T on nu_k = B - 2 degrees of freedom: the trend itself
// (the effect being looked for) does not enter it, unlike the plain batch
// means of the pose, and noise correlated over less than a batch (m_k
// samples) is counted in full. Correlation longer than a batch (bias
// instability, random walk) is only partly counted; for consumer parts
// held 10-30 s it adds a few percent to the variance of a slope (see
// docs/workflows/discover.md).
//
// The sensor's noise is one process, so the estimate is pooled over the
// poses, in per-sample units:
//
//   S = nu / (nu - 4) sum_k m_k R_k / nu,   nu = sum_k nu_k,
//
// and cov(g_k) = S / (m_k D_k). A per-pose estimate on nu_k = 8 degrees of
// freedom would make each pose's whitened slope a Hotelling T^2 (mean
// 3 nu_k / (nu_k - 4) = 6 instead of 3) and bias every chi2 test; pooling
// leaves nu in the hundreds, and the factor nu / (nu - 4) makes the
// expected x^T cov^-1 x of a 3-vector exactly 3. When only the component
// along gravity is used (along_gravity), a scalar t on nu degrees of
// freedom, the factor is nu / (nu - 2): E[t^2] = nu / (nu - 2) for
// Student's t, so the whitened component has unit mean square. Fewer,
// longer batches (5 of 6 s on a 30 s hold) count more of the correlated
// noise in each batch mean at the price of fewer degrees of freedom, which
// the pooling over the poses restores. A batch mean cannot be
// known better than its rounding when the data do not dither: an axis whose
// batch means never changed gets step^2 / 12 (the interval's resolution).
#ifndef GRAVCAL_SRC_METHODS_WITHIN_POSE_TREND_H_
#define GRAVCAL_SRC_METHODS_WITHIN_POSE_TREND_H_

#include <Eigen/Core>
#include <vector>

#include "gravcal/core/imu_log.h"
#include "gravcal/core/position.h"

namespace gravcal {
namespace internal {

struct PoseTrend {
  // False for a pose too short for the batches (then the rest is zero).
  bool valid = false;
  // g_k, raw units per second, and its covariance.
  Eigen::Vector3d accel_slope = Eigen::Vector3d::Zero();
  Eigen::Matrix3d accel_slope_cov = Eigen::Matrix3d::Identity();
  // Tdot_k, degC per second (0 without a temperature column).
  double temperature_slope = 0.0;
};

// One trend per interval of the log. A pose gets one when it has at least
// `batches` * `min_batch_samples` samples and lasts `min_seconds` or more;
// none at all when fewer than two poses qualify (no pooled noise). With
// along_gravity the covariance carries the scalar Student factor (it is
// then meant for the component along the pose's mean only).
std::vector<PoseTrend> WithinPoseTrends(const ImuLog& log,
                                        const std::vector<StaticInterval>& intervals, int batches,
                                        int min_batch_samples, double min_seconds,
                                        bool along_gravity);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_METHODS_WITHIN_POSE_TREND_H_
