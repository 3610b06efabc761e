// The thermal fit at fixed orders (thermal_fitter.h).
#include "methods/thermal_fitter.h"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "estimation/solver_settings.h"

namespace gravcal {
namespace internal {
namespace {

// The accelerometer scale the fit starts from: nominal_scale, unless the
// window means read with it are not near gravity (median |a| outside
// [0.5 g, 1.5 g]: raw counts with nominal_scale 1, or SI data given a
// counts sensitivity). Then the data's own scale g / median |a_raw| is used
// and `note` says so (an offset-free start; the fit estimates the rest).
double StartAccelScale(const std::vector<ThermalWindow>& windows,
                       const ThermalCalibrationOptions& o, std::string* note) {
  std::vector<double> norms;
  for (const ThermalWindow& w : windows) norms.push_back(w.accel_mean.norm());
  if (norms.empty()) return o.accel_nominal_scale;
  std::nth_element(norms.begin(), norms.begin() + norms.size() / 2, norms.end());
  const double median = norms[norms.size() / 2];
  const double read = median * o.accel_nominal_scale;
  if (!(median > 0.0) || (read > 0.5 * o.gravity && read < 1.5 * o.gravity)) {
    return o.accel_nominal_scale;
  }
  const double scale = o.gravity / median;
  std::ostringstream s;
  s.precision(4);
  s << "nominal_scale " << o.accel_nominal_scale << " reads the static poses as " << read
    << " m/s^2, not gravity: the fit starts from the data's own scale " << scale
    << " (set nominal_scale to m/s^2 per raw unit)";
  *note = s.str();
  return scale;
}

}  // namespace

ThermalFitter::ThermalFitter(const std::vector<ThermalWindow>& windows,
                             const ThermalElementSeries& element,
                             const ThermalCalibrationOptions& o, bool has_gyro,
                             double reference_temperature, double span)
    : windows_(windows),
      element_(element),
      o_(o),
      has_gyro_(has_gyro),
      reference_(reference_temperature),
      half_span_(std::max(1.0, 0.5 * span)) {
  start_accel_scale_ = StartAccelScale(windows, o, &scale_note_);
  // The spread of the window means per axis, the data-based floor of the
  // bias terms' prior ranges: for the accelerometer within each static
  // interval (between poses gravity moves, not the temperature), for the
  // gyroscope over all windows.
  Eigen::Vector3d glo = Eigen::Vector3d::Constant(INFINITY), ghi = -glo;
  std::map<int, std::pair<Eigen::Vector3d, Eigen::Vector3d>> per_interval;
  for (const ThermalWindow& w : windows) {
    auto it = per_interval.find(w.interval);
    if (it == per_interval.end()) {
      per_interval[w.interval] = {w.accel_mean, w.accel_mean};
    } else {
      it->second.first = it->second.first.cwiseMin(w.accel_mean);
      it->second.second = it->second.second.cwiseMax(w.accel_mean);
    }
    glo = glo.cwiseMin(w.gyro_mean);
    ghi = ghi.cwiseMax(w.gyro_mean);
  }
  for (const auto& [interval, range] : per_interval) {
    accel_range_ = std::max(accel_range_, (range.second - range.first).maxCoeff());
  }
  gyro_range_ = (ghi - glo).maxCoeff();
}

ThermalFit ThermalFitter::Run(const ThermalOrders& orders,
                              const std::map<std::string, double>& start) const {
  const ThermalLayout layout(orders, has_gyro_);
  std::vector<double> initial(layout.size, 0.0);
  initial[layout.upper + 0] = initial[layout.upper + 3] = initial[layout.upper + 5] =
      start_accel_scale_;
  if (has_gyro_) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const ThermalWindow& w : windows_) mean += w.gyro_mean;
    mean /= static_cast<double>(windows_.size());
    for (int i = 0; i < 3; ++i) initial[layout.gyro_bias + i] = mean(i);
  }
  for (int j = 0; j < layout.size; ++j) {
    const auto it = start.find(layout.names[j]);
    if (it != start.end()) initial[j] = it->second;
  }
  // U's off-diagonal starts (and, when undetermined, stays) at 0, unless
  // `start` gives it (a previous step that determined it, thermal_calibration.cc
  // Named): a next order started with U moved back to 0, the other
  // parameters where that U had put them, begins at a cost a thousand
  // times its solution's and took the solver past its iteration limit on
  // some held-out sessions (a bias order then chosen from an unconverged fit).
  for (int k : {1, 2, 4}) {
    if (start.count(layout.names[layout.upper + k]) == 0) initial[layout.upper + k] = 0.0;
  }
  // What is determined depends on where the Jacobian is taken (a bias far
  // from its value tilts the poses' directions and lends the
  // non-orthogonality information it does not have), so the test is
  // taken twice: at the start, for a first solve that also holds U's
  // off-diagonal (on the faces |U d| depends on it only to second order,
  // and a free start slides along that valley), then once more at that
  // first solution, whose bias and scale are the data's, for the final
  // solve from `initial`. It is not repeated at the final solution: one
  // that slid along a valley the poses leave open (six faces and one or
  // two tilted poses: U's columns turned by tens of degrees, the bias at
  // metres per second squared) would find itself determined there.
  ThermalFit fit;
  fit.theta = initial;
  std::vector<double> sigmas = AccelSigmas(layout, initial);
  fit.fixed = Held(layout, Undetermined(layout, fit.theta, sigmas));
  for (int j : {layout.upper + 1, layout.upper + 2, layout.upper + 4}) fit.fixed[j] = true;
  if (!Solve(layout, sigmas, &fit)) return fit;
  sigmas = AccelSigmas(layout, fit.theta);
  const std::vector<bool> again = Held(layout, Undetermined(layout, fit.theta, sigmas));
  if (again != fit.fixed) {
    fit.fixed = again;
    fit.theta = initial;
    if (!Solve(layout, sigmas, &fit)) return fit;
    sigmas = AccelSigmas(layout, fit.theta);
  }
  Covariance(layout, sigmas, &fit);
  return fit;
}

