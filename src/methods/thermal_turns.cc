// The gyroscope's scale against temperature from the turns (thermal_turns.h).
#include "methods/thermal_turns.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <sstream>

namespace gravcal {
namespace internal {
namespace {

// A static interval's edge included in the turns, s (as the rotations
// gyroscope calibration's edge_seconds).
constexpr double kTurnEdgeSeconds = 0.5;
// A gap longer than this between two poses is not a turn, s.
constexpr double kLongestTurnSeconds = 60.0;
// Turns needed at least: two rows each beside M_g's 9 entries.
constexpr int kMinTurns = 6;
// A parameter whose standard deviation exceeds this share of the scale
// (M_g), or a scale(T) coefficient changing the scale by more than this
// over the turns' half span, is not determined by the turns.
constexpr double kMaxMatrixStd = 0.05;
constexpr double kMaxScaleChangeStd = 0.01;

// The calibrated specific force of a window and the tangent variance of its
// direction per component (rad^2).
Eigen::Vector3d WindowDirection(const ThermalWindow& w, const AccelModel& accel,
                                const ThermalModel& model, double* variance) {
  const double x = model.Offset(w.temperature, w.rate, nullptr);
  const Eigen::Vector3d s = CorrectAccelThermal(model, accel.bias, accel.upper, w.accel_mean, x);
  const Eigen::Matrix3d c = accel.upper * w.accel_mean_cov * accel.upper.transpose();
  const Eigen::Vector3d n = s.normalized();
  *variance = std::max(0.0, c.trace() - n.dot(c * n)) / (2.0 * s.squaredNorm());
  return n;
}

std::string Num(double v, int precision) {
  std::ostringstream s;
  s.precision(precision);
  s << v;
  return s.str();
}

// e = E (R^T d_s - d_e) / sigma for one turn (header).
class TurnResidual {
 public:
  TurnResidual(const ThermalTurn& turn, int order, double sigma)
      : turn_(turn), order_(order), inv_sigma_(1.0 / sigma) {
    // E: two unit vectors orthogonal to d_e.
    const Eigen::Vector3d d = turn.to;
    Eigen::Vector3d a = std::abs(d.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
    a = (a - d * d.dot(a)).normalized();
    basis_.row(0) = a.transpose();
    basis_.row(1) = d.cross(a).transpose();
  }

  template <typename T>
  bool operator()(T const* const* parameters, T* residuals) const {
    const T* m = parameters[0];
    T s[3];
    EvaluateThermalPolynomial(order_ > 0 ? m + 9 : nullptr, 3, order_, turn_.x, s);
    // A = (I + D_g(x))^-1 M_g, D_g diagonal.
    T a[9];
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) a[3 * i + j] = m[3 * i + j] / (T(1.0) + s[i]);
    }
    T r[9] = {T(1.0), T(0.0), T(0.0), T(0.0), T(1.0), T(0.0), T(0.0), T(0.0), T(1.0)};
    for (const Eigen::Vector3d& u : turn_.increments) {
      T angle[3];
      for (int i = 0; i < 3; ++i) {
        angle[i] = a[3 * i] * u.x() + a[3 * i + 1] * u.y() + a[3 * i + 2] * u.z();
      }
      T e[9];
      ceres::AngleAxisToRotationMatrix(angle, ceres::RowMajorAdapter3x3(e));
      T n[9];
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
          n[3 * i + j] = r[3 * i] * e[j] + r[3 * i + 1] * e[3 + j] + r[3 * i + 2] * e[6 + j];
        }
      }
      std::copy(n, n + 9, r);
    }
    T v[3];
    const Eigen::Vector3d& d = turn_.from;
    for (int j = 0; j < 3; ++j) {
      v[j] = r[j] * d.x() + r[3 + j] * d.y() + r[6 + j] * d.z() - T(turn_.to(j));
    }
    for (int i = 0; i < 2; ++i) {
      residuals[i] =
          (basis_(i, 0) * v[0] + basis_(i, 1) * v[1] + basis_(i, 2) * v[2]) * T(inv_sigma_);
    }
    return true;
  }

 private:
  const ThermalTurn& turn_;
  const int order_;
  const double inv_sigma_;
  Eigen::Matrix<double, 2, 3> basis_;
};

struct TurnSolve {
  bool ok = false;
  std::vector<double> theta;
  double chi2 = NAN;
  int residuals = 0;
  Eigen::MatrixXd covariance;
};

