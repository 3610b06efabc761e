#include "estimation/variance_component.h"

#include <glog/logging.h>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "util/statistics.h"

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

// An orthonormal basis (n x m) of the m = n - rank(J) directions the
// parameters leave free (the rank of J with its columns scaled to unit
// norm, so the parameters' units do not decide it). False when m < 1.
bool Complement(const Eigen::MatrixXd& jacobian, Eigen::MatrixXd* basis,
                VarianceComponent* result) {
  const int n = static_cast<int>(jacobian.rows());
  Eigen::MatrixXd scaled = jacobian;
  for (int j = 0; j < scaled.cols(); ++j) {
    const double norm = scaled.col(j).norm();
    if (norm > 0.0) scaled.col(j) /= norm;
  }
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr;
  if (scaled.cols() > 0) {
    qr.setThreshold(1e-10);
    qr.compute(scaled);
  }
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
  *basis = q.rightCols(m);
  return true;
}

// Projects the residuals onto the free directions: d_i and f_i^2 of the
// header. False when there are none.
bool Restrict(const Eigen::VectorXd& residuals, const Eigen::VectorXd& sigmas,
              const Eigen::MatrixXd& jacobian, RestrictedProblem* problem,
              VarianceComponent* result) {
  Eigen::MatrixXd k;
  if (!Complement(jacobian, &k, result)) return false;
  const Eigen::VectorXd e = k.transpose() * residuals;
  const Eigen::MatrixXd a = k.transpose() * sigmas.array().square().matrix().asDiagonal() * k;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(a);
  problem->d = eigen.eigenvalues().cwiseMax(0.0);
  problem->f2 = (eigen.eigenvectors().transpose() * e).array().square().matrix();
  return true;
}

// The whitened form (header): B = K^T D K = Q diag(lambda) Q^T, g = Q^T K^T r;
// each direction with lambda_i > 0 is d_i = 1 / lambda_i, f_i^2 = g_i^2 /
// lambda_i; those with lambda_i = 0 do not depend on s^2 and are left out
// (result->dof counts the others).
bool RestrictWhitened(const Eigen::VectorXd& residuals, const Eigen::MatrixXd& jacobian,
                      const Eigen::MatrixXd& shape, RestrictedProblem* problem,
                      VarianceComponent* result) {
  Eigen::MatrixXd k;
  if (!Complement(jacobian, &k, result)) return false;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(k.transpose() * shape * k);
  const Eigen::VectorXd lambda = eigen.eigenvalues();
  const Eigen::VectorXd g = eigen.eigenvectors().transpose() * (k.transpose() * residuals);
  const double tolerance = 1e-10 * std::max(lambda.maxCoeff(), 0.0);
  std::vector<int> kept;
  for (int i = 0; i < lambda.size(); ++i) {
    if (lambda(i) > tolerance && lambda(i) > 0.0) kept.push_back(i);
  }
  result->dof = static_cast<int>(kept.size());
  if (kept.empty()) {
    result->message = "no free direction of the residuals is moved by the extra variance";
    return false;
  }
  problem->d.resize(kept.size());
  problem->f2.resize(kept.size());
  for (size_t j = 0; j < kept.size(); ++j) {
    problem->d(j) = 1.0 / lambda(kept[j]);
    problem->f2(j) = g(kept[j]) * g(kept[j]) / lambda(kept[j]);
  }
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

// The estimate from the restricted problem: s^2, its standard deviation and
// the message (result->dof already set).
void Estimate(const RestrictedProblem& problem, const VariancePrior& prior,
              VarianceComponent* result) {
  const int m = static_cast<int>(problem.d.size());
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
  Estimate(problem, prior, result);
  return true;
}

bool EstimateWhitenedVarianceComponent(const Eigen::VectorXd& residuals,
                                       const Eigen::MatrixXd& jacobian,
                                       const Eigen::MatrixXd& shape, VarianceComponent* result,
                                       const VariancePrior& prior, double* known_variance) {
  CHECK(result != nullptr);
  *result = VarianceComponent();
  const int n = static_cast<int>(residuals.size());
  if (!CheckInput(residuals, Eigen::VectorXd::Ones(n), jacobian, prior, result)) return false;
  if (shape.rows() != n || shape.cols() != n || !shape.allFinite()) {
    result->message = "the extra variance's shape must be finite and n x n";
    return false;
  }
  RestrictedProblem problem;
  if (!RestrictWhitened(residuals, jacobian, shape, &problem, result)) return false;
  Estimate(problem, prior, result);
  if (known_variance != nullptr) *known_variance = problem.d.mean();
  return true;
}

double PriorPredictiveUpperTail(double chi2, int dof, const VariancePrior& prior, double h) {
  if (!(prior.dof > 0.0) || dof < 1) return 1.0;
  // Trapezoid over t = log X, density of t: f(e^t) e^t. X from 1e-12 nu0
  // (far below any prior's tail of interest) to the mean plus 40 sd.
  const double lo = std::log(1e-12 * prior.dof);
  const double hi = std::log(prior.dof + 40.0 * std::sqrt(2.0 * prior.dof) + 10.0);
  const int kSteps = 2000;
  const double step = (hi - lo) / kSteps;
  double sum = 0.0, weight = 0.0;
  for (int i = 0; i <= kSteps; ++i) {
    const double x = std::exp(lo + i * step);
    const double w = ChiSquareDensity(x, prior.dof) * x * (i == 0 || i == kSteps ? 0.5 : 1.0);
    sum += w * ChiSquareUpperTail(chi2 / (1.0 + prior.dof * prior.variance * h / x), dof);
    weight += w;
  }
  return weight > 0.0 ? sum / weight : 1.0;
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
