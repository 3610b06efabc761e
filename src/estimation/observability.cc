#include "gravcal/estimation/observability.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>

namespace gravcal {

namespace {

// Eigenvalues, ascending, of S^T S with S = J diag(1 / scale) (empty on
// failure). Gram is a fixed-size matrix type where it can be: that makes the
// solve several times cheaper.
template <typename Gram>
Eigen::VectorXd GramEigenvalues(const Eigen::MatrixXd& jacobian, const Eigen::VectorXd& scale) {
  const Eigen::Index cols = jacobian.cols();
  Gram gram(cols, cols);
  gram.template triangularView<Eigen::Lower>() = jacobian.transpose().lazyProduct(jacobian);
  for (Eigen::Index j = 0; j < cols; ++j) {
    for (Eigen::Index i = j; i < cols; ++i) gram(i, j) /= scale(i) * scale(j);
  }
  const Eigen::SelfAdjointEigenSolver<Gram> eigen(gram, Eigen::EigenvaluesOnly);
  if (eigen.info() != Eigen::Success) return Eigen::VectorXd();
  return eigen.eigenvalues();
}

}  // namespace

ObservabilityReport AnalyzeObservability(const Eigen::MatrixXd& jacobian,
                                         const std::vector<std::string>& names,
                                         double relative_tolerance) {
  ObservabilityReport report;
  const int cols = static_cast<int>(jacobian.cols());
  report.columns = cols;
  if (cols == 0) return report;
  Eigen::VectorXd scale = jacobian.colwise().norm().transpose();
  for (int j = 0; j < cols; ++j) {
    if (!(scale(j) > 0.0)) scale(j) = 1.0;
  }
  report.rank = 0;
  // Fast path, for speed only (the Jacobi SVD below is most of the cost of a
  // 12-position refinement). When the Gram matrix S^T S of the scaled
  // Jacobian shows it comfortably full rank, the singular values are taken
  // as the square roots of its eigenvalues. Rounding in S^T S costs them
  // about rows * eps * (s_max / s_i)^2 relative accuracy at worst (measured
  // against the SVD: 1e-13 typical, 3e-10 worst, 9 to 1000 rows); it is only
  // taken when every s_i / s_max exceeds 1e-4, four orders of magnitude above
  // the default rank tolerance, so the rank is certainly `cols` and there is
  // no null space to report. Anything closer to rank deficiency (or a
  // tolerance above 1e-6) takes the SVD, exactly as before.
  if (cols <= 12 && jacobian.rows() >= cols) {
    Eigen::VectorXd lambda;  // Ascending.
    if (cols == 9) {
      lambda = GramEigenvalues<Eigen::Matrix<double, 9, 9>>(jacobian, scale);
    } else if (cols == 6) {
      lambda = GramEigenvalues<Eigen::Matrix<double, 6, 6>>(jacobian, scale);
    } else {
      lambda = GramEigenvalues<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 12, 12>>(
          jacobian, scale);
    }
    const double ratio = std::max(1e-4, 100.0 * relative_tolerance);
    if (lambda.size() == cols && std::isfinite(lambda(cols - 1)) &&
        lambda(0) > ratio * ratio * lambda(cols - 1)) {
      report.singular_values = lambda.reverse().cwiseSqrt();
      report.rank = cols;
      report.null_space.resize(cols, 0);
      return report;
    }
  }
  const Eigen::MatrixXd scaled = jacobian * scale.cwiseInverse().asDiagonal();
  // Pad with zero rows so the SVD has at least `cols` singular values.
  Eigen::MatrixXd padded = Eigen::MatrixXd::Zero(std::max<Eigen::Index>(scaled.rows(), cols), cols);
  padded.topRows(scaled.rows()) = scaled;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(padded, Eigen::ComputeFullV);
  report.singular_values = svd.singularValues();
  const double top = report.singular_values(0);
  for (int i = 0; i < cols; ++i) {
    if (report.singular_values(i) > relative_tolerance * top) ++report.rank;
  }
  const int nullity = cols - report.rank;
  report.null_space.resize(cols, nullity);
  std::vector<bool> involved(cols, false);
  for (int n = 0; n < nullity; ++n) {
    // Back to parameter units, then normalise.
    Eigen::VectorXd v = scale.cwiseInverse().asDiagonal() * svd.matrixV().col(report.rank + n);
    v.normalize();
    report.null_space.col(n) = v;
    const Eigen::VectorXd vs = svd.matrixV().col(report.rank + n);
    std::string text;
    for (int j = 0; j < cols; ++j) {
      if (std::fabs(vs(j)) < 0.1) continue;
      involved[j] = true;
      char term[96];
      std::snprintf(term, sizeof(term), "%s%.2f %s", text.empty() ? "" : " + ", vs(j),
                    j < static_cast<int>(names.size()) ? names[j].c_str() : "?");
      text += term;
    }
    report.descriptions.push_back(text);
  }
  for (int j = 0; j < cols; ++j) {
    if (involved[j])
      report.undetermined.push_back(j < static_cast<int>(names.size()) ? names[j] : "?");
  }
  return report;
}

Eigen::MatrixXd FullMagnitudeJacobian(const std::vector<Position>& positions,
                                      const Eigen::Vector3d& bias, const Eigen::Matrix3d& matrix,
                                      const std::vector<double>& sigmas) {
  Eigen::MatrixXd j(positions.size(), 12);
  for (size_t k = 0; k < positions.size(); ++k) {
    const Eigen::Vector3d d = positions[k].raw_mean - bias;
    const Eigen::Vector3d a = matrix * d;
    const Eigen::Vector3d u = a / a.norm();
    const double w = 1.0 / sigmas[k];
    j.block<1, 3>(k, 0) = -w * (u.transpose() * matrix);
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) j(k, 3 + 3 * r + c) = w * u(r) * d(c);
    }
  }
  return j;
}

std::vector<std::string> FullMagnitudeParameterNames() {
  return {"bias_x", "bias_y", "bias_z", "m_xx", "m_xy", "m_xz",
          "m_yx",   "m_yy",   "m_yz",   "m_zx", "m_zy", "m_zz"};
}

}  // namespace gravcal