// Solves M_g and a scale term of `order` from `start` (M_g; the scale
// coefficients start at 0).
TurnSolve SolveTurns(const std::vector<ThermalTurn>& turns, const std::vector<double>& sigmas,
                     int order, const Eigen::Matrix3d& start, int max_iterations) {
  TurnSolve out;
  const int size = 9 + 3 * order;
  out.theta.assign(size, 0.0);
  for (int i = 0; i < 9; ++i) out.theta[i] = start(i / 3, i % 3);
  ceres::Problem problem;
  for (size_t k = 0; k < turns.size(); ++k) {
    auto* f = new ceres::DynamicAutoDiffCostFunction<TurnResidual, 16>(
        new TurnResidual(turns[k], order, sigmas[k]));
    f->AddParameterBlock(size);
    f->SetNumResiduals(2);
    problem.AddResidualBlock(f, nullptr, out.theta.data());
  }
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = max_iterations;
  so.num_threads = 1;
  so.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  out.chi2 = 2.0 * summary.final_cost;
  out.residuals = problem.NumResiduals();
  out.ok = summary.IsSolutionUsable() && std::isfinite(out.chi2);
  for (double v : out.theta) out.ok = out.ok && std::isfinite(v);
  if (!out.ok) return out;
  ceres::CRSMatrix crs;
  problem.Evaluate(ceres::Problem::EvaluateOptions(), nullptr, nullptr, nullptr, &crs);
  Eigen::MatrixXd j = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int row = 0; row < crs.num_rows; ++row) {
    for (int at = crs.rows[row]; at < crs.rows[row + 1]; ++at)
      j(row, crs.cols[at]) = crs.values[at];
  }
  Eigen::VectorXd d = j.colwise().norm().transpose();
  for (int c = 0; c < d.size(); ++c) {
    if (!(d(c) > 0.0)) d(c) = 1.0;
    j.col(c) /= d(c);
  }
  const Eigen::MatrixXd info = j.transpose() * j;
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(info, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::VectorXd sv = svd.singularValues();
  Eigen::VectorXd inv = Eigen::VectorXd::Zero(sv.size());
  // A direction the turns leave open gets an infinite variance.
  for (int i = 0; i < sv.size(); ++i) inv(i) = sv(i) > 1e-12 * sv(0) ? 1.0 / sv(i) : 1e30;
  const int dof = out.residuals - size;
  const double factor = dof > 0 ? std::max(1.0, out.chi2 / dof) : 1.0;
  out.covariance = factor * d.cwiseInverse().asDiagonal() *
                   (svd.matrixV() * inv.asDiagonal() * svd.matrixU().transpose()) *
                   d.cwiseInverse().asDiagonal();
  return out;
}

}  // namespace

std::vector<ThermalTurn> ThermalTurns(const ImuLog& log,
                                      const std::vector<StaticInterval>& intervals,
                                      const std::vector<ThermalWindow>& windows,
                                      const AccelModel& accel, const Eigen::Vector3d& gyro_bias,
                                      const ThermalModel& model, double gyro_bias_std) {
  std::vector<ThermalTurn> turns;
  if (!log.has_gyro() || !log.has_temperature() || log.size() < 2) return turns;
  const double h = (log.t.back() - log.t.front()) / static_cast<double>(log.size() - 1);
  const ThermalBlocks<double> gyro = model.Blocks(ThermalSensor::kGyro);
  for (size_t k = 0; k + 1 < intervals.size(); ++k) {
    const ThermalWindow* before = nullptr;
    const ThermalWindow* after = nullptr;
    for (const ThermalWindow& w : windows) {
      if (w.interval == static_cast<int>(k)) before = &w;
      if (w.interval == static_cast<int>(k + 1) && after == nullptr) after = &w;
    }
    if (before == nullptr || after == nullptr) continue;
    const StaticInterval& s = intervals[k];
    const StaticInterval& e = intervals[k + 1];
    const size_t edge = static_cast<size_t>(std::round(kTurnEdgeSeconds / std::max(h, 1e-9)));
    const size_t a = s.end - std::min(edge, s.count() / 4) - 1;
    const size_t b = e.begin + std::min(edge, e.count() / 4);
    if (b <= a + 1 || b >= log.size() || log.t[b] - log.t[a] > kLongestTurnSeconds) continue;
    ThermalTurn turn;
    double vs = 0.0, ve = 0.0;
    turn.from = WindowDirection(*before, accel, model, &vs);
    turn.to = WindowDirection(*after, accel, model, &ve);
    turn.seconds = log.t[b] - log.t[a];
    double sum = 0.0;
    for (size_t i = a; i <= b; ++i) sum += log.temperature[i];
    turn.temperature = sum / static_cast<double>(b - a + 1);
    turn.x = model.Offset(turn.temperature, 0.5 * (before->rate + after->rate), nullptr);
    Eigen::Vector3d db;
    gyro.BiasChange(turn.x, db.data());
    for (size_t i = a; i <= b; ++i) {
      turn.rates.push_back(log.gyro[i] - gyro_bias - db);
      turn.t.push_back(log.t[i]);
    }
    // The integral of the rates over each sample interval: the four-point
    // formula h/24 (-u0 + 13 u1 + 13 u2 - u3) inside, the trapezoid at the
    // ends (the trapezoid alone shortens a smooth turn by pi^2 h^2 / 12 of
    // its angle, 3e-4 at 50 samples per turn: a scale error of that size).
    const std::vector<Eigen::Vector3d>& u = turn.rates;
    for (size_t i = 0; i + 1 < u.size(); ++i) {
      const double h = turn.t[i + 1] - turn.t[i];
      if (i == 0 || i + 2 >= u.size()) {
        turn.increments.push_back(0.5 * h * (u[i] + u[i + 1]));
      } else {
        turn.increments.push_back(h / 24.0 * (13.0 * (u[i] + u[i + 1]) - u[i - 1] - u[i + 2]));
      }
    }
    turn.direction_variance = vs + ve + std::pow(gyro_bias_std * turn.seconds, 2);
    turns.push_back(std::move(turn));
  }
  return turns;
}

