// Private: the restricted-maximum-likelihood (REML) estimate of one extra
// variance s^2 added to every residual's variance.
//
// Model: the residuals r (n) of a least-squares fit with Jacobian J (n x p,
// unwhitened, at the optimum) are r_k = e_k + (J d)_k, e ~ N(0, V),
//   V = diag(sigma_k^2 + s^2),
// with sigma_k the known (white-noise) standard deviation of residual k and
// s^2 >= 0 the unknown common variance the samples cannot show. The
// restricted log-likelihood does not depend on the fitted parameters d:
//
//   l_R(s^2) = -1/2 [ sum_k log(sigma_k^2 + s^2) + log det(J^T V^-1 J) + r^T P r ],
//   P = V^-1 - V^-1 J (J^T V^-1 J)^-1 J^T V^-1.
//
// Computed through an orthonormal basis K (n x m, m = n - rank J) of the
// space orthogonal to the columns of J, with e = K^T r and A = K^T diag(sigma^2) K
// = Q diag(d) Q^T, f = Q^T e (up to a constant independent of s^2):
//
//   l_R(s^2) = -1/2 sum_i [ log(d_i + s^2) + f_i^2 / (d_i + s^2) ].
//
// Unlike the plain maximum likelihood estimate, which divides the residual
// sum of squares by n and so comes out low by about p/n of the total
// variance, REML counts only the m = n - p directions the parameters leave
// free: it is not fooled by the parameters' own degrees of freedom.
//
// The standard deviation of s^2 is from the expected restricted information,
//
//   I(s^2) = 1/2 sum_i 1 / (d_i + s^2)^2,   std(s^2) = 1 / sqrt(I(s^2)),
//
// evaluated at the estimate (also at the boundary s^2 = 0, where it says how
// large an excess the data could have shown).
//
// A prior. With m = 1-3 (ten poses and nine parameters leave one) the
// likelihood alone says little about s^2. What a pose of a given kind of
// placement scatters by (a hand on a table, a fixture) can be stated as a
// scaled inverse chi-square prior with nu0 degrees of freedom at s0^2,
//
//   -2 log p(s^2) = nu0 log s^2 + nu0 s0^2 / s^2   (+ const),
//
// added to -2 l_R, so that the estimate is a compromise between s0^2 (weight
// nu0) and what the m residual directions show (about (nu0 s0^2 + sum f_i^2)
// / (nu0 + m) when the white part is small), and its information grows by
// nu0 / (2 s^4). nu0 = 0 (the default) is no prior: REML alone.
//
// An estimated s^2 makes every standard deviation itself an estimate, and
// error / sigma then follows a Student t rather than N(0, 1): with few
// residual degrees of freedom (three for twelve poses and nine parameters)
// its variance nu / (nu - 2) is far above 1. The total variance per residual
// direction, dbar + s^2 (dbar the mean of the d_i), rests on
//
//   nu = 2 (dbar + s^2)^2 / var(s^2)      (Satterthwaite)
//
// degrees of freedom: nu -> m when s^2 dominates, nu -> infinity when the
// white part does. StudentInflation gives nu / (nu - 2), the factor that
// makes the variance of error / sigma one, with nu held at kMinEffectiveDof
// or above (at most a factor 3): below three degrees of freedom no factor
// makes the variance finite, and a warning says so instead.
#ifndef GRAVCAL_SRC_ESTIMATION_VARIANCE_COMPONENT_H_
#define GRAVCAL_SRC_ESTIMATION_VARIANCE_COMPONENT_H_

#include <Eigen/Core>

#include "gravcal/core/solver_result.h"

namespace gravcal {
namespace internal {

// `residuals` r_k and `sigmas` sigma_k (same unit), `jacobian` dr/dparameters
// unwhitened (n x p; columns of any scale, rank decided after scaling each to
// unit norm). Returns false (result->message says why) when n - rank(J) < 1
// or an input is not finite or a sigma is not positive.
struct VariancePrior {
  // s0^2 and nu0 (above); dof = 0 is no prior.
  double variance = 0.0;
  double dof = 0.0;
};

bool EstimateVarianceComponent(const Eigen::VectorXd& residuals, const Eigen::VectorXd& sigmas,
                               const Eigen::MatrixXd& jacobian, VarianceComponent* result,
                               const VariancePrior& prior = VariancePrior());

// The same for correlated residuals whose known (white) covariance is not
// diagonal and an extra variance that enters only some of them with a
// shape: with W the whitening of the known covariance (W Sigma W^T = I),
// `residuals` = W r and `jacobian` = W J, and `shape` = W E W^T, E the
// extra covariance per unit s^2 (zero rows for residuals it does not
// enter, such as priors):
//
//   V = I + s^2 D,   D = shape.
//
// With B = K^T D K = Q diag(lambda) Q^T and g = Q^T K^T r, every free
// direction with lambda_i > 0 is the diagonal problem above with d_i =
// 1 / lambda_i and f_i^2 = g_i^2 / lambda_i (up to a constant); directions
// with lambda_i = 0 do not depend on s^2. dof counts the others.
// *known_variance (when not null) receives the mean of those d_i: the
// known variance per direction in s^2's unit, the dbar of StudentInflation
// (with priors among the residuals it includes what they allow, which the
// white sensor noise alone would leave out).
bool EstimateWhitenedVarianceComponent(const Eigen::VectorXd& residuals,
                                       const Eigen::MatrixXd& jacobian,
                                       const Eigen::MatrixXd& shape, VarianceComponent* result,
                                       const VariancePrior& prior = VariancePrior(),
                                       double* known_variance = nullptr);

// The prior predictive upper tail of a white-weighted chi-square on `dof`
// (dof >= 1) when s^2 has the prior above and adds s^2 h to every
// residual's variance in chi2's units (h = 1 / sigma^2 for equal sigmas):
// with s^2 = nu0 s0^2 / X, X ~ chi2(nu0), chi2 = (1 + s^2 h) Y, Y ~ chi2(dof),
//
//   P(chi2_rep > chi2) = E_X[ Q_dof( chi2 / (1 + nu0 s0^2 h / X) ) ],
//
// Q_dof the chi-square upper tail, integrated over log X. When s^2 h >> 1
// it is the F(dof, nu0) tail of (chi2 / dof) / (s0^2 h); unlike that it
// counts the white part, which a prior far below it cannot move. 1 when
// there is no prior.
double PriorPredictiveUpperTail(double chi2, int dof, const VariancePrior& prior, double h);

constexpr double kMinEffectiveDof = 3.0;

// nu / (nu - 2) for an estimated component (1 when s^2 = 0 or not
// estimated), nu from Satterthwaite as above with dbar =
// mean_white_variance; *effective_dof receives nu (infinity for none).
double StudentInflation(const VarianceComponent& component, double mean_white_variance,
                        double* effective_dof);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_ESTIMATION_VARIANCE_COMPONENT_H_
