#include "estimation/variance_component.h"

#include <glog/logging.h>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <sstream>

namespace gravcal {
namespace internal {

namespace {

// The eigen-decomposed restricted problem of the header: d_i and f_i^2.
struct RestrictedProblem {
  Eigen::VectorXd d;
  Eigen::VectorXd f2;
};

// -2 (l_R(t) + log p(t)) up to a constant (see the header), t = s^2.
double Objective(const RestrictedProblem& r, const VariancePrior& prior, double t) {
  double sum = 0.0;
  for (int i = 0; i < r.d.size(); ++i) sum += std::log(r.d(i) + t) + r.f2(i) / (r.d(i) + t);
  if (prior.dof > 0.0) {
    if (!(t > 0.0)) return INFINITY;
    sum += prior.dof * (std::log(t) + prior.variance / t);
  }
  return sum;
}

bool CheckInput(const Eigen::VectorXd& residuals, const Eigen::VectorXd& sigmas,
                const Eigen::MatrixXd& jacobian, const VariancePrior& prior,
                VarianceComponent* result) {
  const int n = static_cast<int>(residuals.size());
  if (sigmas.size() != n || jacobian.rows() != n) {
    result->message = "residuals, sigmas and the Jacobian's rows differ in number";
    return false;
  }
  if (!residuals.allFinite() || !sigmas.allFinite() || !jacobian.allFinite() ||
      (n > 0 && !(sigmas.minCoeff() > 0.0))) {
    result->message = "residuals, sigmas and the Jacobian must be finite and the sigmas positive";
    return false;
  }
  if (!(prior.dof >= 0.0) || !(prior.variance >= 0.0) || !std::isfinite(prior.dof) ||
      !std::isfinite(prior.variance) || (prior.dof > 0.0 && !(prior.variance > 0.0))) {
    result->message = "the prior needs dof >= 0 and, with dof > 0, a positive variance";
    return false;
  }
  return true;
}

// Projects the residuals onto the m = n - rank(J) directions the parameters
// leave free (the rank of J with its columns scaled to unit norm, so the
// parameters' units do not decide it). False when m < 1.
bool Restrict(const Eigen::VectorXd& residuals, const Eigen::VectorXd& sigmas,
              const Eigen::MatrixXd& jacobian, RestrictedProblem* problem,
              VarianceComponent* result) {
  const int n = static_cast<int>(residuals.size());
  Eigen::MatrixXd scaled = jacobian;
  for (int j = 0; j < scaled.cols(); ++j) {
    const double norm = scaled.col(j).norm();
    if (norm > 0.0) scaled.col(j) /= norm;
  }
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(scaled);
  qr.setThreshold(1e-10);
  const int rank = scaled.cols() > 0 ? static_cast<int>(qr.rank()) : 0;
  const int m = n - rank;
  result->dof = m;
  if (m < 1) {
    std::ostringstream s;
    s << n << " residuals and " << rank
      << " determined parameters leave no degree of freedom to estimate an extra variance";
    result->message = s.str();
    return false;
  }
  Eigen::MatrixXd q = Eigen::MatrixXd::Identity(n, n);
  if (rank > 0) q = qr.householderQ() * Eigen::MatrixXd::Identity(n, n);
  const Eigen::MatrixXd k = q.rightCols(m);
  const Eigen::VectorXd e = k.transpose() * residuals;
  const Eigen::MatrixXd a = k.transpose() * sigmas.array().square().matrix().asDiagonal() * k;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(a);
  problem->d = eigen.eigenvalues().cwiseMax(0.0);
  problem->f2 = (eigen.eigenvectors().transpose() * e).array().square().matrix();
  return true;
}

// The minimum of the objective over t >= 0. It can have more than one
// minimum: a logarithmic grid (and t = 0) is scanned, then the best is
// refined by golden section in log t.
double Minimise(const RestrictedProblem& r, const VariancePrior& prior) {
  const double floor = std::max(r.d.maxCoeff(), 1e-300);
  const double top = std::max({10.0 * r.f2.maxCoeff(), 10.0 * prior.variance, floor});
  const double lo = std::log(1e-8 * floor), hi = std::log(top);
  const int kGrid = 80;
  double best_u = lo, best = Objective(r, prior, 0.0);
  bool interior = false;
  for (int i = 0; i <= kGrid; ++i) {
    const double u = lo + (hi - lo) * i / kGrid;
    const double v = Objective(r, prior, std::exp(u));
    if (v < best) {
      best = v;
      best_u = u;
      interior = true;
    }
  }
  if (!interior) return 0.0;
  const double step = (hi - lo) / kGrid;
  double x0 = best_u - step, x3 = best_u + step;
  const double g = 0.5 * (3.0 - std::sqrt(5.0));
  double x1 = x0 + g * (x3 - x0), x2 = x3 - g * (x3 - x0);
  double f1 = Objective(r, prior, std::exp(x1));
  double f_2 = Objective(r, prior, std::exp(x2));
  for (int it = 0; it < 200 && x3 - x0 > 1e-10; ++it) {
    if (f1 < f_2) {
      x3 = x2;
      x2 = x1;
      f_2 = f1;
      x1 = x0 + g * (x3 - x0);
      f1 = Objective(r, prior, std::exp(x1));
    } else {
      x0 = x1;
      x1 = x2;
      f1 = f_2;
      x2 = x3 - g * (x3 - x0);
      f_2 = Objective(r, prior, std::exp(x2));
    }
  }
  const double t = std::exp(0.5 * (x0 + x3));
  // The excess is real only where it beats the boundary.
  return Objective(r, prior, t) < Objective(r, prior, 0.0) ? t : 0.0;
}

}  // namespace

bool EstimateVarianceComponent(const Eigen::VectorXd& residuals, const Eigen::VectorXd& sigmas,
                               const Eigen::MatrixXd& jacobian, VarianceComponent* result,
                               const VariancePrior& prior) {
  CHECK(result != nullptr);
  *result = VarianceComponent();
  if (!CheckInput(residuals, sigmas, jacobian, prior, result)) return false;
  RestrictedProblem problem;
  if (!Restrict(residuals, sigmas, jacobian, &problem, result)) return false;
  const int m = result->dof;
  const double t = Minimise(problem, prior);
  double information = 0.0;
  for (int i = 0; i < m; ++i) {
    information += 0.5 / ((problem.d(i) + t) * (problem.d(i) + t));
  }
  if (prior.dof > 0.0 && t > 0.0) information += 0.5 * prior.dof / (t * t);
  result->estimated = true;
  result->variance = t;
  result->variance_std = 1.0 / std::sqrt(information);
  result->at_boundary = t == 0.0;
  std::ostringstream s;
  s.precision(3);
  if (result->at_boundary) {
    s << "no excess over the white-noise sigmas (s^2 = 0 at the boundary, std "
      << result->variance_std << ", " << m << " dof)";
  } else {
    s << "s = " << std::sqrt(t) << " (s^2 = " << t << " +- " << result->variance_std << ", " << m
      << " dof";
    if (prior.dof > 0.0) s << ", prior s0 = " << std::sqrt(prior.variance) << " on " << prior.dof;
    s << ")";
  }
  result->message = s.str();
  return true;
}

double StudentInflation(const VarianceComponent& component, double mean_white_variance,
                        double* effective_dof) {
  double nu = INFINITY;
  if (component.estimated && component.variance > 0.0 && component.variance_std > 0.0) {
    const double total = mean_white_variance + component.variance;
    nu = 2.0 * total * total / (component.variance_std * component.variance_std);
  }
  if (effective_dof != nullptr) *effective_dof = nu;
  if (!std::isfinite(nu)) return 1.0;
  const double held = std::max(nu, kMinEffectiveDof);
  return held / (held - 2.0);
}

}  // namespace internal
}  // namespace gravcal
