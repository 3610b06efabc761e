#include "gravcal/estimation/check_session.h"

#include <glog/logging.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
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
                        const ComparisonOptions& options, CheckSessionResult* result,
                        const Eigen::MatrixXd* extra_covariance) {
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
  if (extra_covariance != nullptr && extra_covariance->rows() == k &&
      extra_covariance->cols() == k) {
    s += *extra_covariance;
  }
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

bool CheckDesignOptions::IsValid(std::string* error) const {
  if (!(noise_density > 0.0) || !std::isfinite(noise_density)) {
    *error = "the accelerometer noise density must be positive (m/s^2/sqrt(Hz))";
    return false;
  }
  if (!(target_sigmas > 0.0) || !(max_hold_seconds > 0.0)) {
    *error = "the target (stored sigmas) and the longest hold must be positive";
    return false;
  }
  return comparison.IsValid(error);
}

namespace {

// MDC / stored sigma of every tested parameter at `hold` seconds.
bool MdcAtHold(const Calibration& stored, const CheckDesignOptions& options,
               const std::vector<Eigen::Vector3d>& directions, double hold,
               CheckSessionResult* result) {
  const AccelModel& model = stored.accel.model;
  const Eigen::Matrix3d minv = model.matrix().inverse();
  const double var = options.noise_density * options.noise_density / hold;
  std::vector<Position> poses;
  for (const Eigen::Vector3d& d : directions) {
    Position p;
    p.raw_mean = model.Invert(stored.gravity * d.normalized());
    p.raw_mean_cov = var * minv * minv.transpose();
    p.t_end = hold;
    poses.push_back(p);
  }
  return VerifyCheckSession(poses, stored, options.comparison, result);
}

}  // namespace

bool DesignCheckSession(const Calibration& stored, const CheckDesignOptions& options,
                        CheckDesign* design) {
  CHECK(design != nullptr);
  *design = CheckDesign();
  if (!options.IsValid(&design->message)) return false;
  std::vector<Eigen::Vector3d> directions = options.directions;
  if (directions.empty()) {
    const double c = 1.0 / std::sqrt(3.0);
    directions = {{c, c, c}, {c, -c, -c}, {-c, c, -c}, {-c, -c, c}};
  }
  // Worst MDC in stored sigmas at a hold (and the per-parameter values).
  auto worst = [&](double hold, CheckDesign* d) -> double {
    CheckSessionResult r;
    if (!MdcAtHold(stored, options, directions, hold, &r)) {
      d->message = r.comparison.message;
      return NAN;
    }
    d->names.clear();
    d->mdc_sigmas.clear();
    d->short_of_target.clear();
    double w = 0.0;
    for (const ParameterDifference& p : r.comparison.parameters) {
      d->names.push_back(p.name);
      d->mdc_sigmas.push_back(NAN);
    }
    // The reference sigmas are the stored ones (sqrt of C_p's diagonal).
    const std::vector<std::string>& names = stored.accel.covariance_names;
    for (size_t j = 0; j < d->names.size(); ++j) {
      for (size_t k = 0; k < names.size(); ++k) {
        if ("accel." + names[k] != d->names[j]) continue;
        const double sigma = std::sqrt(stored.accel.covariance(k, k));
        d->mdc_sigmas[j] = r.comparison.minimal_detectable_change[j] / sigma;
      }
      if (!(d->mdc_sigmas[j] <= options.target_sigmas)) d->short_of_target.push_back(d->names[j]);
      w = std::max(w, std::isfinite(d->mdc_sigmas[j]) ? d->mdc_sigmas[j] : INFINITY);
    }
    return w;
  };
  const double at_max = worst(options.max_hold_seconds, design);
  if (std::isnan(at_max)) return false;
  if (at_max > options.target_sigmas) {
    design->hold_seconds = options.max_hold_seconds;
    char buffer[256];
    std::snprintf(buffer, sizeof(buffer),
                  "no hold up to %.4g s detects %.3g stored sigmas in every parameter (the "
                  "stored calibration's own uncertainty, or poses that cannot tell terms apart)",
                  options.max_hold_seconds, options.target_sigmas);
    design->message = buffer;
    return true;
  }
  double lo = 0.0, hi = options.max_hold_seconds;
  while (hi - lo > 0.01 * hi) {
    const double mid = 0.5 * (lo + hi);
    CheckDesign probe;
    (worst(mid, &probe) <= options.target_sigmas ? hi : lo) = mid;
  }
  worst(hi, design);
  design->met = true;
  design->hold_seconds = hi;
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer),
                "%zu poses held %.3g s each detect a change of %.3g stored sigmas in any one "
                "parameter with power %.3g at level %.3g",
                directions.size(), hi, options.target_sigmas, options.comparison.power,
                options.comparison.level);
  design->message = buffer;
  return true;
}

}  // namespace gravcal
