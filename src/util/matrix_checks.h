// util/matrix_checks.h (private): checks on small covariance matrices.
#ifndef GRAVCAL_SRC_UTIL_MATRIX_CHECKS_H_
#define GRAVCAL_SRC_UTIL_MATRIX_CHECKS_H_

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

namespace gravcal {
namespace internal {

// True when the symmetric matrix is finite and safely positive definite:
// its largest eigenvalue is positive and its smallest above 1e-12 times it.
inline bool IsSafelyPositiveDefinite(const Eigen::Matrix3d& m) {
  if (!m.allFinite()) return false;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(m, Eigen::EigenvaluesOnly);
  const Eigen::Vector3d ev = eig.eigenvalues();
  return ev[2] > 0.0 && ev[0] > 1e-12 * ev[2];
}

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_UTIL_MATRIX_CHECKS_H_
