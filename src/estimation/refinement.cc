#include "gravcal/estimation/refinement.h"

#include <ceres/ceres.h>
#include <ceres/covariance.h>
#include <ceres/manifold.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <sstream>

#include "core/warnings.h"
#include "estimation/magnitude_fit.h"
#include "estimation/normalization.h"
#include "estimation/robust_loss.h"
#include "estimation/solver_settings.h"
#include "gravcal/residuals/gravity_magnitude_residual.h"
#include "util/statistics.h"

namespace gravcal {

using internal::ChiSquareUpperTail;
using internal::MagnitudeFitStart;
using internal::MakeLoss;
using internal::StartMagnitudeFit;
using internal::WhitenedSumOfSquares;

bool RefinementOptions::IsValid(std::string* error) const {
  if (!(loss_scale > 0.0 && std::isfinite(loss_scale))) {
    *error = "loss_scale: must be positive";
    return false;
  }
  if (!(max_bias_std > 0.0) || !(max_matrix_std > 0.0)) {
    *error = "max_bias_std, max_matrix_std: must be positive";
    return false;
  }
  if (!(extra_variance >= 0.0) || !(max_pose_disturbance > 0.0) ||
      !(structure_test_level > 0.0 && structure_test_level < 1.0)) {
    *error = "extra_variance >= 0, max_pose_disturbance > 0, 0 < structure_test_level < 1";
    return false;
  }
  if (!(pose_disturbance_prior_dof >= 0.0) || !std::isfinite(pose_disturbance_prior_dof) ||
      !(pose_disturbance_prior >= 0.0) || !std::isfinite(pose_disturbance_prior) ||
      (pose_disturbance_prior_dof > 0.0 && !(pose_disturbance_prior > 0.0))) {
    *error = "pose_disturbance_prior_dof >= 0 and, when it is positive, pose_disturbance_prior > 0";
    return false;
  }
  if (!(prior_conflict_level > 0.0 && prior_conflict_level < 0.5)) {
    *error = "prior_conflict_level: must be in (0, 0.5)";
    return false;
  }
  return solver.IsValid(error);
}

std::vector<double> MagnitudeSigmas(const std::vector<Position>& positions,
                                    const AccelModel& model) {
  std::vector<double> sigmas(positions.size());
  for (size_t k = 0; k < positions.size(); ++k) {
    const Eigen::Vector3d a = model.upper * (positions[k].raw_mean - model.bias);
    const Eigen::Vector3d u = a.normalized();
    const Eigen::Vector3d w = model.upper.transpose() * u;
    sigmas[k] = std::sqrt(std::max(w.dot(positions[k].raw_mean_cov * w), 0.0));
  }
  return sigmas;
}

std::vector<int> FreeUpperIndices(AccelParameterization p) {
  if (p == AccelParameterization::kScale) return {0, 3, 5};
  return {0, 1, 2, 3, 4, 5};
}

std::vector<std::string> MagnitudeParameterNames(AccelParameterization p) {
  static const char* kUpper[] = {"u_xx", "u_xy", "u_xz", "u_yy", "u_yz", "u_zz"};
  std::vector<std::string> names = {"bias_x", "bias_y", "bias_z"};
  for (int i : FreeUpperIndices(p)) names.push_back(kUpper[i]);
  return names;
}

Eigen::MatrixXd MagnitudeJacobian(const std::vector<Position>& positions, const AccelModel& model,
                                  const std::vector<double>& sigmas) {
  const std::vector<int> free = FreeUpperIndices(model.parameterization);
  Eigen::MatrixXd j(positions.size(), 3 + free.size());
  for (size_t k = 0; k < positions.size(); ++k) {
    const Eigen::Vector3d d = positions[k].raw_mean - model.bias;
    const Eigen::Vector3d u = (model.upper * d).normalized();
    const double w = 1.0 / sigmas[k];
    j.block<1, 3>(k, 0) = -w * (u.transpose() * model.upper);
    // d|a|/du for u00 u01 u02 u11 u12 u22.
    const double all[6] = {u(0) * d(0), u(0) * d(1), u(0) * d(2),
                           u(1) * d(1), u(1) * d(2), u(2) * d(2)};
    for (size_t i = 0; i < free.size(); ++i) j(k, 3 + i) = w * all[free[i]];
  }
  return j;
}

std::vector<double> MagnitudeResiduals(const std::vector<Position>& positions,
                                       const AccelModel& model, double gravity) {
  std::vector<double> r(positions.size());
  for (size_t k = 0; k < positions.size(); ++k) {
    r[k] = (model.upper * (positions[k].raw_mean - model.bias)).norm() - gravity;
  }
  return r;
}

namespace {

// Graduated loss scales, widest last: from one that holds every initial
// whitened residual (the first stage is then close to least squares) down to
// the requested one. Just loss_scale without a loss.
std::vector<double> LossScales(const RefinementOptions& options, const RefinementResult& result) {
  double largest = 0.0;
  for (size_t k = 0; k < result.residuals_before.size(); ++k) {
    largest = std::max(largest, std::fabs(result.residuals_before[k] / result.sigmas[k]));
  }
  return internal::GraduatedLossScales(options.loss, options.loss_scale, largest);
}

// The Ceres problem of the magnitude fit in normalised units, with its
// parameter blocks and loss.
struct MagnitudeProblem {
  explicit MagnitudeProblem(const ceres::Problem::Options& options) : problem(options) {}
  ceres::Problem problem;
  double bias[3];
  double upper[kUpperSize];
  std::unique_ptr<ceres::LossFunctionWrapper> loss;
  // Columns (bias_x ... u_zz of the free parameters) held at their value.
  std::vector<bool> held_column;
};

// One autodiff residual block per position (the public functor), so the
// robust loss acts per position; the blocks start at the normalised initial
// model and the loss at the widest scale.
void AddMagnitudeBlocks(const MagnitudeFitStart& fit, double gravity,
                        const RefinementOptions& options, const std::vector<double>& scales,
                        const std::vector<double>& sigmas, MagnitudeProblem* m) {
  for (int i = 0; i < 3; ++i) m->bias[i] = fit.normalized_model.bias(i);
  fit.normalized_model.GetUpper(m->upper);
  if (options.loss != LossType::kNone) {
    m->loss = std::make_unique<ceres::LossFunctionWrapper>(MakeLoss(options.loss, scales.back()),
                                                           ceres::TAKE_OWNERSHIP);
  }
  for (int k = 0; k < fit.num_positions; ++k) {
    m->problem.AddResidualBlock(
        GravityMagnitudeResidual::Create(fit.normalized[k].raw_mean, gravity, sigmas[k]),
        m->loss.get(), m->bias, m->upper);
  }
}

// Holds the scale model's off-diagonal and options.held_parameters constant.
// False with result->message on a name that is not a parameter.
bool HoldParameters(const MagnitudeFitStart& fit, const RefinementOptions& options,
                    MagnitudeProblem* m, RefinementResult* result) {
  const AccelParameterization p = options.parameterization;
  std::vector<int> held_bias, held_upper;
  if (p == AccelParameterization::kScale) held_upper = {1, 2, 4};
  m->held_column.assign(fit.num_parameters, false);
  for (const std::string& name : options.held_parameters) {
    const auto it = std::find(result->parameter_names.begin(), result->parameter_names.end(), name);
    if (it == result->parameter_names.end()) {
      result->message =
          "held_parameters: '" + name + "' is not a parameter of '" + ToString(p) + "'";
      return false;
    }
    const int column = static_cast<int>(it - result->parameter_names.begin());
    m->held_column[column] = true;
    if (column < 3) {
      held_bias.push_back(column);
    } else {
      held_upper.push_back(fit.free[column - 3]);
    }
  }
  if (held_bias.size() == 3) {
    m->problem.SetParameterBlockConstant(m->bias);
  } else if (!held_bias.empty()) {
    m->problem.SetManifold(m->bias, new ceres::SubsetManifold(3, held_bias));
  }
  if (held_upper.size() == kUpperSize) {
    m->problem.SetParameterBlockConstant(m->upper);
  } else if (!held_upper.empty()) {
    m->problem.SetManifold(m->upper, new ceres::SubsetManifold(kUpperSize, held_upper));
  }
  return true;
}

// Solves once per loss scale, narrowest last; fills iterations, solve time
// and termination.
void SolveGraduated(const RefinementOptions& options, const std::vector<double>& scales,
                    MagnitudeProblem* m, ceres::Solver::Summary* summary,
                    RefinementResult* result) {
  // For speed: with 9 parameters and the normalised (well-conditioned)
  // problem, J^T J + D and a Cholesky factor are about 4 times cheaper per
  // step than Householder QR; the optimum is the same to within the solver's
  // tolerances (benchmarks/RESULTS.md).
  const ceres::Solver::Options solver_options =
      internal::SolverOptions(options.solver, ceres::DENSE_NORMAL_CHOLESKY);
  const auto start = std::chrono::steady_clock::now();
  result->iterations = 0;
  for (auto it = scales.rbegin(); it != scales.rend(); ++it) {
    if (m->loss) m->loss->Reset(MakeLoss(options.loss, *it), ceres::TAKE_OWNERSHIP);
    ceres::Solve(solver_options, &m->problem, summary);
    result->iterations += static_cast<int>(summary->iterations.size()) - 1;
    if (!summary->IsSolutionUsable()) break;
  }
  result->solve_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result->termination = ceres::TerminationTypeToString(summary->termination_type);
}

// Rank and null directions from the analytic whitened Jacobian at the
// optimum (normalised units). Held columns are not estimated and take no part
// in the rank; they are reported as undetermined. Returns the number of
// estimated parameters.
int AnalyzeActiveObservability(const MagnitudeFitStart& fit, const AccelModel& refined_n,
                               const std::vector<bool>& held_column, RefinementResult* result) {
  const Eigen::MatrixXd jacobian = MagnitudeJacobian(fit.normalized, refined_n, result->sigmas);
  std::vector<int> active;
  std::vector<std::string> active_names;
  for (int i = 0; i < fit.num_parameters; ++i) {
    if (held_column[i]) continue;
    active.push_back(i);
    active_names.push_back(result->parameter_names[i]);
  }
  Eigen::MatrixXd active_jacobian(fit.num_positions, active.size());
  for (size_t i = 0; i < active.size(); ++i) active_jacobian.col(i) = jacobian.col(active[i]);
  result->observability = AnalyzeObservability(active_jacobian, active_names);
  const int num_active = static_cast<int>(active.size());
  for (int i = 0; i < fit.num_parameters; ++i) {
    if (held_column[i]) result->observability.undetermined.push_back(result->parameter_names[i]);
  }
  if (!result->observability.full_rank()) {
    std::ostringstream s;
    s << "the positions do not determine " << num_active - result->observability.rank
      << " direction(s) of the model:";
    for (const std::string& d : result->observability.descriptions) s << " [" << d << "]";
    s << "; add positions with other axes up";
    internal::AddWarning(WarningCode::kUndetermined, s.str(), &result->warnings,
                         &result->warning_codes);
  }
  return num_active;
}

// The covariance of (b, free entries of U) in normalised units from Ceres;
// false when Ceres cannot compute it.
bool NormalizedCovariance(const MagnitudeFitStart& fit, int null_space_rank, MagnitudeProblem* m,
                          Eigen::MatrixXd* cov) {
  ceres::Covariance::Options covariance_options;
  covariance_options.algorithm_type = ceres::DENSE_SVD;
  covariance_options.null_space_rank = null_space_rank;
  covariance_options.num_threads = 1;
  ceres::Covariance covariance(covariance_options);
  const double* bias = m->bias;
  const double* upper = m->upper;
  std::vector<std::pair<const double*, const double*>> blocks = {
      {bias, bias}, {bias, upper}, {upper, upper}};
  if (!covariance.Compute(blocks, &m->problem)) return false;
  double cbb[9], cbu[18], cuu[36];
  covariance.GetCovarianceBlock(bias, bias, cbb);
  covariance.GetCovarianceBlock(bias, upper, cbu);
  covariance.GetCovarianceBlock(upper, upper, cuu);
  const std::vector<int>& free = fit.free;
  cov->resize(fit.num_parameters, fit.num_parameters);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) (*cov)(i, j) = cbb[3 * i + j];
    for (size_t j = 0; j < free.size(); ++j) {
      (*cov)(i, 3 + j) = (*cov)(3 + j, i) = cbu[kUpperSize * i + free[j]];
    }
  }
  for (size_t i = 0; i < free.size(); ++i) {
    for (size_t j = 0; j < free.size(); ++j) {
      (*cov)(3 + i, 3 + j) = cuu[kUpperSize * free[i] + free[j]];
    }
  }
  return true;
}