double ThermalFitter::Score(const ThermalFit& f) const {
  const double n = f.residuals, k = f.free;
  if (o_.selection == ThermalOrderSelection::kAicc) {
    return f.chi2 + 2.0 * k + (n - k - 1.0 > 0.0 ? 2.0 * k * (k + 1.0) / (n - k - 1.0) : 1e30);
  }
  return f.chi2 + k * std::log(n);
}

std::vector<bool> ThermalFitter::Held(const ThermalLayout& layout, std::vector<bool> fixed) const {
  if (faces_only_) {
    for (int j : {layout.upper + 1, layout.upper + 2, layout.upper + 4}) fixed[j] = true;
    for (int j = 0; j < layout.size; ++j) {
      const ThermalLayout::Slot& s = layout.slots[j];
      if (s.thermal && s.sensor == ThermalSensor::kAccel &&
          s.quantity == ThermalQuantity::kMisalignment) {
        fixed[j] = true;
      }
    }
  }
  if (single_axis_ < 0) return fixed;
  for (int j = 0; j < layout.size; ++j) {
    const ThermalLayout::Slot& s = layout.slots[j];
    if (s.sensor != ThermalSensor::kAccel || j == layout.lag) continue;
    if (j >= layout.upper && j < layout.upper + 6) {
      fixed[j] = true;
    } else if (s.quantity != ThermalQuantity::kBias || s.component != single_axis_) {
      fixed[j] = true;
    }
  }
  return fixed;
}