void FitThermalTurns(const std::vector<ThermalTurn>& turns, double gyro_noise_variance,
                     double nominal, const ThermalCalibrationOptions& options,
                     ThermalTurnFit* fit) {
  *fit = ThermalTurnFit();
  fit->turns = static_cast<int>(turns.size());
  fit->matrix = nominal * Eigen::Matrix3d::Identity();
  const int max_order =
      options.gyro_scale_order >= 0 ? options.gyro_scale_order : options.gyro_scale_max_order;
  if (fit->turns < kMinTurns) {
    fit->notes.push_back("gyro scale and misalignment are not estimated: " +
                         std::to_string(fit->turns) + " turns between static poses, at least " +
                         std::to_string(kMinTurns) + " needed (turn the unit between its poses)");
    return;
  }
  double lo = INFINITY, hi = -INFINITY;
  for (const ThermalTurn& t : turns) {
    lo = std::min(lo, t.temperature);
    hi = std::max(hi, t.temperature);
  }
  fit->span = hi - lo;
  // The common scale from the turns' angles, when the nominal one is far
  // from it (raw counts given nominal 1, or the wrong unit).
  std::vector<double> ratios;
  for (const ThermalTurn& t : turns) {
    Eigen::Vector3d integral = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& d : t.increments) integral += d;
    const double angle = std::acos(std::clamp(t.from.dot(t.to), -1.0, 1.0));
    if (angle > 30.0 * M_PI / 180.0 && integral.norm() > 0.0) {
      ratios.push_back(angle / integral.norm());
    }
  }
  double start = nominal;
  if (!ratios.empty()) {
    std::nth_element(ratios.begin(), ratios.begin() + ratios.size() / 2, ratios.end());
    const double data = ratios[ratios.size() / 2];
    if (!(data / nominal > 0.7 && data / nominal < 1.4)) start = data;
  }
  std::vector<double> sigmas;
  for (const ThermalTurn& t : turns) {
    const double h = t.seconds / std::max<size_t>(1, t.rates.size() - 1);
    sigmas.push_back(
        std::sqrt(t.direction_variance + gyro_noise_variance * start * start * h * t.seconds));
  }
  const int supported = ThermalMaxOrderForSpan(fit->span);
  const int limit = options.gyro_scale_order >= 0 ? max_order : std::min(max_order, supported);
  TurnSolve best;
  int best_order = -1;
  double best_score = INFINITY;
  Eigen::Matrix3d from = start * Eigen::Matrix3d::Identity();
  for (int order = 0; order <= limit; ++order) {
    TurnSolve s = SolveTurns(turns, sigmas, order, from, options.max_iterations);
    if (!s.ok) break;
    const double k = 9 + 3 * order;
    const double score =
        options.selection == ThermalOrderSelection::kAicc
            ? s.chi2 + 2.0 * k +
                  (s.residuals - k - 1.0 > 0.0 ? 2.0 * k * (k + 1.0) / (s.residuals - k - 1.0)
                                               : 1e30)
            : s.chi2 + k * std::log(static_cast<double>(s.residuals));
    if (order == 0) {
      for (int i = 0; i < 9; ++i) from(i / 3, i % 3) = s.theta[i];
    }
    if (options.gyro_scale_order >= 0 && order != options.gyro_scale_order) continue;
    if (score < best_score) {
      best_score = score;
      best = std::move(s);
      best_order = order;
    }
  }
  if (best_order < 0) {
    fit->notes.push_back("gyro scale and misalignment are not estimated: the fit to the " +
                         std::to_string(fit->turns) + " turns failed");
    return;
  }
  const double scale = std::cbrt(
      std::abs(Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(best.theta.data())
                   .determinant()));
  Eigen::Matrix3d m, m_std;
  for (int i = 0; i < 9; ++i) {
    m(i / 3, i % 3) = best.theta[i];
    m_std(i / 3, i % 3) = std::sqrt(std::max(0.0, best.covariance(i, i)));
  }
  if (!(m_std.maxCoeff() < kMaxMatrixStd * scale)) {
    fit->notes.push_back(
        "gyro scale and misalignment are not estimated: the " + std::to_string(fit->turns) +
        " turns do not determine the gyroscope matrix (turns about all three axes, each away "
        "from the vertical, are needed)");
    return;
  }
  fit->matrix_estimated = true;
  fit->matrix = m;
  fit->matrix_std = m_std;
  fit->chi2 = best.chi2;
  fit->dof = best.residuals - static_cast<int>(best.theta.size());
  ThermalPolynomial& p = fit->scale;
  p.Resize(3, best_order);
  p.max_order = max_order;
  p.selection = options.gyro_scale_order >= 0 ? "given" : std::string(ToString(options.selection));
  const double half = std::max(1.0, 0.5 * fit->span);
  bool undetermined = false;
  for (int i = 0; i < 3 && best_order > 0; ++i) {
    Eigen::MatrixXd c = Eigen::MatrixXd::Zero(best_order + 1, best_order + 1);
    for (int a = 1; a <= best_order; ++a) {
      for (int b = 1; b <= best_order; ++b) {
        c(a, b) = best.covariance(9 + i * best_order + a - 1, 9 + i * best_order + b - 1);
      }
    }
    p.covariance.push_back(c);
    for (int k = 1; k <= best_order; ++k) {
      const bool known = std::sqrt(c(k, k)) * std::pow(half, k) < kMaxScaleChangeStd;
      p.determined(i, k - 1) = known;
      p.coefficients(i, k - 1) = known ? best.theta[9 + i * best_order + k - 1] : 0.0;
      undetermined = undetermined || !known;
    }
  }
  if (fit->span < ThermalMinimumSpan(1)) {
    fit->notes.push_back("gyro scale against temperature undetermined: the " +
                         std::to_string(fit->turns) + " turns span only " + Num(fit->span, 2) +
                         " degC (a linear term needs " + Num(ThermalMinimumSpan(1), 2) +
                         "); turn the unit between poses at several temperatures");
  } else if (undetermined) {
    fit->notes.push_back(
        "gyro scale against temperature: some coefficients undetermined by the turns "
        "(reported as null, applied as 0)");
  }
  std::ostringstream s;
  s << "gyro matrix and scale against temperature (order " << best_order << ") from " << fit->turns
    << " turns between poses at " << Num(lo, 3) << " to " << Num(hi, 3) << " degC";
  fit->notes.push_back(s.str());
}

