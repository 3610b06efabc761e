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

// -2 l_R(t) up to a constant (see the header), t = s^2.
double MinusTwoLogLikelihood(const Eigen::VectorXd& d, const Eigen::VectorXd& f2, double t) {
  double sum = 0.0;
  for (int i = 0; i < d.size(); ++i) sum += std::log(d(i) + t) + f2(i) / (d(i) + t);
  return sum;
}

}  // namespace

bool EstimateVarianceComponent(const Eigen::VectorXd& residuals, const Eigen::VectorXd& sigmas,
                               const Eigen::MatrixXd& jacobian, VarianceComponent* result) {
  CHECK(result != nullptr);
  *result = VarianceComponent();
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
  // The rank of J with its columns scaled to unit norm (the parameters'
  // units do not decide it).
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
  const Eigen::VectorXd d = eigen.eigenvalues().cwiseMax(0.0);
  const Eigen::VectorXd f2 = (eigen.eigenvectors().transpose() * e).array().square().matrix();

  // -2 l_R can have more than one minimum in t: scan a logarithmic grid
  // (and t = 0), then refine the best by golden section in log t.
  const double floor = std::max(d.maxCoeff(), 1e-300);
  const double top = std::max(10.0 * f2.maxCoeff(), floor);
  const double lo = std::log(1e-8 * floor), hi = std::log(top);
  const int kGrid = 80;
  double best_u = lo, best = MinusTwoLogLikelihood(d, f2, 0.0);
  bool interior = false;
  for (int i = 0; i <= kGrid; ++i) {
    const double u = lo + (hi - lo) * i / kGrid;
    const double v = MinusTwoLogLikelihood(d, f2, std::exp(u));
    if (v < best) {
      best = v;
      best_u = u;
      interior = true;
    }
  }
  double t = 0.0;
  if (interior) {
    const double step = (hi - lo) / kGrid;
    double x0 = best_u - step, x3 = best_u + step;
    const double g = 0.5 * (3.0 - std::sqrt(5.0));
    double x1 = x0 + g * (x3 - x0), x2 = x3 - g * (x3 - x0);
    double f1 = MinusTwoLogLikelihood(d, f2, std::exp(x1));
    double f_2 = MinusTwoLogLikelihood(d, f2, std::exp(x2));
    for (int it = 0; it < 200 && x3 - x0 > 1e-10; ++it) {
      if (f1 < f_2) {
        x3 = x2;
        x2 = x1;
        f_2 = f1;
        x1 = x0 + g * (x3 - x0);
        f1 = MinusTwoLogLikelihood(d, f2, std::exp(x1));
      } else {
        x0 = x1;
        x1 = x2;
        f1 = f_2;
        x2 = x3 - g * (x3 - x0);
        f_2 = MinusTwoLogLikelihood(d, f2, std::exp(x2));
      }
    }
    t = std::exp(0.5 * (x0 + x3));
    // The excess is real only where it beats the boundary.
    if (!(MinusTwoLogLikelihood(d, f2, t) < MinusTwoLogLikelihood(d, f2, 0.0))) t = 0.0;
  }
  double information = 0.0;
  for (int i = 0; i < m; ++i) information += 0.5 / ((d(i) + t) * (d(i) + t));
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
      << " dof)";
  }
  result->message = s.str();
  return true;
}

}  // namespace internal
}  // namespace gravcal
