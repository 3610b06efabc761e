#include "gravcal/estimation/calibration_comparison.h"

#include <glog/logging.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "core/enum_names.h"
#include "util/statistics.h"

namespace gravcal {

namespace {

constexpr const char* kAxes = "xyz";
// Eigenvalues of the correlation matrix of S below this times the largest
// span directions neither calibration determines.
constexpr double kRangeTolerance = 1e-10;
// |correlation| in S^+ above which two one-term changes cannot be told apart.
constexpr double kIndistinguishable = 0.9;

int AxisIndex(char c) {
  const char* p = std::strchr(kAxes, c);
  return c != '\0' && p != nullptr ? static_cast<int>(p - kAxes) : -1;
}

// The value of a model parameter `name` ("bias_x", "u_xy", "m_yz", "rot_z")
// of a sensor with bias b, matrix M = R U: false for a name it does not know.
bool ModelValue(const std::string& name, const Eigen::Vector3d& bias, const Eigen::Matrix3d& upper,
                const Eigen::Matrix3d& matrix, const Eigen::Matrix3d& rotation, double* value) {
  if (name.size() == 6 && name.rfind("bias_", 0) == 0 && AxisIndex(name[5]) >= 0) {
    *value = bias(AxisIndex(name[5]));
    return true;
  }
  if (name.size() == 4 && (name[0] == 'u' || name[0] == 'm') && name[1] == '_') {
    const int r = AxisIndex(name[2]), c = AxisIndex(name[3]);
    if (r < 0 || c < 0) return false;
    *value = name[0] == 'u' ? upper(r, c) : matrix(r, c);
    return true;
  }
  if (name.size() == 5 && name.rfind("rot_", 0) == 0 && AxisIndex(name[4]) >= 0) {
    const Eigen::AngleAxisd aa(rotation);
    *value = (aa.angle() * aa.axis())(AxisIndex(name[4]));
    return true;
  }
  return false;
}

// Whether the calibration gives `name` a standard deviation (null = not
// determined by its data).
bool ModelDetermined(const std::string& name, const Eigen::Vector3d& bias_std,
                     const Eigen::Matrix3d& matrix_std) {
  if (name.rfind("bias_", 0) == 0) return std::isfinite(bias_std(AxisIndex(name[5])));
  if (name[0] == 'u' || name[0] == 'm') {
    return std::isfinite(matrix_std(AxisIndex(name[2]), AxisIndex(name[3])));
  }
  return true;
}

// Appends the parameters of one sensor (prefix "accel." or "gyro.") that
// ModelValue knows.
void AppendSensor(const std::string& prefix, const std::vector<std::string>& names,
                  const Eigen::MatrixXd& covariance, const Eigen::Vector3d& bias,
                  const Eigen::Matrix3d& upper, const Eigen::Matrix3d& matrix,
                  const Eigen::Matrix3d& rotation, const Eigen::Vector3d& bias_std,
                  const Eigen::Matrix3d& matrix_std, ParameterVector* out) {
  std::vector<int> kept;
  std::vector<double> values;
  for (size_t i = 0; i < names.size(); ++i) {
    double v = 0.0;
    if (!ModelValue(names[i], bias, upper, matrix, rotation, &v)) {
      out->left_out.push_back(prefix + names[i]);
      continue;
    }
    kept.push_back(static_cast<int>(i));
    values.push_back(v);
  }
  const int n0 = static_cast<int>(out->names.size());
  const int n = n0 + static_cast<int>(kept.size());
  out->values.conservativeResize(n);
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(n, n);
  cov.topLeftCorner(n0, n0) = out->covariance;
  for (size_t i = 0; i < kept.size(); ++i) {
    out->names.push_back(prefix + names[kept[i]]);
    out->values(n0 + i) = values[i];
    out->determined.push_back(ModelDetermined(names[kept[i]], bias_std, matrix_std));
    for (size_t j = 0; j < kept.size(); ++j) cov(n0 + i, n0 + j) = covariance(kept[i], kept[j]);
  }
  out->covariance = cov;
}

// The nine intrinsic parameters (header) of v = S a + b, S = X^-1 with X
// the sensor matrix U or M (its rotation does not matter).
Eigen::Matrix<double, 9, 1> Intrinsic(const Eigen::Vector3d& bias, const Eigen::Matrix3d& x) {
  const Eigen::Matrix3d s = x.inverse();
  Eigen::Matrix<double, 9, 1> p;
  p.head<3>() = bias;
  for (int i = 0; i < 3; ++i) p(3 + i) = s.row(i).norm();
  const int pairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
  for (int k = 0; k < 3; ++k) {
    const int i = pairs[k][0], j = pairs[k][1];
    const double c = s.row(i).dot(s.row(j)) / (p(3 + i) * p(3 + j));
    // Angle between s_i and s_j less 90 degrees: asin of the cosine.
    p(6 + k) = std::asin(std::clamp(c, -1.0, 1.0));
  }
  return p;
}

const char* const kIntrinsicNames[9] = {
    "accel.bias_x",        "accel.bias_y",        "accel.bias_z",
    "accel.sensitivity_x", "accel.sensitivity_y", "accel.sensitivity_z",
    "accel.nonorth_xy",    "accel.nonorth_xz",    "accel.nonorth_yz"};

// The intrinsic parameters from the accelerometer's model parameters, with
// J C J^T: J by central differences over the model parameters.
bool IntrinsicParameters(const Calibration& c, const ParameterVector& model, ParameterVector* out,
                         std::string* error) {
  // The accelerometer's part of `model` and the sensor matrix it parameterises.
  std::vector<int> idx;
  bool uses_m = false;
  for (size_t i = 0; i < model.names.size(); ++i) {
    const std::string& n = model.names[i];
    if (n.rfind("accel.", 0) != 0 || n.rfind("accel.rot_", 0) == 0) continue;
    idx.push_back(static_cast<int>(i));
    uses_m = uses_m || n.rfind("accel.m_", 0) == 0;
  }
  const Eigen::Matrix3d base_x = uses_m ? c.accel.model.matrix() : c.accel.model.upper;
  if (std::fabs(base_x.determinant()) <= 0.0 || !base_x.allFinite()) {
    *error = "the accelerometer matrix is singular: no intrinsic parameters";
    return false;
  }
  auto evaluate = [&](const Eigen::VectorXd& values) {
    Eigen::Vector3d b = c.accel.model.bias;
    Eigen::Matrix3d x = base_x;
    for (size_t k = 0; k < idx.size(); ++k) {
      const std::string n = model.names[idx[k]].substr(6);
      if (n.rfind("bias_", 0) == 0) b(AxisIndex(n[5])) = values(k);
      if (n[0] == 'u' || n[0] == 'm') x(AxisIndex(n[2]), AxisIndex(n[3])) = values(k);
    }
    return Intrinsic(b, x);
  };
  Eigen::VectorXd v0(idx.size());
  for (size_t k = 0; k < idx.size(); ++k) v0(k) = model.values(idx[k]);
  Eigen::MatrixXd jac = Eigen::MatrixXd::Zero(9, idx.size());
  for (size_t k = 0; k < idx.size(); ++k) {
    const double step = 1e-6 * std::max(1.0, std::fabs(v0(k)));
    Eigen::VectorXd plus = v0, minus = v0;
    plus(k) += step;
    minus(k) -= step;
    jac.col(k) = (evaluate(plus) - evaluate(minus)) / (2.0 * step);
  }
  Eigen::MatrixXd cov(idx.size(), idx.size());
  for (size_t i = 0; i < idx.size(); ++i) {
    for (size_t j = 0; j < idx.size(); ++j) cov(i, j) = model.covariance(idx[i], idx[j]);
  }
  *out = ParameterVector();
  out->values = evaluate(v0);
  out->covariance = jac * cov * jac.transpose();
  for (int i = 0; i < 9; ++i) {
    out->names.push_back(kIntrinsicNames[i]);
    // Undetermined when it depends on a model parameter that is.
    bool determined = true;
    for (size_t k = 0; k < idx.size(); ++k) {
      if (!model.determined[idx[k]] && std::fabs(jac(i, k)) > 1e-9 * jac.row(i).norm()) {
        determined = false;
      }
    }
    out->determined.push_back(determined);
  }
  return true;
}

// S^+ on the range of s: scaled to a correlation matrix first, so that units
// do not decide what is dropped. Returns the rank.
int PseudoInverse(const Eigen::MatrixXd& s, Eigen::MatrixXd* s_plus) {
  const int n = static_cast<int>(s.rows());
  Eigen::VectorXd scale(n);
  for (int i = 0; i < n; ++i) scale(i) = s(i, i) > 0.0 ? 1.0 / std::sqrt(s(i, i)) : 0.0;
  const Eigen::MatrixXd r = scale.asDiagonal() * s * scale.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(0.5 * (r + r.transpose()));
  const double largest = n > 0 ? eig.eigenvalues().maxCoeff() : 0.0;
  Eigen::VectorXd inv = Eigen::VectorXd::Zero(n);
  int rank = 0;
  for (int i = 0; i < n; ++i) {
    if (largest > 0.0 && eig.eigenvalues()(i) > kRangeTolerance * largest) {
      inv(i) = 1.0 / eig.eigenvalues()(i);
      ++rank;
    }
  }
  *s_plus = scale.asDiagonal() * eig.eigenvectors() * inv.asDiagonal() *
            eig.eigenvectors().transpose() * scale.asDiagonal();
  return rank;
}

// P(|N(0, 1)| > t).
double TwoSidedNormalTail(double t) { return std::erfc(std::fabs(t) / std::sqrt(2.0)); }

}  // namespace

namespace {
const internal::EnumName<ComparisonSpace> kComparisonSpaces[] = {
    {ComparisonSpace::kModel, "model"}, {ComparisonSpace::kIntrinsic, "intrinsic"}};
}  // namespace

GRAVCAL_ENUM_STRINGS(ComparisonSpace, kComparisonSpaces)

bool ComparisonOptions::IsValid(std::string* error) const {
  if (!(level > 0.0 && level < 1.0)) {
    *error = "level must lie in (0, 1)";
    return false;
  }
  if (!(power > 0.0 && power < 1.0)) {
    *error = "power must lie in (0, 1)";
    return false;
  }
  return true;
}

bool CalibrationParameters(const Calibration& c, ComparisonSpace space, ParameterVector* parameters,
                           std::string* error) {
  *parameters = ParameterVector();
  const AccelCalibration& a = c.accel;
  if (a.covariance.size() == 0 || a.covariance_names.empty() ||
      a.covariance.rows() != static_cast<int>(a.covariance_names.size()) ||
      a.covariance.cols() != a.covariance.rows()) {
    *error =
        "the calibration has no accelerometer covariance (calibrate with output_covariance: "
        "true)";
    parameters->note = *error;
    return false;
  }
  ParameterVector model;
  AppendSensor("accel.", a.covariance_names, a.covariance, a.model.bias, a.model.upper,
               a.model.matrix(), a.model.rotation, a.bias_std, a.matrix_std, &model);
  if (space == ComparisonSpace::kIntrinsic) return IntrinsicParameters(c, model, parameters, error);
  const GyroCalibration& g = c.gyro;
  if (g.estimated && g.covariance.size() > 0 &&
      g.covariance.rows() == static_cast<int>(g.covariance_names.size())) {
    AppendSensor("gyro.", g.covariance_names, g.covariance, g.model.bias, g.model.matrix,
                 g.model.matrix, Eigen::Matrix3d::Identity(), g.bias_std, g.matrix_std, &model);
  }
  *parameters = model;
  return true;
}

bool TestShifts(const ShiftTestInput& in, const ComparisonOptions& options,
                ComparisonResult* result) {
  const int n = static_cast<int>(in.y.size());
  const int m = static_cast<int>(in.names.size());
  if (in.s.rows() != n || in.s.cols() != n || in.h.rows() != n || in.h.cols() != m ||
      in.reference_std.size() != m) {
    result->message = "shift test: sizes disagree";
    return false;
  }
  result->level = options.level;
  result->power = options.power;
  Eigen::MatrixXd s_plus;
  result->dof = PseudoInverse(in.s, &s_plus);
  result->chi2 = in.y.dot(s_plus * in.y);
  result->chi2_p_value =
      result->dof > 0 ? internal::ChiSquareUpperTail(result->chi2, result->dof) : 1.0;
  // One-term statistics.
  const Eigen::VectorXd score = in.h.transpose() * s_plus * in.y;
  const Eigen::MatrixXd info = in.h.transpose() * s_plus * in.h;
  int tested_terms = 0;
  int best = -1;
  double best_t = 0.0;
  result->parameters.clear();
  for (int j = 0; j < m; ++j) {
    ParameterDifference p;
    p.name = in.names[j];
    const double fisher = info(j, j);
    if (fisher > 0.0 && std::isfinite(fisher)) {
      ++tested_terms;
      p.difference = score(j) / fisher;
      p.std = 1.0 / std::sqrt(fisher);
      p.shift_z = score(j) / std::sqrt(fisher);
      p.z = p.shift_z;
      if (std::fabs(p.shift_z) > best_t) {
        best_t = std::fabs(p.shift_z);
        best = j;
      }
    } else {
      p.difference = p.std = p.z = NAN;
    }
    result->parameters.push_back(p);
  }
  result->max_shift_p_value =
      tested_terms > 0 ? std::min(1.0, tested_terms * TwoSidedNormalTail(best_t)) : 1.0;
  result->p_value = std::min(1.0, 2.0 * std::min(result->chi2_p_value, result->max_shift_p_value));
  result->tested = result->dof > 0;
  result->consistent = !result->tested || result->p_value >= options.level;
  // The smallest one-term change the max-|t| half of the test (level / 2,
  // m terms) finds with the stated power: |t| > c with t ~ N(mu, 1).
  const double c =
      internal::NormalQuantile(1.0 - options.level / (4.0 * std::max(1, tested_terms)));
  const double mu = c + internal::NormalQuantile(options.power);
  result->minimal_detectable_change.assign(m, NAN);
  for (int j = 0; j < m; ++j) {
    if (info(j, j) > 0.0) result->minimal_detectable_change[j] = mu / std::sqrt(info(j, j));
  }
  result->changed.clear();
  result->indistinguishable.clear();
  result->changed_size = result->changed_sigmas = NAN;
  if (!result->consistent && best >= 0) {
    result->changed = in.names[best];
    result->changed_size = result->parameters[best].difference;
    result->changed_sigmas = result->changed_size / in.reference_std(best);
    for (int k = 0; k < m; ++k) {
      if (k == best || !(info(k, k) > 0.0)) continue;
      const double corr = info(best, k) / std::sqrt(info(best, best) * info(k, k));
      if (std::fabs(corr) > kIndistinguishable) result->indistinguishable.push_back(in.names[k]);
    }
  }
  return true;
}

bool CompareParameters(const ParameterVector& a, const ParameterVector& b,
                       const ComparisonOptions& options, ComparisonResult* result) {
  CHECK(result != nullptr);
  *result = ComparisonResult();
  if (!options.IsValid(&result->message)) return false;
  result->level = options.level;
  result->power = options.power;
  if (a.covariance.size() == 0 || b.covariance.size() == 0) {
    result->message = std::string("not tested: ") +
                      (a.covariance.size() == 0 ? "the first" : "the second") +
                      " calibration has no covariance" +
                      (a.covariance.size() == 0 ? (a.note.empty() ? "" : " (" + a.note + ")")
                                                : (b.note.empty() ? "" : " (" + b.note + ")"));
    return true;
  }
  std::vector<std::pair<int, int>> pairs;
  std::vector<std::string> names;
  for (size_t i = 0; i < a.names.size(); ++i) {
    const auto it = std::find(b.names.begin(), b.names.end(), a.names[i]);
    if (it == b.names.end()) {
      result->not_compared.push_back(a.names[i]);
      continue;
    }
    const int j = static_cast<int>(it - b.names.begin());
    const double var = a.covariance(i, i) + b.covariance(j, j);
    if (!a.determined[i] || !b.determined[j] || !std::isfinite(var)) {
      result->undetermined.push_back(a.names[i]);
      continue;
    }
    if (!(var > 0.0)) {
      result->not_compared.push_back(a.names[i]);
      continue;
    }
    pairs.emplace_back(static_cast<int>(i), j);
    names.push_back(a.names[i]);
  }
  for (const std::string& n : b.names) {
    if (std::find(a.names.begin(), a.names.end(), n) == a.names.end()) {
      result->not_compared.push_back(n);
    }
  }
  for (const ParameterVector* p : {&a, &b}) {
    for (const std::string& n : p->left_out) {
      if (std::find(result->not_compared.begin(), result->not_compared.end(), n) ==
          result->not_compared.end()) {
        result->not_compared.push_back(n);
      }
    }
  }
  const int m = static_cast<int>(pairs.size());
  ShiftTestInput in;
  in.names = names;
  in.y.resize(m);
  in.s.resize(m, m);
  for (int r = 0; r < m; ++r) {
    in.y(r) = b.values(pairs[r].second) - a.values(pairs[r].first);
    for (int k = 0; k < m; ++k) {
      in.s(r, k) = a.covariance(pairs[r].first, pairs[k].first) +
                   b.covariance(pairs[r].second, pairs[k].second);
    }
  }
  in.h = Eigen::MatrixXd::Identity(m, m);
  in.reference_std = in.s.diagonal().cwiseSqrt();
  if (!TestShifts(in, options, result)) return false;
  for (int r = 0; r < m; ++r) {
    ParameterDifference& p = result->parameters[r];
    p.difference = in.y(r);
    p.std = in.reference_std(r);
    p.z = p.difference / p.std;
  }
  result->message =
      m == 0 ? "not tested: no parameter both calibrations determine" : ComparisonSummary(*result);
  // A verdict on part of the calibrations says which part: matrix terms
  // left out mean different models (u_* against m_*), which only the
  // mount-invariant intrinsic parameters compare.
  if (m > 0 && !result->not_compared.empty()) {
    bool matrix = false;
    for (const std::string& n : result->not_compared) {
      matrix = matrix || n.find(".u_") != std::string::npos || n.find(".m_") != std::string::npos;
    }
    result->message += "; " + std::to_string(result->not_compared.size()) +
                       " parameters of one calibration only not compared" +
                       (matrix ? " (the calibrations model the matrix differently: compare them "
                                 "in intrinsic parameters)"
                               : "");
  }
  return true;
}

std::string ComparisonSummary(const ComparisonResult& r) {
  char buffer[512];
  if (!r.tested) return "not tested: nothing to compare";
  if (r.consistent) {
    std::snprintf(buffer, sizeof(buffer),
                  "consistent at level %g (p = %.3g; chi2 = %.3g on %d dof, largest one-term "
                  "|t| p = %.3g)",
                  r.level, r.p_value, r.chi2, r.dof, r.max_shift_p_value);
    return buffer;
  }
  std::snprintf(buffer, sizeof(buffer),
                "changed at level %g (p = %.3g; chi2 = %.3g on %d dof): %s moved by %.6g (%.1f "
                "sigma)",
                r.level, r.p_value, r.chi2, r.dof, r.changed.c_str(), r.changed_size,
                r.changed_sigmas);
  std::string text = buffer;
  if (!r.indistinguishable.empty()) {
    text += ", or ";
    for (size_t i = 0; i < r.indistinguishable.size(); ++i) {
      text += (i ? ", " : "") + r.indistinguishable[i];
    }
    text += " (this data cannot tell them apart)";
  }
  return text;
}

}  // namespace gravcal
