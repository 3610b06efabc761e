// The gyroscope's scale against temperature from the turns (thermal_turns.h).
#include "methods/thermal_turns.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include "estimation/solver_settings.h"
#include "gravcal/methods/gyro_calibration.h"
#include "methods/thermal_turn_residual.h"

namespace gravcal {
namespace internal {
namespace {

// Turns needed at least: two rows each beside M_g's 9 entries.
constexpr int kMinTurns = 6;
// A parameter whose standard deviation exceeds this share of the scale
// (M_g), or a scale(T) coefficient changing the scale by more than this
// over the turns' half span, is not determined by the turns.
constexpr double kMaxMatrixStd = 0.05;
constexpr double kMaxScaleChangeStd = 0.01;
// The accelerometer frame's N (rad): an entry the turns do not determine
// is held at 0 and considered, with this spread, in M_g's covariance: the
// cross-axis sensitivity of an ICM-42688-P's accelerometer (+-1 %,
// DS-000347; BMI088's is 0.5 %).
constexpr double kFrameSpread = 0.01;
// An entry is fitted when its linearised std is below a fifth of that
// spread (a weaker one lets the fit wander along the valley it shares with
// M_g).
constexpr double kFrameStdLimit = 0.2 * kFrameSpread;
constexpr const char* kFrameNames[3] = {"xy", "xz", "yz"};
// The bound on each fitted entry of N (rad); a fit that reaches half of it
// does not determine N.
constexpr double kFrameBound = 0.05;
constexpr int kFrameIterations = 15;

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

struct TurnSolve {
  bool ok = false;
  std::vector<double> theta;
  double chi2 = NAN;
  bool converged = false;
  int residuals = 0;
  Eigen::MatrixXd covariance;
};

// Solves the turn fit of `layout` from `start` (layout.size() values).
TurnSolve SolveTurns(const std::vector<ThermalTurn>& turns, const std::vector<double>& sigmas,
                     const TurnLayout& layout, const std::vector<double>& start,
                     int max_iterations) {
  TurnSolve out;
  const int size = layout.size();
  out.theta = start;
  ceres::Problem problem;
  for (size_t k = 0; k < turns.size(); ++k) {
    auto* f = new ceres::DynamicAutoDiffCostFunction<TurnResidual, 16>(
        new TurnResidual(turns[k], layout, sigmas[k]));
    f->AddParameterBlock(size);
    f->SetNumResiduals(2);
    problem.AddResidualBlock(f, nullptr, out.theta.data());
  }
  // N stays near I: a large N folds the gravity directions together,
  // which fits any turn.
  for (int k = 0; k < layout.frames(); ++k) {
    problem.SetParameterLowerBound(out.theta.data(), layout.frame_at() + k, -kFrameBound);
    problem.SetParameterUpperBound(out.theta.data(), layout.frame_at() + k, kFrameBound);
  }
  const ceres::Solver::Options so =
      internal::SolverOptions(internal::CeresDefaultTolerances(max_iterations), ceres::DENSE_QR);
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  out.chi2 = 2.0 * summary.final_cost;
  out.residuals = problem.NumResiduals();
  out.ok = summary.IsSolutionUsable() && std::isfinite(out.chi2);
  out.converged = summary.termination_type == ceres::CONVERGENCE;
  for (double v : out.theta) out.ok = out.ok && std::isfinite(v);
  if (!out.ok) return out;
  const Eigen::MatrixXd inverse = TurnScaledInverse(TurnDenseJacobian(&problem));
  const int dof = out.residuals - size;
  const double factor = dof > 0 ? std::max(1.0, out.chi2 / dof) : 1.0;
  out.covariance = factor * inverse;
  return out;
}

// The whitened Jacobian of the turns' residuals (`layout`) at `theta`.
Eigen::MatrixXd TurnJacobian(const std::vector<ThermalTurn>& turns,
                             const std::vector<double>& sigmas, const TurnLayout& layout,
                             std::vector<double> theta) {
  ceres::Problem problem;
  for (size_t k = 0; k < turns.size(); ++k) {
    auto* f = new ceres::DynamicAutoDiffCostFunction<TurnResidual, 16>(
        new TurnResidual(turns[k], layout, sigmas[k]));
    f->AddParameterBlock(layout.size());
    f->SetNumResiduals(2);
    problem.AddResidualBlock(f, nullptr, theta.data());
  }
  return TurnDenseJacobian(&problem);
}

// `theta` of `layout` carried into `wider` (the same orders, more of N's
// entries: those new are 0).
std::vector<double> WidenTurnTheta(const TurnLayout& layout, const std::vector<double>& theta,
                                   const TurnLayout& wider) {
  std::vector<double> out(theta.begin(), theta.begin() + layout.frame_at());
  for (int k = 0, at = layout.frame_at(); k < 3; ++k) {
    if (layout.frame[k]) {
      out.push_back(theta[at++]);
    } else if (wider.frame[k]) {
      out.push_back(0.0);
    }
  }
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
  // A static interval's edge included in a turn, and the longest gap
  // between two poses that is a turn: the rotations gyroscope calibration's
  // defaults (edge_seconds, max_rotation_seconds).
  const GyroCalibrationOptions turn_defaults;
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
    const size_t edge =
        static_cast<size_t>(std::round(turn_defaults.edge_seconds / std::max(h, 1e-9)));
    const size_t a = s.end - std::min(edge, s.count() / 4) - 1;
    const size_t b = e.begin + std::min(edge, e.count() / 4);
    if (b <= a + 1 || b >= log.size() || log.t[b] - log.t[a] > turn_defaults.max_rotation_seconds)
      continue;
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

namespace {

// The starting values of `layout`: M_g = `m`, the polynomials 0, N's fitted
// entries from `n`.
std::vector<double> TurnStart(const TurnLayout& layout, const Eigen::Matrix3d& m,
                              const Eigen::Vector3d& n) {
  std::vector<double> theta(layout.size(), 0.0);
  for (int i = 0; i < 9; ++i) theta[i] = m(i / 3, i % 3);
  for (int k = 0, at = layout.frame_at(); k < 3; ++k) {
    if (layout.frame[k]) theta[at++] = n(k);
  }
  return theta;
}

// The information criterion of a solve with `k` parameters.
double TurnScore(const TurnSolve& s, double k, ThermalOrderSelection selection) {
  if (selection == ThermalOrderSelection::kAicc) {
    const double d = s.residuals - k - 1.0;
    return s.chi2 + 2.0 * k + (d > 0.0 ? 2.0 * k * (k + 1.0) / d : 1e30);
  }
  return s.chi2 + k * std::log(static_cast<double>(s.residuals));
}

// Fills one polynomial term of `components` x `order` from the solve's
// parameters at `at`; a coefficient whose std changes the term by more
// than `limit` over the half span is undetermined. Returns false when any
// is.
bool FillTurnTerm(const TurnSolve& s, const Eigen::MatrixXd& covariance, int at, int components,
                  int order, int max_order, const std::string& selection, double half, double limit,
                  ThermalPolynomial* p) {
  p->Resize(components, order);
  p->max_order = max_order;
  p->selection = selection;
  bool all = true;
  for (int i = 0; i < components && order > 0; ++i) {
    Eigen::MatrixXd c = Eigen::MatrixXd::Zero(order + 1, order + 1);
    for (int a = 1; a <= order; ++a) {
      for (int b = 1; b <= order; ++b) {
        c(a, b) = covariance(at + i * order + a - 1, at + i * order + b - 1);
      }
    }
    p->covariance.push_back(c);
    for (int k = 1; k <= order; ++k) {
      const bool known = std::sqrt(c(k, k)) * std::pow(half, k) < limit;
      p->determined(i, k - 1) = known;
      p->coefficients(i, k - 1) = known ? s.theta[at + i * order + k - 1] : 0.0;
      all = all && known;
    }
  }
  return all;
}

}  // namespace

void FitThermalTurns(const std::vector<ThermalTurn>& turns, double gyro_noise_variance,
                     double nominal, const ThermalCalibrationOptions& options,
                     const std::array<bool, 3>& frame, ThermalTurnFit* fit) {
  *fit = ThermalTurnFit();
  fit->turns = static_cast<int>(turns.size());
  fit->matrix = nominal * Eigen::Matrix3d::Identity();
  const int max_scale =
      options.gyro_scale_order >= 0 ? options.gyro_scale_order : options.gyro_scale_max_order;
  const int max_misalignment = options.gyro_misalignment_order >= 0
                                   ? options.gyro_misalignment_order
                                   : options.gyro_misalignment_max_order;
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
  const int scale_limit =
      options.gyro_scale_order >= 0 ? max_scale : std::min(max_scale, supported);
  const int misalignment_limit = options.gyro_misalignment_order >= 0
                                     ? max_misalignment
                                     : std::min(max_misalignment, supported);
  // The orders: the scale's first (misalignment off), then the
  // misalignment's at that scale order; each by the criterion, or the
  // given one.
  TurnLayout layout;
  Eigen::Matrix3d from = start * Eigen::Matrix3d::Identity();
  // The order-0 solve of the fitted entries, when the check below made it.
  TurnSolve checked;
  // Which of N's open entries the turns determine: their std about the
  // fit with neither temperature term and N = I. The others stay 0 and are
  // considered in the covariance below.
  {
    TurnSolve s =
        SolveTurns(turns, sigmas, layout, TurnStart(layout, from, Eigen::Vector3d::Zero()),
                   options.max_iterations);
    if (s.ok) {
      for (int i = 0; i < 9; ++i) from(i / 3, i % 3) = s.theta[i];
    }
    if (s.ok && (frame[0] || frame[1] || frame[2])) {
      TurnLayout open;
      open.frame = frame;
      const Eigen::MatrixXd c = TurnScaledInverse(
          TurnJacobian(turns, sigmas, open, WidenTurnTheta(layout, s.theta, open)));
      for (int k = 0, at = open.frame_at(); k < 3; ++k) {
        if (!frame[k]) continue;
        layout.frame[k] = std::sqrt(c(at, at)) < kFrameStdLimit;
        ++at;
      }
    }
    // The linearised std can promise what the fit does not keep: each entry
    // of N must stay well inside its bound (the entries that do not are
    // considered instead; twice, then none is fitted).
    for (int pass = 0; pass < 3 && layout.frames() > 0; ++pass) {
      // A determined N converges in a few iterations from the fit without it.
      TurnSolve t =
          SolveTurns(turns, sigmas, layout, TurnStart(layout, from, Eigen::Vector3d::Zero()),
                     std::min(options.max_iterations, kFrameIterations));
      if (!t.ok || !t.converged || pass == 2) {
        layout.frame = {false, false, false};
        break;
      }
      bool sane = true;
      for (int k = 0, at = layout.frame_at(); k < 3; ++k) {
        if (!layout.frame[k]) continue;
        if (!(std::abs(t.theta[at++]) < 0.5 * kFrameBound)) {
          layout.frame[k] = false;
          sane = false;
        }
      }
      if (sane) {
        checked = std::move(t);
        break;
      }
    }
    if (layout.frames() == 0 && s.ok) checked = std::move(s);
  }
  TurnSolve best;
  TurnLayout best_layout;
  double best_score = INFINITY;
  Eigen::Vector3d n_from = Eigen::Vector3d::Zero();
  auto consider = [&](TurnSolve&& s, const TurnLayout& l) {
    const double score = TurnScore(s, l.size(), options.selection);
    if (score < best_score) {
      best_score = score;
      best = std::move(s);
      best_layout = l;
    }
  };
  for (int order = 0; order <= scale_limit; ++order) {
    layout.scale = order;
    TurnSolve s = order == 0 && checked.ok
                      ? std::move(checked)
                      : SolveTurns(turns, sigmas, layout, TurnStart(layout, from, n_from),
                                   options.max_iterations);
    if (!s.ok) break;
    if (order == 0) {
      for (int i = 0; i < 9; ++i) from(i / 3, i % 3) = s.theta[i];
      for (int k = 0, at = layout.frame_at(); k < 3; ++k) {
        if (layout.frame[k]) n_from(k) = s.theta[at++];
      }
    }
    if (options.gyro_scale_order >= 0 && order != options.gyro_scale_order) continue;
    consider(std::move(s), layout);
  }
  if (best.ok) {
    layout = best_layout;
    // A given order replaces the misalignment-free fit.
    if (options.gyro_misalignment_order > 0) best_score = INFINITY;
    for (int order = 1; order <= misalignment_limit; ++order) {
      layout.misalignment = order;
      // From the chosen scale fit, the misalignment coefficients at 0.
      const TurnSolve& base = best;
      std::vector<double> theta(base.theta.begin(), base.theta.begin() + layout.misalignment_at());
      theta.resize(layout.frame_at(), 0.0);
      theta.insert(theta.end(), base.theta.begin() + best_layout.frame_at(), base.theta.end());
      TurnSolve s = SolveTurns(turns, sigmas, layout, theta, options.max_iterations);
      if (!s.ok) break;
      if (options.gyro_misalignment_order >= 0 && order != options.gyro_misalignment_order) {
        continue;
      }
      consider(std::move(s), layout);
    }
  }
  if (!best.ok) {
    fit->notes.push_back("gyro scale and misalignment are not estimated: the fit to the " +
                         std::to_string(fit->turns) + " turns failed");
    return;
  }
  layout = best_layout;
  Eigen::MatrixXd covariance = best.covariance;
  // N: the accelerometer frame's entries that the static poses left open
  // and the turns determine, with their std.
  for (int k = 0, at = layout.frame_at(); k < 3; ++k) {
    if (!layout.frame[k]) continue;
    fit->frame(k) = best.theta[at];
    fit->frame_std(k) = std::sqrt(std::max(0.0, covariance(at, at)));
    ++at;
  }
  fit->frame_fitted = layout.frame;
  // The open entries held at 0, considered: the solution moves by
  // K = (J^T J)^-1 J^T J_n per unit of them, so the covariance gains
  // s^2 K K^T (s = kFrameSpread, a typical non-orthogonality bound).
  TurnLayout wide = layout;
  wide.frame = frame;
  if (wide.frames() > layout.frames()) {
    const Eigen::MatrixXd j =
        TurnJacobian(turns, sigmas, wide, WidenTurnTheta(layout, best.theta, wide));
    std::vector<int> fitted, held;
    for (int c = 0; c < layout.frame_at(); ++c) fitted.push_back(c);
    for (int k = 0, at = layout.frame_at(); k < 3; ++k) {
      if (!frame[k]) continue;
      (layout.frame[k] ? fitted : held).push_back(at++);
      if (!layout.frame[k]) fit->frame_considered[k] = true;
    }
    Eigen::MatrixXd jf(j.rows(), fitted.size()), jc(j.rows(), held.size());
    for (size_t c = 0; c < fitted.size(); ++c) jf.col(c) = j.col(fitted[c]);
    for (size_t c = 0; c < held.size(); ++c) jc.col(c) = j.col(held[c]);
    const Eigen::MatrixXd k = TurnScaledInverse(jf) * (jf.transpose() * jc);
    covariance += kFrameSpread * kFrameSpread * k * k.transpose();
  }
  const double scale = std::cbrt(
      std::abs(Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(best.theta.data())
                   .determinant()));
  Eigen::Matrix3d m, m_std;
  for (int i = 0; i < 9; ++i) {
    m(i / 3, i % 3) = best.theta[i];
    m_std(i / 3, i % 3) = std::sqrt(std::max(0.0, covariance(i, i)));
  }
  if (!(m_std.maxCoeff() < kMaxMatrixStd * scale)) {
    fit->notes.push_back(
        "gyro scale and misalignment are not estimated: the " + std::to_string(fit->turns) +
        " turns do not determine the gyroscope matrix (turns about all three axes, each away "
        "from the vertical, are needed)");
    fit->frame_fitted = {false, false, false};
    fit->frame_considered = {false, false, false};
    fit->frame.setZero();
    return;
  }
  fit->matrix_estimated = true;
  fit->matrix = m;
  fit->matrix_std = m_std;
  fit->chi2 = best.chi2;
  fit->dof = best.residuals - layout.size();
  const double half = std::max(1.0, 0.5 * fit->span);
  auto how = [&](int given) {
    return given >= 0 ? std::string("given") : std::string(ToString(options.selection));
  };
  const bool scale_known =
      FillTurnTerm(best, covariance, layout.scale_at(), 3, layout.scale, max_scale,
                   how(options.gyro_scale_order), half, kMaxScaleChangeStd, &fit->scale);
  const bool misalignment_known = FillTurnTerm(
      best, covariance, layout.misalignment_at(), 6, layout.misalignment, max_misalignment,
      how(options.gyro_misalignment_order), half, kMaxScaleChangeStd, &fit->misalignment);
  if (fit->span < ThermalMinimumSpan(1)) {
    fit->notes.push_back("gyro scale against temperature undetermined (and misalignment): the " +
                         std::to_string(fit->turns) + " turns span only " + Num(fit->span, 2) +
                         " degC (a linear term needs " + Num(ThermalMinimumSpan(1), 2) +
                         "); turn the unit between poses at several temperatures");
  } else {
    if (!scale_known) {
      fit->notes.push_back(
          "gyro scale against temperature: some coefficients undetermined by the turns "
          "(reported as null, applied as 0)");
    }
    if (!misalignment_known) {
      fit->notes.push_back(
          "gyro misalignment against temperature: some coefficients undetermined by the turns "
          "(reported as null, applied as 0)");
    }
  }
  std::ostringstream s;
  s << "gyro matrix, scale (order " << layout.scale << ") and misalignment (order "
    << layout.misalignment << ") against temperature from " << fit->turns
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
  // The accelerometer's non-orthogonality (U's off-diagonal) that the
  // static poses left open (six faces do): the turns' angles measure it,
  // so it is fitted with M_g (else M_g would carry it unseen, 0.1-0.2 %).
  const Eigen::Matrix3d& u_std = out->accel.matrix_std;
  const std::array<bool, 3> frame = {!std::isfinite(u_std(0, 1)), !std::isfinite(u_std(0, 2)),
                                     !std::isfinite(u_std(1, 2))};
  ThermalTurnFit fit;
  FitThermalTurns(ThermalTurns(log, intervals, windows, out->accel.model, out->gyro.model.bias,
                               model, bias_std),
                  per_sample[per_sample.size() / 2], options.gyro_nominal_scale, options, frame,
                  &fit);
  if (fit.matrix_estimated) {
    out->gyro.model.matrix = fit.matrix;
    out->gyro.matrix_std = fit.matrix_std;
    model.gyro.scale = fit.scale;
    model.gyro.misalignment = fit.misalignment;
    if (fit.frame_fitted[0] || fit.frame_fitted[1] || fit.frame_fitted[2]) {
      // M_g is in the frame N U gives. U keeps the static fit's entries
      // (held at 0, null): verify tests U against check sessions, whose
      // own fit of those entries does not agree with the turns' N yet
      // (issue 35 leftover).
      std::ostringstream note;
      note.precision(3);
      note << "accelerometer non-orthogonality, which the static poses leave open, from the turns:";
      for (int k = 0; k < 3; ++k) {
        if (!fit.frame_fitted[k]) continue;
        note << " n_" << kFrameNames[k] << " " << fit.frame(k) << " +- " << fit.frame_std(k);
      }
      note << " rad (M_g is in the frame N U; U keeps 0 there)";
      fit.notes.push_back(note.str());
    }
    if (fit.frame_considered[0] || fit.frame_considered[1] || fit.frame_considered[2]) {
      std::ostringstream note;
      note << "accelerometer non-orthogonality";
      for (int k = 0; k < 3; ++k) {
        if (fit.frame_considered[k]) note << " n_" << kFrameNames[k];
      }
      note << ": undetermined by the static poses and the turns (held at 0, reported as null); "
              "the gyro matrix's std carries +-"
           << kFrameSpread
           << " rad of it (add tilted poses, or turn between the faces in varied order)";
      fit.notes.push_back(note.str());
    }
  }
  for (const std::string& n : fit.notes) model.notes.push_back(n);
}

}  // namespace internal
}  // namespace gravcal