// Names of the estimated parameters whose standard deviation (normalised
// units: bias in m/s^2, U relative to the mean scale, so the limits apply
// directly) exceeds max_bias_std / max_matrix_std; they are added to the
// undetermined list.
std::vector<std::string> WeakParameters(const RefinementOptions& options,
                                        const Eigen::MatrixXd& cov,
                                        const std::vector<bool>& held_column,
                                        RefinementResult* result) {
  std::vector<std::string> weak;
  for (int i = 0; i < static_cast<int>(held_column.size()); ++i) {
    if (held_column[i]) continue;
    const double limit = i < 3 ? options.max_bias_std : options.max_matrix_std;
    if (std::sqrt(std::max(cov(i, i), 0.0)) > limit) weak.push_back(result->parameter_names[i]);
  }
  for (const std::string& name : weak) {
    auto& undetermined = result->observability.undetermined;
    if (std::find(undetermined.begin(), undetermined.end(), name) == undetermined.end()) {
      undetermined.push_back(name);
    }
  }
  return weak;
}

}  // namespace

namespace {

// The weak parameter whose standard deviation is the largest multiple of
// its limit (normalised units, as WeakParameters).
std::string Weakest(const RefinementOptions& options, const Eigen::MatrixXd& cov,
                    const std::vector<std::string>& weak, const RefinementResult& result) {
  std::string weakest;
  double worst = -1.0;
  for (size_t i = 0; i < result.parameter_names.size(); ++i) {
    if (std::find(weak.begin(), weak.end(), result.parameter_names[i]) == weak.end()) continue;
    const double limit = i < 3 ? options.max_bias_std : options.max_matrix_std;
    const double ratio = std::sqrt(std::max(cov(i, i), 0.0)) / limit;
    if (ratio > worst) {
      worst = ratio;
      weakest = result.parameter_names[i];
    }
  }
  return weakest;
}

// The spread a held term may have about its held value: what makes it
// undetermined, max_bias_std or max_matrix_std (normalised units). The
// estimated terms move with it through the fit,
//
//   dx_o = G dx_h,   G = -(J_o^T J_o)^-1 J_o^T J_h
//
// (J whitened, o the estimated columns, h the held ones), so their
// covariance conditional on the held values gains G diag(spread^2) G^T: the
// standard deviations stay honest when the held value is off by up to that
// spread. The held rows and columns stay zero (they are reported without a
// number).
void AddHeldSpread(const MagnitudeFitStart& fit, const AccelModel& refined_n,
                   const std::vector<bool>& held_column, const RefinementOptions& options,
                   const std::vector<double>& sigmas, Eigen::MatrixXd* cov) {
  std::vector<int> o, h;
  for (int i = 0; i < static_cast<int>(held_column.size()); ++i) {
    (held_column[i] ? h : o).push_back(i);
  }
  if (h.empty() || o.empty()) return;
  const Eigen::MatrixXd j = MagnitudeJacobian(fit.normalized, refined_n, sigmas);
  Eigen::MatrixXd jo(j.rows(), o.size()), jh(j.rows(), h.size());
  for (size_t k = 0; k < o.size(); ++k) jo.col(k) = j.col(o[k]);
  Eigen::VectorXd spread2(h.size());
  for (size_t k = 0; k < h.size(); ++k) {
    jh.col(k) = j.col(h[k]);
    const double limit = h[k] < 3 ? options.max_bias_std : options.max_matrix_std;
    spread2(k) = limit * limit;
  }
  const Eigen::MatrixXd g = -(jo.transpose() * jo).ldlt().solve(jo.transpose() * jh);
  if (!g.allFinite()) return;
  const Eigen::MatrixXd add = g * spread2.asDiagonal() * g.transpose();
  for (size_t a = 0; a < o.size(); ++a) {
    for (size_t b = 0; b < o.size(); ++b) (*cov)(o[a], o[b]) += add(a, b);
  }
}

// Sets the off-diagonal entries of model->upper named in `held` (u_xy,
// u_xz, u_yz) to zero.
void ZeroHeldCrossTerms(const std::vector<std::string>& held, AccelModel* model) {
  const char* names[3] = {"u_xy", "u_xz", "u_yz"};
  const int rows[3] = {0, 0, 1}, cols[3] = {1, 2, 2};
  for (int k = 0; k < 3; ++k) {
    if (std::find(held.begin(), held.end(), names[k]) != held.end()) {
      model->upper(rows[k], cols[k]) = 0.0;
    }
  }
}

// Refine; `outermost` is false in the refits that hold weak terms (the
// outermost call names every term they held, in one warning).
bool RefineHoldingWeak(const std::vector<Position>& positions, const AccelModel& initial,
                       double gravity, const RefinementOptions& options, bool outermost,
                       RefinementResult* result);

}  // namespace

