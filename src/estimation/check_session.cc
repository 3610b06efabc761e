#include "gravcal/estimation/check_session.h"

#include <glog/logging.h>

#include <Eigen/Dense>
#include <cmath>
#include <string>

namespace gravcal {

namespace {

// The accelerometer model with parameter `name` (bias_x, u_xy, m_yz) moved
// by `delta`; false for a name the magnitude does not depend on (rot_*) or
// does not know.
bool Perturbed(const AccelModel& model, const std::string& name, double delta, Eigen::Vector3d* b,
               Eigen::Matrix3d* m) {
  static const std::string kAxes = "xyz";
  *b = model.bias;
  Eigen::Matrix3d upper = model.upper;
  *m = model.matrix();
  if (name.size() == 6 && name.rfind("bias_", 0) == 0 && kAxes.find(name[5]) != std::string::npos) {
    (*b)(kAxes.find(name[5])) += delta;
    return true;
  }
  if (name.size() != 4 || name[1] != '_') return false;
  const size_t r = kAxes.find(name[2]), c = kAxes.find(name[3]);
  if (r == std::string::npos || c == std::string::npos) return false;
  if (name[0] == 'u') {
    upper(r, c) += delta;
    *m = model.rotation * upper;
    return true;
  }
  if (name[0] == 'm') {
    (*m)(r, c) += delta;
    return true;
  }
  return false;
}

Eigen::VectorXd Residuals(const std::vector<Position>& positions, const Eigen::Vector3d& b,
                          const Eigen::Matrix3d& m, double gravity) {
  Eigen::VectorXd r(positions.size());
  for (size_t k = 0; k < positions.size(); ++k) {
    r(k) = (m * (positions[k].raw_mean - b)).norm() - gravity;
  }
  return r;
}

}  // namespace

bool VerifyCheckSession(const std::vector<Position>& positions, const Calibration& stored,
                        const ComparisonOptions& options, CheckSessionResult* result) {
  CHECK(result != nullptr);
  *result = CheckSessionResult();
  ComparisonResult& out = result->comparison;
  if (!options.IsValid(&out.message)) return false;
  if (positions.empty()) {
    out.message = "the check session has no static pose";
    return false;
  }
  const AccelCalibration& a = stored.accel;
  const int np = static_cast<int>(a.covariance_names.size());
  if (np == 0 || a.covariance.rows() != np || a.covariance.cols() != np) {
    out.message = "the stored calibration has no accelerometer covariance: it cannot be verified";
    return false;
  }
  const AccelModel& model = a.model;
  const Eigen::Matrix3d m = model.matrix();
  const double g = stored.gravity;
  const int k = static_cast<int>(positions.size());
  const Eigen::VectorXd r = Residuals(positions, model.bias, m, g);
  // Columns of H for every stored parameter the magnitude depends on.
  std::vector<int> columns;
  std::vector<std::string> names;
  Eigen::MatrixXd h(k, 0);
  for (int j = 0; j < np; ++j) {
    const std::string& name = a.covariance_names[j];
    const double step = 1e-6 * std::max(1.0, std::sqrt(std::max(0.0, a.covariance(j, j))) * 1e3);
    Eigen::Vector3d bp, bm;
    Eigen::Matrix3d mp, mm;
    if (!Perturbed(model, name, step, &bp, &mp) || !Perturbed(model, name, -step, &bm, &mm)) {
      continue;
    }
    const Eigen::VectorXd col =
        (Residuals(positions, bp, mp, g) - Residuals(positions, bm, mm, g)) / (2.0 * step);
    columns.push_back(j);
    names.push_back("accel." + name);
    h.conservativeResize(k, h.cols() + 1);
    h.col(h.cols() - 1) = col;
  }
  const int nc = static_cast<int>(columns.size());
  Eigen::MatrixXd cp(nc, nc);
  for (int i = 0; i < nc; ++i) {
    for (int j = 0; j < nc; ++j) cp(i, j) = a.covariance(columns[i], columns[j]);
  }
  Eigen::MatrixXd s = h * cp * h.transpose();
  for (int i = 0; i < k; ++i) {
    const Eigen::Vector3d f = m * (positions[i].raw_mean - model.bias);
    const Eigen::Vector3d u = f.normalized();
    const double noise = u.dot(m * positions[i].raw_mean_cov * m.transpose() * u);
    s(i, i) += noise;
    CheckPose pose;
    pose.residual = r(i);
    pose.noise_sigma = std::sqrt(std::max(0.0, noise));
    pose.t_begin = positions[i].t_begin;
    pose.t_end = positions[i].t_end;
    result->poses.push_back(pose);
  }
  for (int i = 0; i < k; ++i) result->poses[i].sigma = std::sqrt(std::max(0.0, s(i, i)));
  // Only parameters the stored calibration determines are tested.
  ShiftTestInput in;
  in.y = r;
  in.s = s;
  std::vector<int> tested;
  for (int i = 0; i < nc; ++i) {
    const std::string& name = a.covariance_names[columns[i]];
    const bool is_bias = name.rfind("bias_", 0) == 0;
    const double sd =
        is_bias ? a.bias_std(std::string("xyz").find(name[5]))
                : a.matrix_std(std::string("xyz").find(name[2]), std::string("xyz").find(name[3]));
    if (!std::isfinite(sd) || !(cp(i, i) > 0.0)) {
      out.undetermined.push_back(names[i]);
      continue;
    }
    tested.push_back(i);
  }
  in.h.resize(k, tested.size());
  in.reference_std.resize(tested.size());
  for (size_t t = 0; t < tested.size(); ++t) {
    in.names.push_back(names[tested[t]]);
    in.h.col(t) = h.col(tested[t]);
    in.reference_std(t) = std::sqrt(cp(tested[t], tested[t]));
  }
  if (!TestShifts(in, options, &out)) return false;
  out.message = "check of " + std::to_string(k) + " pose" + (k == 1 ? "" : "s") + ": " +
                ComparisonSummary(out);
  return true;
}

}  // namespace gravcal
