#include "gravcal/methods/rate_table.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cmath>
#include <sstream>

#include "core/warnings.h"

namespace gravcal {
namespace {

// Smallest / largest eigenvalue of the normal matrix below which the rates
// do not determine the fit.
constexpr double kConditionLimit = 1e-12;

// Per segment: the mean output and the variance of that mean, per axis.
// False with a message naming a segment outside the log.
bool SegmentMeans(const ImuLog& log, const std::vector<RateTableSegment>& segments,
                  std::vector<Eigen::Vector3d>* mean, std::vector<Eigen::Vector3d>* mean_var,
                  std::string* message) {
  const size_t k_count = segments.size();
  mean->assign(k_count, Eigen::Vector3d::Zero());
  mean_var->assign(k_count, Eigen::Vector3d::Zero());
  for (size_t k = 0; k < k_count; ++k) {
    const RateTableSegment& seg = segments[k];
    if (seg.end > log.size() || seg.begin + 2 > seg.end || !seg.rate.allFinite()) {
      std::ostringstream s;
      s << "rate table: segment " << k << " [" << seg.begin << ", " << seg.end
        << ") is outside the log (" << log.size() << " samples) or has fewer than 2 samples";
      *message = s.str();
      return false;
    }
    const double n = static_cast<double>(seg.end - seg.begin);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (size_t i = seg.begin; i < seg.end; ++i) sum += log.gyro[i];
    (*mean)[k] = sum / n;
    Eigen::Vector3d sq = Eigen::Vector3d::Zero();
    for (size_t i = seg.begin; i < seg.end; ++i) {
      sq += (log.gyro[i] - (*mean)[k]).cwiseAbs2();
    }
    // A noise-free output would get infinite weight: floor the variance.
    (*mean_var)[k] = (sq / (n - 1.0)).cwiseMax(1e-20) / n;
  }
  return true;
}

// Per output axis i: u_k,i = a_i . w_k + b_i, weighted least squares.
// `cov` is the covariance of (b, row-major vec(A)). False with a message
// when the segment rates do not determine the fit.
bool FitOutputAxes(const std::vector<RateTableSegment>& segments,
                   const std::vector<Eigen::Vector3d>& mean,
                   const std::vector<Eigen::Vector3d>& mean_var, Eigen::Matrix3d* a,
                   Eigen::Vector3d* b, Eigen::Matrix<double, 12, 12>* cov, std::string* message) {
  *cov = Eigen::Matrix<double, 12, 12>::Zero();
  for (int i = 0; i < 3; ++i) {
    Eigen::Matrix4d normal = Eigen::Matrix4d::Zero();
    Eigen::Vector4d rhs = Eigen::Vector4d::Zero();
    for (size_t k = 0; k < segments.size(); ++k) {
      Eigen::Vector4d x;
      x << segments[k].rate, 1.0;
      const double w = 1.0 / mean_var[k](i);
      normal.noalias() += w * x * x.transpose();
      rhs += w * mean[k](i) * x;
    }
    // Scale-free rank test on the normalised normal matrix.
    const Eigen::Vector4d d = normal.diagonal().cwiseSqrt().cwiseInverse();
    const Eigen::Matrix4d scaled = d.asDiagonal() * normal * d.asDiagonal();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eig(scaled);
    if (!(eig.eigenvalues()(0) > kConditionLimit * eig.eigenvalues()(3))) {
      *message =
          "rate table: the segment rates do not determine the gyroscope (they need to span "
          "rotations about three axes plus a still segment or the opposite direction)";
      return false;
    }
    const Eigen::Matrix4d inv = normal.inverse();
    const Eigen::Vector4d theta = inv * rhs;
    a->row(i) = theta.head<3>().transpose();
    (*b)(i) = theta(3);
    (*cov)(i, i) = inv(3, 3);
    for (int j = 0; j < 3; ++j) {
      (*cov)(i, 3 + 3 * i + j) = inv(3, j);
      (*cov)(3 + 3 * i + j, i) = inv(j, 3);
      for (int l = 0; l < 3; ++l) (*cov)(3 + 3 * i + j, 3 + 3 * i + l) = inv(j, l);
    }
  }
  return true;
}

// The gyroscope model M = A^-1 with bias b, and the covariance of
// (b, vec(M)) from that of (b, vec(A)): dM_rc / dA_ij = -M_ri M_jc.
void FillGyro(const Eigen::Matrix3d& m, const Eigen::Vector3d& b,
              const Eigen::Matrix<double, 12, 12>& cov, GyroCalibration* g) {
  Eigen::Matrix<double, 12, 12> jac = Eigen::Matrix<double, 12, 12>::Zero();
  jac.topLeftCorner<3, 3>().setIdentity();
  for (int rr = 0; rr < 3; ++rr) {
    for (int c = 0; c < 3; ++c) {
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) jac(3 + 3 * rr + c, 3 + 3 * i + j) = -m(rr, i) * m(j, c);
      }
    }
  }
  const Eigen::Matrix<double, 12, 12> out = jac * cov * jac.transpose();
  g->estimated = true;
  g->model.bias = b;
  g->model.matrix = m;
  g->covariance = out;
  const char* axes = "xyz";
  for (int i = 0; i < 3; ++i) g->covariance_names.push_back(std::string("bias_") + axes[i]);
  for (int rr = 0; rr < 3; ++rr) {
    for (int c = 0; c < 3; ++c) {
      g->covariance_names.push_back(std::string("m_") + axes[rr] + axes[c]);
      g->matrix_std(rr, c) = std::sqrt(out(3 + 3 * rr + c, 3 + 3 * rr + c));
    }
  }
  for (int i = 0; i < 3; ++i) g->bias_std(i) = std::sqrt(out(i, i));
}

}  // namespace

