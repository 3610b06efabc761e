#include "gravcal/observability.h"

#include <Eigen/SVD>
#include <cmath>
#include <cstdio>

namespace gravcal {

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
  const Eigen::MatrixXd scaled = jacobian * scale.cwiseInverse().asDiagonal();
  // Pad with zero rows so the SVD has at least `cols` singular values.
  Eigen::MatrixXd padded = Eigen::MatrixXd::Zero(std::max<Eigen::Index>(scaled.rows(), cols), cols);
  padded.topRows(scaled.rows()) = scaled;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(padded, Eigen::ComputeFullV);
  report.singular_values = svd.singularValues();
  const double top = report.singular_values(0);
  report.rank = 0;
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
