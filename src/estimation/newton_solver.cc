#include "estimation/newton_solver.h"

#include <Eigen/Cholesky>
#include <chrono>
#include <cmath>
#include <sstream>

#include "estimation/magnitude_fit.h"
#include "estimation/normalization.h"
#include "util/statistics.h"

namespace gravcal {
namespace internal {

using internal::MagnitudeFitStart;
using internal::Normalization;
using internal::StartMagnitudeFit;
using internal::WhitenedSumOfSquares;

bool NewtonOptions::IsValid(std::string* error) const {
  if (max_iterations < 1) {
    *error = "max_iterations: must be at least 1";
    return false;
  }
  if (!(step_tolerance > 0.0)) {
    *error = "step_tolerance: must be positive";
    return false;
  }
  return true;
}

namespace {

// Residuals and Jacobian of the chosen form at `model`, rows whitened.
void Linearise(const std::vector<Position>& positions, const AccelModel& model, double gravity,
               const std::vector<double>& sigmas, NewtonResidual form, const std::vector<int>& free,
               Eigen::VectorXd* f, Eigen::MatrixXd* j) {
  const int n = static_cast<int>(positions.size());
  f->resize(n);
  j->resize(n, 3 + free.size());
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector3d d = positions[k].raw_mean - model.bias;
    const Eigen::Vector3d a = model.upper * d;
    const double norm = a.norm();
    // Gradient of |a| (magnitude form) or |a|^2 (seed form) with respect to a.
    Eigen::Vector3d da;
    double w;
    if (form == NewtonResidual::kMagnitude) {
      w = 1.0 / sigmas[k];
      (*f)(k) = w * (norm - gravity);
      da = a / norm;
    } else {
      w = 1.0 / (2.0 * gravity * sigmas[k]);
      (*f)(k) = w * (a.squaredNorm() - gravity * gravity);
      da = 2.0 * a;
    }
    j->block(k, 0, 1, 3) = -w * (da.transpose() * model.upper);
    const double all[6] = {da(0) * d(0), da(0) * d(1), da(0) * d(2),
                           da(1) * d(1), da(1) * d(2), da(2) * d(2)};
    for (size_t i = 0; i < free.size(); ++i) (*j)(k, 3 + i) = w * all[free[i]];
  }
}

}  // namespace

bool NewtonRefine(const std::vector<Position>& positions, const AccelModel& initial, double gravity,
                  const NewtonOptions& options, RefinementResult* result) {
  MagnitudeFitStart fit;
  if (!StartMagnitudeFit(positions, initial, gravity, options, "Newton refinement", &fit, result)) {
    return false;
  }
  const std::vector<int>& free = fit.free;
  const int num_parameters = fit.num_parameters;
  const int n = fit.num_positions;
  // Iterate in well-conditioned units (normalization.h).
  const Normalization& norm = fit.norm;
  const std::vector<Position>& normalized = fit.normalized;
  AccelModel model = fit.normalized_model;
  std::string error;
  const auto start = std::chrono::steady_clock::now();
  Eigen::VectorXd f;
  Eigen::MatrixXd j;
  bool converged = false;
  int iteration = 0;
  std::string termination = "NO_CONVERGENCE";
  for (; iteration < options.max_iterations && !converged; ++iteration) {
    Linearise(normalized, model, gravity, result->sigmas, options.residual, free, &f, &j);
    const Eigen::MatrixXd jtj = j.transpose() * j;
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(jtj);
    const Eigen::VectorXd diag = ldlt.vectorD().cwiseAbs();
    if (ldlt.info() != Eigen::Success || !(diag.minCoeff() > 1e-14 * diag.maxCoeff())) {
      termination = "FAILURE";
      error = "the normal equations are singular: the positions do not determine the model";
      break;
    }
    const Eigen::VectorXd dx = ldlt.solve(-j.transpose() * f);
    if (!dx.allFinite()) {
      termination = "FAILURE";
      error = "the step is not finite";
      break;
    }
    Eigen::VectorXd x(num_parameters);
    x.head<3>() = model.bias;
    double u[kUpperSize];
    model.GetUpper(u);
    for (size_t i = 0; i < free.size(); ++i) x(3 + i) = u[free[i]];
    converged = true;
    for (int i = 0; i < num_parameters; ++i) {
      if (std::fabs(dx(i)) > options.step_tolerance * (std::fabs(x(i)) + options.step_tolerance)) {
        converged = false;
      }
    }
    x += dx;
    model.bias = x.head<3>();
    for (size_t i = 0; i < free.size(); ++i) u[free[i]] = x(3 + i);
    model.SetUpper(u);
    if (converged) termination = "CONVERGENCE";
  }
  result->solve_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result->iterations = iteration;
  result->termination = termination;
  const bool usable = termination != "FAILURE" && model.bias.allFinite() &&
                      model.upper.allFinite() && model.upper.diagonal().minCoeff() > 0.0;
  result->converged = usable && converged;
  if (!usable) {
    result->model = initial;
    result->message = "Newton iteration failed: " + error + "; the coarse result is kept";
    return true;
  }
  const Eigen::MatrixXd jm = MagnitudeJacobian(normalized, model, result->sigmas);
  model = norm.Undo(model);
  result->model = model;
  result->residuals_after = MagnitudeResiduals(positions, model, gravity);
  result->chi2 = WhitenedSumOfSquares(result->residuals_after, result->sigmas);
  result->final_cost = 0.5 * result->chi2;
  result->dof = n - num_parameters;
  result->observability = AnalyzeObservability(jm, result->parameter_names);
  if (options.compute_covariance && result->observability.full_rank()) {
    const Eigen::MatrixXd jtj = jm.transpose() * jm;
    result->covariance = norm.Undo(Eigen::MatrixXd(
        jtj.ldlt().solve(Eigen::MatrixXd::Identity(num_parameters, num_parameters))));
    result->covariance_available = result->covariance.allFinite();
  }
  internal::WarnOnChiSquare(result);
  std::ostringstream s;
  s << (result->converged ? "converged" : "did not converge") << " after " << iteration
    << " Newton iterations (" << ToString(options.residual) << " residual)";
  result->message = s.str();
  return true;
}

}  // namespace internal
}  // namespace gravcal