std::vector<double> ThermalFitter::AccelSigmas(const ThermalLayout& layout,
                                               const std::vector<double>& theta) const {
  Eigen::Matrix3d u = Eigen::Matrix3d::Zero();
  const double* p = theta.data() + layout.upper;
  u << p[0], p[1], p[2], 0.0, p[3], p[4], 0.0, 0.0, p[5];
  const Eigen::Vector3d b(theta[0], theta[1], theta[2]);
  std::vector<double> out;
  for (const ThermalWindow& w : windows_) {
    Eigen::Vector3d s = u * (w.accel_mean - b);
    if (!(s.norm() > 0.0)) s = Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d n = s.normalized();
    const double v = n.dot(u * w.accel_mean_cov * u.transpose() * n);
    out.push_back(std::sqrt(std::max(v, 1e-300)));
  }
  return out;
}

void ThermalFitter::Build(const ThermalLayout& layout, const std::vector<double>& sigmas,
                          double* theta, ceres::Problem* problem) const {
  for (size_t k = 0; k < windows_.size(); ++k) {
    problem->AddResidualBlock(ThermalWindowResidual::Create(layout, windows_[k], &element_,
                                                            reference_, o_.gravity, sigmas[k]),
                              nullptr, theta);
  }
}

Eigen::MatrixXd ThermalFitter::Jacobian(const ThermalLayout& layout,
                                        const std::vector<double>& sigmas,
                                        std::vector<double> theta,
                                        Eigen::VectorXd* residual) const {
  ceres::Problem::Options po;
  ceres::Problem problem(po);
  Build(layout, sigmas, theta.data(), &problem);
  ceres::CRSMatrix crs;
  std::vector<double> r;
  problem.Evaluate(ceres::Problem::EvaluateOptions(), nullptr, &r, nullptr, &crs);
  Eigen::MatrixXd j = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int row = 0; row < crs.num_rows; ++row) {
    for (int at = crs.rows[row]; at < crs.rows[row + 1]; ++at) {
      j(row, crs.cols[at]) = crs.values[at];
    }
  }
  if (residual != nullptr) *residual = Eigen::Map<Eigen::VectorXd>(r.data(), r.size());
  return j;
}

std::vector<double> ThermalFitter::PriorScale(const ThermalLayout& layout,
                                              const std::vector<double>& theta) const {
  std::vector<double> scale(layout.size, 1.0);
  const double* u = theta.data() + layout.upper;
  const double u_diag[3] = {std::abs(u[0]), std::abs(u[3]), std::abs(u[5])};
  const double accel_unit = std::max({u_diag[0], u_diag[1], u_diag[2], 1e-300});
  const double gyro_unit = o_.gyro_nominal_scale;
  constexpr double kCharacteristicRange = 30.0;
  for (int j = 0; j < layout.size; ++j) {
    const ThermalLayout::Slot& s = layout.slots[j];
    if (j == layout.lag) {
      scale[j] = 100.0;
    } else if (!s.thermal) {
      if (j < layout.upper) {
        scale[j] = std::max(1.0 / accel_unit, 10.0 * accel_range_);
      } else if (j < layout.upper + 6) {
        const bool diagonal = s.component == 0 || s.component == 3 || s.component == 5;
        scale[j] = (diagonal ? 0.1 : 0.05) * accel_unit;
      } else {
        scale[j] = std::max(0.2 / gyro_unit, 10.0 * gyro_range_);
      }
    } else {
      // The linear term's range (physical, or twice the change the data
      // show over the half span when larger: raw units whose nominal
      // scale is unknown), each further power divided by a 30 degree
      // characteristic range.
      const double per_power = std::pow(kCharacteristicRange, s.power - 1);
      double linear = 1e-4;  // scale, misalignment: 1e-4 per degC
      if (s.quantity == ThermalQuantity::kBias) {
        const bool accel = s.sensor == ThermalSensor::kAccel;
        linear = std::max(accel ? 0.01 / accel_unit : 1e-3 / gyro_unit,
                          2.0 * (accel ? accel_range_ : gyro_range_) / half_span_);
      }
      scale[j] = linear / per_power;
    }
  }
  return scale;
}