void AddThermalTurns(const ImuLog& log, const std::vector<StaticInterval>& intervals,
                     const std::vector<ThermalWindow>& windows,
                     const ThermalCalibrationOptions& options, Calibration* out) {
  if (windows.empty()) return;
  // The gyroscope's white noise per sample: the median over the windows.
  std::vector<double> per_sample;
  for (const ThermalWindow& w : windows) {
    per_sample.push_back(w.gyro_mean_var.mean() * static_cast<double>(w.end - w.begin));
  }
  std::nth_element(per_sample.begin(), per_sample.begin() + per_sample.size() / 2,
                   per_sample.end());
  const Eigen::Vector3d s = out->gyro.bias_std;
  const double bias_std =
      options.gyro_nominal_scale * s.array().isNaN().select(0.0, s.array()).maxCoeff();
  ThermalModel& model = out->thermal;
  ThermalTurnFit fit;
  FitThermalTurns(ThermalTurns(log, intervals, windows, out->accel.model, out->gyro.model.bias,
                               model, bias_std),
                  per_sample[per_sample.size() / 2], options.gyro_nominal_scale, options, &fit);
  if (fit.matrix_estimated) {
    out->gyro.model.matrix = fit.matrix;
    out->gyro.matrix_std = fit.matrix_std;
    model.gyro.scale = fit.scale;
    // The turns' angles are measured in the calibrated accelerometer's
    // frame: its non-orthogonality, when held, moves M_g (measured on six
    // faces: 0.1-0.2 % on the axis whose turns join the two non-orthogonal
    // axes).
    const Eigen::Matrix3d& u = out->accel.matrix_std;
    if (!std::isfinite(u(0, 1)) || !std::isfinite(u(0, 2)) || !std::isfinite(u(1, 2))) {
      fit.notes.push_back(
          "gyro matrix: the turns are measured in the accelerometer's frame, whose "
          "non-orthogonality this session leaves undetermined (add tilted poses): each gyro scale "
          "also carries an error of about that non-orthogonality (1e-3 is typical), not in its "
          "std; the scale's change with temperature is not affected");
    }
  }
  for (const std::string& n : fit.notes) model.notes.push_back(n);
}

}  // namespace internal
}  // namespace gravcal