bool Refine(const std::vector<Position>& positions, const AccelModel& initial, double gravity,
            const RefinementOptions& options, RefinementResult* result) {
  return RefineHoldingWeak(positions, initial, gravity, options, true, result);
}

namespace {

bool RefineHoldingWeak(const std::vector<Position>& positions, const AccelModel& initial,
                       double gravity, const RefinementOptions& options, bool outermost,
                       RefinementResult* result) {
  CHECK(result != nullptr);
  // Solve in well-conditioned units (normalization.h); |a| is unchanged.
  MagnitudeFitStart fit;
  if (!StartMagnitudeFit(positions, initial, gravity, options, "refinement", &fit, result)) {
    return false;
  }
  // sigma_k^2 + s^2: the per-pose variance the samples cannot show.
  for (double& s : result->sigmas) s = std::sqrt(s * s + options.extra_variance);
  const std::vector<double> scales = LossScales(options, *result);
  ceres::Problem::Options problem_options;
  problem_options.enable_fast_removal = false;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  // For speed: the blocks below are built correctly by construction, so
  // Ceres's checks of them are pure overhead (results are bit-identical).
  problem_options.disable_all_safety_checks = true;
  MagnitudeProblem m(problem_options);
  AddMagnitudeBlocks(fit, gravity, options, scales, result->sigmas, &m);
  if (!HoldParameters(fit, options, &m, result)) return false;
  ceres::Solver::Summary summary;
  SolveGraduated(options, scales, &m, &summary, result);

  AccelModel refined_n = fit.normalized_model;
  refined_n.bias = Eigen::Vector3d(m.bias[0], m.bias[1], m.bias[2]);
  refined_n.SetUpper(m.upper);
  const AccelModel refined = fit.norm.Undo(refined_n);
  const bool usable = summary.IsSolutionUsable() && refined.bias.allFinite() &&
                      refined.upper.allFinite() && refined.upper.diagonal().minCoeff() > 0.0;
  result->converged = usable && summary.termination_type == ceres::CONVERGENCE;
  if (!usable) {
    result->model = fit.model;
    result->message = "refinement failed: " + summary.message + "; the coarse result is kept";
    return true;
  }
  result->model = refined;
  result->residuals_after = MagnitudeResiduals(positions, refined, gravity);
  result->chi2 = WhitenedSumOfSquares(result->residuals_after, result->sigmas);
  result->final_cost = 0.5 * result->chi2;
  result->dof = fit.num_positions - fit.num_parameters +
                static_cast<int>(std::count(m.held_column.begin(), m.held_column.end(), true));
  const int num_active = AnalyzeActiveObservability(fit, refined_n, m.held_column, result);

  Eigen::MatrixXd cov;
  if (options.compute_covariance &&
      !NormalizedCovariance(fit, num_active - result->observability.rank, &m, &cov)) {
    internal::AddWarning(WarningCode::kNoCovariance,
                         "the covariance could not be computed (the problem is rank deficient); "
                         "no standard deviations are reported",
                         &result->warnings, &result->warning_codes);
  } else if (options.compute_covariance) {
    AddHeldSpread(fit, refined_n, m.held_column, options, result->sigmas, &cov);
    result->covariance = fit.norm.Undo(cov);
    result->covariance_available = true;
    const std::vector<std::string> weak = WeakParameters(options, cov, m.held_column, result);
    std::string listed;
    for (const std::string& name : weak) listed += (listed.empty() ? "" : ", ") + name;
    // Only when something is left to fit.
    if (!weak.empty() && static_cast<int>(weak.size()) < num_active) {
      // Hold the flat directions at their initial (coarse) value and fit
      // the rest again. The free fit's other sigmas are inflated by the
      // near-singular directions through a linearisation that is poor
      // there (a term determined only to second order); the refit's are
      // conditional on the held values, and are reported as such, with the
      // held terms named (core/conditional_sigmas.h).
      // One term at a time, the weakest first: holding it can make the
      // others determined (an exact fit on near-singular poses shows every
      // term weak while one or two flat directions cause it).
      // When that refit stalls (the free fit may have stalled on the flat
      // directions too), every weak term is held at once.
      // A non-orthogonality term is held at zero (the nominal: a term the
      // poses cannot see is not taken from the coarse fit, whose value for
      // it can be far off); any other at the coarse fit's value.
      RefinementOptions again = options;
      again.held_parameters.push_back(Weakest(options, cov, weak, *result));
      AccelModel start = initial;
      ZeroHeldCrossTerms(again.held_parameters, &start);
      const double first_seconds = result->solve_seconds;
      const int first_iterations = result->iterations;
      if (!RefineHoldingWeak(positions, start, gravity, again, false, result)) return false;
      if (!result->converged && weak.size() > 1) {
        again = options;
        again.held_parameters.insert(again.held_parameters.end(), weak.begin(), weak.end());
        start = initial;
        ZeroHeldCrossTerms(again.held_parameters, &start);
        if (!RefineHoldingWeak(positions, start, gravity, again, false, result)) return false;
      }
      result->solve_seconds += first_seconds;
      result->iterations += first_iterations;
      if (outermost) {
        // Every term the refits held (not the caller's own held_parameters).
        std::vector<std::string> held;
        for (const std::string& name : result->observability.undetermined) {
          const auto& own = options.held_parameters;
          if (std::find(own.begin(), own.end(), name) == own.end()) held.push_back(name);
        }
        std::string names;
        for (const std::string& name : held) names += (names.empty() ? "" : ", ") + name;
        internal::AddWarning(WarningCode::kUndetermined,
                             "the positions do not determine " + names +
                                 " (standard deviation beyond max_bias_std / max_matrix_std); "
                                 "they are held (a non-orthogonality term at zero, any other at "
                                 "the coarse fit's value) and reported without a number, and "
                                 "every other standard deviation is conditional on holding them "
                                 "(with their spread up to that limit): add positions with other "
                                 "axes up or down",
                             &result->warnings, &result->warning_codes);
      }
      return true;
    }
    if (!weak.empty()) {
      internal::AddWarning(WarningCode::kUndetermined,
                           "the positions do not determine " + listed +
                               " (standard deviation beyond max_bias_std / max_matrix_std); "
                               "they are reported without a number: add positions with other "
                               "axes up or down",
                           &result->warnings, &result->warning_codes);
    }
  }
  internal::WarnOnChiSquare(result);

  std::ostringstream s;
  s << (result->converged ? "converged" : "did not converge") << " after " << result->iterations
    << " iterations (" << result->termination << "): " << summary.message;
  result->message = s.str();
  return true;
}

}  // namespace

}  // namespace gravcal
