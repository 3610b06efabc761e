// Shared by the tests that judge standard deviations on the real recordings
// of ../shared/data/real (issue 14, issue 33): the poses of a recording as
// the pipeline found them, refits on subsets of them with the same options,
// and the z statistics that say whether the sigmas are honest.
#ifndef GRAVCAL_TESTS_REAL_SESSIONS_H_
#define GRAVCAL_TESTS_REAL_SESSIONS_H_

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "estimation/variance_component.h"
#include "gravcal/estimation/refinement.h"
#include "gravcal/methods/twelve_position.h"
#include "gravcal/workflows/config.h"
#include "gravcal/workflows/pipeline.h"
#include "test_util.h"

namespace gravcal {
namespace testing_util {

// The real recordings with static poses, each with its shipped config.
struct RealPoseSession {
  const char* config;
  const char* file;
};

inline const std::vector<RealPoseSession>& RealPoseSessions() {
  static const std::vector<RealPoseSession> sessions = {
      {"ahrs_static_poses.yaml", "ahrs_static_poses/imu_good1.txt"},
      {"ahrs_static_poses.yaml", "ahrs_static_poses/imu_good2.txt"},
      {"ahrs_static_poses.yaml", "ahrs_static_poses/imu_good3.txt"},
      {"mpu6050_ten_pose.yaml", "mpu6050_ten_pose/session.csv"},
      {"ferraris_nilspod.yaml", "ferraris_nilspod/session.csv"},
  };
  return sessions;
}

// A full calibration's poses and the options that refit a subset of them
// exactly as the full fit was made (gravity fixed at the full fit's, the
// nominal axes re-assigned, a prior the full fit set aside kept aside: a
// refit on fewer poses, whose conflict test is weaker, must not bring it
// back).
struct RealFit {
  Calibration calibration;
  std::vector<Position> positions;
  CalibrationOptions refit;
};

inline bool CalibrateRealSession(const Config& config, const ImuLog& log, const std::string& name,
                                 RealFit* fit) {
  PipelineInput input;
  input.log = log;
  input.source = name;
  if (!RunCalibration(config, input, &fit->calibration)) return false;
  const Calibration& c = fit->calibration;
  fit->positions.clear();
  for (const PositionReport& p : c.positions) fit->positions.push_back(p.position);
  fit->refit = config.calibration;
  fit->refit.gravity = GravityOptions();
  fit->refit.gravity.gravity = c.gravity;
  fit->refit.nominal_up.clear();
  if (c.accel.pose_variance.prior_set_aside) fit->refit.refinement.pose_disturbance_prior_dof = 0.0;
  return true;
}

// The free parameters of a fit and their standard deviations (NaN for a
// parameter the poses do not determine: it is reported without a number).
struct ParameterEstimate {
  Eigen::VectorXd value, sigma;
};

inline bool EstimateOf(const Calibration& c, AccelParameterization p, ParameterEstimate* e) {
  if (!c.refinement.covariance_available) return false;
  e->value = FreeParameters(c.accel.model, p);
  const Eigen::VectorXd d = c.refinement.covariance.diagonal();
  if (d.size() != e->value.size()) return false;
  e->sigma = d.array().sqrt();
  const std::vector<std::string>& names = c.refinement.parameter_names;
  const std::vector<std::string>& undetermined = c.refinement.observability.undetermined;
  for (size_t k = 0; k < names.size() && k < static_cast<size_t>(e->sigma.size()); ++k) {
    if (std::find(undetermined.begin(), undetermined.end(), names[k]) != undetermined.end()) {
      e->sigma(k) = NAN;
    }
  }
  return true;
}

// z = (a - b) / sqrt(sa^2 + sb^2) of every parameter both determine,
// appended to *z.
inline void AppendZ(const ParameterEstimate& a, const ParameterEstimate& b,
                    std::vector<double>* z) {
  for (int k = 0; k < a.value.size() && k < b.value.size(); ++k) {
    const double v = (a.value(k) - b.value(k)) / std::hypot(a.sigma(k), b.sigma(k));
    if (std::isfinite(v)) z->push_back(v);
  }
}

inline double RmsOf(const std::vector<double>& z) {
  if (z.empty()) return NAN;
  double sum = 0.0;
  for (double v : z) sum += v * v;
  return std::sqrt(sum / z.size());
}

// The fit to one half of the poses: interleaved, those with index % 2 ==
// half; else the first (half 0) or second (1) half in time. False when they
// do not give a fit with a covariance.
inline bool FitHalf(const RealFit& fit, int half_index, bool interleaved, ParameterEstimate* e) {
  std::vector<Position> half;
  const size_t n = fit.positions.size();
  for (size_t i = 0; i < n; ++i) {
    const int which = interleaved ? static_cast<int>(i % 2) : (2 * i >= n ? 1 : 0);
    if (which == half_index) half.push_back(fit.positions[i]);
  }
  Calibration c;
  return CalibrateFromPositions(half, fit.refit, &c) &&
         EstimateOf(c, fit.refit.refinement.parameterization, e);
}

// The split-half z of every parameter: the even poses' fit against the odd
// poses' (interleaved), or the first half's against the second's (the halves
// are independent, so z ~ N(0, 1) with honest sigmas).
inline std::vector<double> SplitHalfZ(const RealFit& fit, bool interleaved = true) {
  ParameterEstimate a, b;
  std::vector<double> z;
  if (FitHalf(fit, 0, interleaved, &a) && FitHalf(fit, 1, interleaved, &b)) AppendZ(a, b, &z);
  return z;
}

// Pose k left out, the others fitted with fit.refit, and the left-out
// pose's residual |a_k| - g over its predicted standard deviation,
//
//   var_k = j_k C j_k^T + f (sigma_k^2 + s^2),
//
// j_k the row of the magnitude Jacobian at the fitted model, C the fit's
// (already inflated) covariance, sigma_k the pose's own noise, s^2 the
// per-pose variance the fit estimated and f its Student-t inflation
// (estimation/variance_component.h; 1 without pose_variance). NaN when the
// other poses do not give a fit with a covariance.
inline double LeftOutZ(const RealFit& full, size_t k) {
  std::vector<Position> others;
  for (size_t i = 0; i < full.positions.size(); ++i) {
    if (i != k) others.push_back(full.positions[i]);
  }
  Calibration fit;
  if (!CalibrateFromPositions(others, full.refit, &fit) || !fit.refinement.covariance_available) {
    return NAN;
  }
  const AccelModel& model = fit.refinement.model;
  const std::vector<Position> left = {full.positions[k]};
  const double residual = MagnitudeResiduals(left, model, fit.gravity)[0];
  const Eigen::MatrixXd j = MagnitudeJacobian(left, model, {1.0});
  const double white = MagnitudeSigmas(left, model)[0];
  const VarianceComponent& vc = fit.accel.pose_variance;
  double pose = white * white;
  if (vc.absorbed) {
    double white_mean = 0.0;
    const std::vector<double> sigmas = MagnitudeSigmas(others, model);
    for (double s : sigmas) white_mean += s * s / sigmas.size();
    pose = (pose + vc.variance) * internal::StudentInflation(vc, white_mean, nullptr);
  }
  const Eigen::MatrixXd& c = fit.refinement.covariance;
  if (c.rows() != j.cols()) return NAN;
  const double variance = (j * c * j.transpose())(0, 0) + pose;
  return residual / std::sqrt(variance);
}

// LeftOutZ of every pose (NaN entries where the others give no fit).
inline std::vector<double> LeaveOnePoseOutZ(const RealFit& full) {
  std::vector<double> z;
  for (size_t k = 0; k < full.positions.size(); ++k) z.push_back(LeftOutZ(full, k));
  return z;
}

}  // namespace testing_util
}  // namespace gravcal

#endif  // GRAVCAL_TESTS_REAL_SESSIONS_H_
