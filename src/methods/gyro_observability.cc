#include "methods/gyro_observability.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "gravcal/estimation/observability.h"

namespace gravcal {
namespace internal {

std::vector<std::string> UndeterminedGyroParameters(const Eigen::MatrixXd& jacobian,
                                                    const GyroFreeColumns& free,
                                                    const GyroCalibrationOptions& options) {
  const ObservabilityReport report = AnalyzeObservability(jacobian, free.names);
  std::vector<std::string> out = report.undetermined;
  if (report.full_rank()) {
    const Eigen::VectorXd norms = jacobian.colwise().norm();
    const Eigen::VectorXd inv = norms.cwiseInverse();
    const Eigen::MatrixXd scaled = jacobian * inv.asDiagonal();
    const Eigen::MatrixXd information = scaled.transpose() * scaled;
    const Eigen::MatrixXd cov = inv.asDiagonal() *
                                information.ldlt().solve(Eigen::MatrixXd::Identity(
                                    information.rows(), information.cols())) *
                                inv.asDiagonal();
    for (size_t j = 0; j < free.names.size(); ++j) {
      const std::string& name = free.names[j];
      const double std = std::sqrt(std::max(cov(j, j), 0.0));
      const bool matrix = name == "scale" || name.rfind("m_", 0) == 0;
      const bool g = name.rfind("g_", 0) == 0;
      if ((matrix && !(std <= options.max_matrix_std)) ||
          (g && !(std <= options.max_g_sensitivity_std))) {
        if (std::find(out.begin(), out.end(), name) == out.end()) out.push_back(name);
      }
    }
  }
  return out;
}

// Warnings for undetermined gyroscope parameters, grouped by what is missing.
void WarnUndeterminedGyro(const std::vector<std::string>& names,
                          std::vector<std::string>* warnings) {
  for (int c = 0; c < 3; ++c) {
    std::vector<std::string> column;
    for (const std::string& n : names) {
      if (n.size() == 4 && n.rfind("m_", 0) == 0 && n[3] == kGyroAxisNames[c]) column.push_back(n);
    }
    if (column.empty()) continue;
    const std::string axis(1, kGyroAxisNames[c]);
    std::string listed;
    for (const std::string& n : column) listed += (listed.empty() ? "" : ", ") + n;
    const bool scale = std::find(column.begin(), column.end(), "m_" + axis + axis) != column.end();
    warnings->push_back("no rotation about the body " + axis +
                        " axis (away from the vertical) between the static poses: gyro " +
                        (scale ? "scale " + axis + " and " : std::string()) + "matrix entries " +
                        listed +
                        " not determined; they are held at the initial estimate and reported "
                        "without a standard deviation: turn the unit about its " +
                        axis + " axis while that axis is horizontal");
  }
  std::string g;
  for (const std::string& n : names) {
    if (n.rfind("g_", 0) == 0) g += (g.empty() ? "" : ", ") + n;
  }
  if (!g.empty()) {
    warnings->push_back(
        "the gravity directions of the static poses do not span three dimensions: gyro "
        "g-sensitivity " +
        g +
        " not determined (held at 0, reported without a standard deviation): add poses with "
        "other axes up");
  }
}

}  // namespace internal
}  // namespace gravcal
