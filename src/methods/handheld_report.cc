#include "methods/handheld_report.h"

#include <cmath>

#include "core/warnings.h"

namespace gravcal {
namespace internal {
namespace {

constexpr const char* kAxisLetters = "xyz";

// The motion that excites a sensor error, for the warning.
std::string MissingMotion(const std::string& name) {
  const bool accel = name.rfind("accel", 0) == 0;
  const char axis = name.back();
  std::string others;
  for (int i = 0; i < 3; ++i) {
    if (kAxisLetters[i] != axis)
      others +=
          others.empty() ? std::string(1, kAxisLetters[i]) : std::string(" or ") + kAxisLetters[i];
  }
  std::ostringstream s;
  if (name.rfind("lever_arm", 0) == 0) {
    s << "turns about the axes other than " << axis;
  } else if (name.find("_cross_") != std::string::npos) {
    s << "rotations about all three axes while each is horizontal";
  } else if (accel) {
    s << "the " << axis << " axis pointing up and down: turn the unit about its " << others
      << " axis while that axis is horizontal";
  } else if (name.find("_scale_") != std::string::npos) {
    s << "turns about the " << axis << " axis while it is horizontal: turn the unit about its "
      << axis << " axis while that axis is horizontal (turns about the vertical do not count)";
  } else {
    s << "the " << axis << " axis horizontal for a while (turn the unit about its " << others
      << " axis while that axis is horizontal)";
  }
  return s.str();
}

}  // namespace

std::vector<std::string> ReportConvergence(const HandheldFilter& filter,
                                           const ErrorStateLayout& layout,
                                           const HandheldKalmanOptions& options, Calibration* c) {
  const Eigen::MatrixXd& p = filter.covariance();
  const Eigen::MatrixXd& p0 = filter.initial_covariance();
  const int n = layout.size();
  std::ostringstream criterion;
  criterion << "on the first (causal) filter pass: converged at the first epoch from which on "
               "both the distance of the estimate from its final value and its standard "
               "deviation stay below "
            << options.convergence_fraction
            << " times the prior standard deviation; a state whose final standard deviation is "
               "above that is not determined";
  c->convergence.criterion = criterion.str();
  const EstimateHistory& history = c->history;
  const int first_sensor = layout.offset(StateBlock::kAccelBias);
  const size_t rows = history.rows();
  const size_t cols = history.columns.size();
  std::vector<std::string> unexcited;
  for (int j = first_sensor; j < n; ++j) {
    ConvergenceEntry e;
    e.name = layout.names()[j];
    const bool bias = e.name.find("_bias_") != std::string::npos;
    const bool accel = e.name.rfind("accel", 0) == 0;
    const bool lever = e.name.rfind("lever_arm", 0) == 0;
    e.unit = lever ? "m" : bias ? (accel ? "m/s^2" : "rad/s") : "fraction";
    e.value = filter.SensorValue(j);
    e.sigma_initial = std::sqrt(p0(j, j));
    e.sigma_final = std::sqrt(std::max(p(j, j), 0.0));
    const bool excited = e.sigma_final <= options.convergence_fraction * e.sigma_initial;
    if (excited) {
      const size_t col = 1 + 2 * static_cast<size_t>(j - first_sensor);
      // On the first (causal) pass, against its own final value.
      const double* last = &history.values[(rows - 1) * cols];
      const double tolerance = options.convergence_fraction * e.sigma_initial;
      size_t first_good = rows;
      while (first_good > 0) {
        const double* row = &history.values[(first_good - 1) * cols];
        const bool inside =
            std::fabs(row[col] - last[col]) <= tolerance && row[col + 1] <= tolerance;
        if (!inside) break;
        --first_good;
      }
      e.converged = first_good < rows;
      if (e.converged) e.time = history.values[first_good * cols];
    } else {
      unexcited.push_back(e.name);
      std::ostringstream s;
      s << e.name << " not determined: its standard deviation only went from "
        << FormatShort(e.sigma_initial) << " to " << FormatShort(e.sigma_final) << " " << e.unit
        << " (the reported value is mostly the prior); the recording lacks "
        << MissingMotion(e.name);
      AddWarning(WarningCode::kUndetermined, s.str(), &c->warnings, &c->warning_codes);
    }
    c->convergence.entries.push_back(e);
  }
  return unexcited;
}

SensorResult ToCalibrationModel(const HandheldSensorEstimate& est, double scale, int bias_offset,
                                int matrix_offset, const SensorErrorTerms& terms,
                                const Eigen::MatrixXd& p) {
  SensorResult out;
  out.bias = est.bias / scale;
  out.matrix = scale * est.inverse;
  const int ne = static_cast<int>(terms.matrix_entries.size());
  // Which entries of M move: all those reached by some estimated entry.
  bool moves[3][3] = {};
  for (const auto& [r, col] : terms.matrix_entries) {
    for (int i = 0; i < 3; ++i) {
      for (int k = 0; k < 3; ++k) {
        if (out.matrix(i, r) != 0.0 && out.matrix(col, k) != 0.0) moves[i][k] = true;
      }
    }
  }
  std::vector<std::pair<int, int>> outputs;
  out.names.clear();
  for (int i = 0; i < 3; ++i) out.names.push_back(std::string("bias_") + kAxisLetters[i]);
  for (int i = 0; i < 3; ++i) {
    for (int k = 0; k < 3; ++k) {
      if (moves[i][k]) {
        outputs.emplace_back(i, k);
        out.names.push_back(std::string("m_") + kAxisLetters[i] + kAxisLetters[k]);
      }
    }
  }
  const int no = 3 + static_cast<int>(outputs.size());
  Eigen::MatrixXd jac = Eigen::MatrixXd::Zero(no, 3 + ne);
  jac.topLeftCorner<3, 3>() = Eigen::Matrix3d::Identity() / scale;
  for (size_t o = 0; o < outputs.size(); ++o) {
    const auto [i, k] = outputs[o];
    for (int e = 0; e < ne; ++e) {
      const auto [r, col] = terms.matrix_entries[e];
      jac(3 + static_cast<int>(o), 3 + e) = -out.matrix(i, r) * out.matrix(col, k) / scale;
    }
  }
  Eigen::MatrixXd source(3 + ne, 3 + ne);
  std::vector<int> index;
  for (int i = 0; i < 3; ++i) index.push_back(bias_offset + i);
  for (int e = 0; e < ne; ++e) index.push_back(matrix_offset + e);
  for (int a = 0; a < 3 + ne; ++a) {
    for (int b = 0; b < 3 + ne; ++b) source(a, b) = p(index[a], index[b]);
  }
  out.covariance = jac * source * jac.transpose();
  for (int i = 0; i < 3; ++i) out.bias_std(i) = std::sqrt(out.covariance(i, i));
  out.matrix_std.setConstant(NAN);
  for (size_t o = 0; o < outputs.size(); ++o) {
    out.matrix_std(outputs[o].first, outputs[o].second) =
        std::sqrt(out.covariance(3 + static_cast<int>(o), 3 + static_cast<int>(o)));
  }
  return out;
}

}  // namespace internal
}  // namespace gravcal