std::vector<bool> ThermalFitter::Undetermined(const ThermalLayout& layout,
                                              std::vector<double> theta,
                                              const std::vector<double>& sigmas) const {
  for (int k : {1, 2, 4}) theta[layout.upper + k] = 0.0;
  Eigen::MatrixXd j = Jacobian(layout, sigmas, theta, nullptr);
  const std::vector<double> prior = PriorScale(layout, theta);
  for (int c = 0; c < layout.size; ++c) j.col(c) *= prior[c];
  // U's off-diagonal and the accelerometer misalignment terms enter |U d|
  // on the faces only to second order: the first-order "information" the
  // columns carry there comes from small perturbations of the design (the
  // thermal drift and the pose noise tilting a tilted pose's direction
  // lend each of the three off-diagonals information on what is one
  // combination of them; measured 0.2-0.4 % of their squared norm beyond
  // the columns kept before them), which the nonlinear problem does not
  // honour: a solve slides along the valley. Such a column is undetermined
  // when the columns kept before it explain all but kCollinear of it.
  // (Other terms are not held to this: x beside the constant on a
  // single warm-up keeps under 1 % and is rightly determined.)
  constexpr double kCollinear = 1e-2;
  std::vector<bool> valley(layout.size, false);
  for (int k : {1, 2, 4}) valley[layout.upper + k] = true;
  for (int c = 0; c < layout.size; ++c) {
    const ThermalLayout::Slot& s = layout.slots[c];
    valley[c] = valley[c] || (s.thermal && s.sensor == ThermalSensor::kAccel &&
                              s.quantity == ThermalQuantity::kMisalignment);
  }
  const Eigen::VectorXd original = j.colwise().squaredNorm().transpose();
  std::vector<bool> undetermined(layout.size, false), done(layout.size, false);
  std::vector<int> groups = layout.group;
  std::sort(groups.begin(), groups.end());
  groups.erase(std::unique(groups.begin(), groups.end()), groups.end());
  for (int g : groups) {
    while (true) {
      int best = -1;
      double best_norm = -1.0;
      for (int c = 0; c < layout.size; ++c) {
        if (done[c] || layout.group[c] != g) continue;
        const double n = j.col(c).squaredNorm();
        if (n > best_norm) {
          best_norm = n;
          best = c;
        }
      }
      if (best < 0) break;
      done[best] = true;
      if (!(best_norm >= o_.min_information) ||
          (valley[best] && !(best_norm >= kCollinear * original(best)))) {
        undetermined[best] = true;
        continue;
      }
      const Eigen::VectorXd q = j.col(best) / std::sqrt(best_norm);
      for (int c = 0; c < layout.size; ++c) {
        if (!done[c]) j.col(c) -= q * q.dot(j.col(c));
      }
    }
  }
  return undetermined;
}

bool ThermalFitter::Solve(const ThermalLayout& layout, const std::vector<double>& sigmas,
                          ThermalFit* fit) const {
  ceres::Problem problem;
  Build(layout, sigmas, fit->theta.data(), &problem);
  std::vector<int> held;
  for (int j = 0; j < layout.size; ++j) {
    if (fit->fixed[j]) held.push_back(j);
  }
  if (static_cast<int>(held.size()) == layout.size) {
    problem.SetParameterBlockConstant(fit->theta.data());
  } else if (!held.empty()) {
    problem.SetManifold(fit->theta.data(), new ceres::SubsetManifold(layout.size, held));
  }
  // The lag filter is stable for tau >= 0 only (a negative tau, an
  // element leading its own sensor, is not physical).
  if (layout.lag >= 0 && !fit->fixed[layout.lag]) {
    fit->theta[layout.lag] = std::max(0.0, fit->theta[layout.lag]);
    problem.SetParameterLowerBound(fit->theta.data(), layout.lag, 0.0);
  }
  const ceres::Solver::Options so =
      internal::SolverOptions(internal::CeresDefaultTolerances(o_.max_iterations), ceres::DENSE_QR);
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  fit->residuals = static_cast<int>(problem.NumResiduals());
  fit->free = layout.size - static_cast<int>(held.size());
  fit->chi2 = 2.0 * summary.final_cost;
  fit->ok = summary.IsSolutionUsable() && std::isfinite(fit->chi2);
  fit->converged = summary.termination_type == ceres::CONVERGENCE;
  for (double v : fit->theta) fit->ok = fit->ok && std::isfinite(v);
  fit->message = summary.BriefReport();
  return fit->ok;
}

