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
bool EstimateVarianceComponent(const Eigen::VectorXd& residuals, const Eigen::VectorXd& sigmas,
                               const Eigen::MatrixXd& jacobian, VarianceComponent* result);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_ESTIMATION_VARIANCE_COMPONENT_H_
