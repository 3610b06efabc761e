// Private: the noise of a measured gravity direction, as the rotations
// gyroscope calibration weighs it. A direction d = a / |a| with a = M (v - b)
// has its covariance in the plane perpendicular to d; the residuals live in
// that plane (two tangent rows) and are whitened with W, W C W^T = I.
#ifndef GRAVCAL_SRC_METHODS_DIRECTION_NOISE_H_
#define GRAVCAL_SRC_METHODS_DIRECTION_NOISE_H_

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace gravcal {
namespace internal {

// W with W C W^T = I: the inverse of the lower Cholesky factor of C.
template <int N>
bool SqrtInformation(const Eigen::Matrix<double, N, N>& c, Eigen::Matrix<double, N, N>* w) {
  Eigen::LLT<Eigen::Matrix<double, N, N>> llt(c);
  if (llt.info() != Eigen::Success) return false;
  *w = llt.matrixL().solve(Eigen::Matrix<double, N, N>::Identity());
  return w->allFinite();
}

// Covariance of d = a / |a|, a = M (v - b), from the covariance of v.
inline Eigen::Matrix3d DirectionCovariance(const Eigen::Matrix3d& m, const Eigen::Vector3d& a,
                                           const Eigen::Matrix3d& raw_cov) {
  const Eigen::Vector3d d = a.normalized();
  const Eigen::Matrix3d p = (Eigen::Matrix3d::Identity() - d * d.transpose()) / a.norm();
  return p * m * raw_cov * m.transpose() * p.transpose();
}

// Two orthonormal rows perpendicular to the unit vector d.
inline Eigen::Matrix<double, 2, 3> TangentBasis(const Eigen::Vector3d& d) {
  int least = 0;
  d.cwiseAbs().minCoeff(&least);
  const Eigen::Vector3d e1 = d.cross(Eigen::Vector3d::Unit(least)).normalized();
  const Eigen::Vector3d e2 = d.cross(e1);
  Eigen::Matrix<double, 2, 3> basis;
  basis.row(0) = e1.transpose();
  basis.row(1) = e2.transpose();
  return basis;
}

// The rotation matrix of a (w, x, y, z) quaternion, as the integrated
// gyroscope rotation (gyro_rotation_residual.h) stores it.
inline Eigen::Matrix3d RotationOf(const double* q) {
  return Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
}

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_METHODS_DIRECTION_NOISE_H_