bool CalibrateRateTable(const ImuLog& log, const std::vector<RateTableSegment>& segments,
                        RateTableResult* result) {
  *result = RateTableResult();
  RateTableResult& r = *result;
  std::string error;
  if (!log.Validate(&error)) {
    r.message = error;
    return false;
  }
  if (!log.has_gyro()) {
    r.message = log.source + ": the rate-table calibration needs a gyroscope";
    return false;
  }
  if (segments.size() < 4) {
    std::ostringstream s;
    s << "rate table: " << segments.size()
      << " segments; at least 4 are needed (rotations about three axes plus a still segment or "
         "the opposite direction)";
    r.message = s.str();
    return false;
  }
  const size_t k_count = segments.size();
  std::vector<Eigen::Vector3d> mean, mean_var;
  if (!SegmentMeans(log, segments, &mean, &mean_var, &r.message)) return false;
  Eigen::Matrix3d a;
  Eigen::Vector3d b;
  Eigen::Matrix<double, 12, 12> cov;
  if (!FitOutputAxes(segments, mean, mean_var, &a, &b, &cov, &r.message)) return false;
  const Eigen::Matrix3d m = a.inverse();
  if (!m.allFinite()) {
    r.message = "rate table: the fitted gyroscope matrix is singular";
    return false;
  }
  FillGyro(m, b, cov, &r.gyro);
  for (size_t k = 0; k < k_count; ++k) {
    const Eigen::Vector3d e = mean[k] - a * segments[k].rate - b;
    r.normalized_residuals.push_back(
        std::sqrt((e.cwiseAbs2().cwiseQuotient(mean_var[k])).sum() / 3.0));
  }
  std::ostringstream s;
  s << "rate table: gyroscope bias and matrix from " << k_count << " segments";
  r.message = s.str();
  r.success = true;
  return true;
}

bool CalibrateRateTable(const Session& session, const RateTableMethodOptions&,
                        Calibration* calibration) {
  *calibration = Calibration();
  calibration->method = ToString(Method::kRateTable);
  RateTableResult result;
  const bool ok = CalibrateRateTable(session.log, session.segments, &result);
  calibration->message = result.message;
  if (!ok) return false;
  calibration->success = true;
  calibration->gyro = result.gyro;
  calibration->solver_name = "weighted linear least squares per gyroscope axis";
  internal::AddWarning(WarningCode::kMethodScope,
                       "rate_table calibrates the gyroscope only: the accelerometer model "
                       "written is the identity, not an estimate",
                       &calibration->warnings, &calibration->warning_codes);
  return true;
}

}  // namespace gravcal