void ThermalFitter::Covariance(const ThermalLayout& layout, const std::vector<double>& sigmas,
                               ThermalFit* fit) const {
  const Eigen::MatrixXd j = Jacobian(layout, sigmas, fit->theta, nullptr);
  std::vector<int> free;
  for (int c = 0; c < layout.size; ++c) {
    if (!fit->fixed[c]) free.push_back(c);
  }
  Eigen::MatrixXd jf(j.rows(), free.size());
  for (size_t c = 0; c < free.size(); ++c) jf.col(c) = j.col(free[c]);
  // Column scaling keeps the normal matrix well conditioned.
  Eigen::VectorXd d = jf.colwise().norm().transpose();
  for (int c = 0; c < d.size(); ++c) {
    if (!(d(c) > 0.0)) d(c) = 1.0;
    jf.col(c) /= d(c);
  }
  const Eigen::MatrixXd info = jf.transpose() * jf;
  Eigen::MatrixXd inv = info.ldlt().solve(Eigen::MatrixXd::Identity(info.rows(), info.cols()));
  const int dof = fit->residuals - fit->free;
  // Quantised temperatures (thermal_calibration.h): the error e_g a group
  // of windows shares moves the solution by K_g e_g, K_g = (J^T J)^-1 J^T
  // a_g, a_g the whitened residuals' derivative in the group's
  // temperatures; the covariance gains sum_g var_g K_g K_g^T.
  Eigen::MatrixXd extra = Eigen::MatrixXd::Zero(free.size(), free.size());
  std::map<int, std::pair<Eigen::VectorXd, double>> groups;
  const int rows = layout.has_gyro ? 4 : 1;
  for (size_t k = 0; k < windows_.size(); ++k) {
    const ThermalWindow& w = windows_[k];
    if (!(w.temperature_variance > 0.0)) continue;
    constexpr double kStep = 0.01;  // degC
    double r[2][4];
    for (int side = 0; side < 2; ++side) {
      ThermalWindow moved = w;
      moved.temperature += side == 0 ? kStep : -kStep;
      const ThermalWindowResidual f(layout, moved, &element_, reference_, o_.gravity, sigmas[k]);
      const double* p[1] = {fit->theta.data()};
      f(p, r[side]);
    }
    const int key = w.temperature_group >= 0 ? w.temperature_group : -1 - static_cast<int>(k);
    auto it = groups.find(key);
    if (it == groups.end()) {
      it = groups.emplace(key, std::make_pair(Eigen::VectorXd::Zero(j.rows()), 0.0)).first;
    }
    for (int i = 0; i < rows; ++i) {
      it->second.first(k * rows + i) = (r[0][i] - r[1][i]) / (2.0 * kStep);
    }
    it->second.second = w.temperature_variance;
  }
  // What those errors add to chi^2 on average, var_g |(I - J K) a_g|^2, is
  // not taken as a sign of too small a noise (below).
  double expected = 0.0;
  for (const auto& [key, g] : groups) {
    const Eigen::VectorXd gain = inv * (jf.transpose() * g.first);
    extra += g.second * gain * gain.transpose();
    expected += g.second * (g.first - jf * gain).squaredNorm();
  }
  const double factor = dof > 0 ? std::max(1.0, (fit->chi2 - expected) / dof) : 1.0;
  fit->covariance = Eigen::MatrixXd::Zero(layout.size, layout.size);
  for (size_t a = 0; a < free.size(); ++a) {
    for (size_t b = 0; b < free.size(); ++b) {
      fit->covariance(free[a], free[b]) = (factor * inv(a, b) + extra(a, b)) / (d(a) * d(b));
    }
  }
}

}  // namespace internal
}  // namespace gravcal
