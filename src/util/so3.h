// util/so3.h: the small rotation helpers the estimators and simulators share.
#ifndef GRAVCAL_SRC_UTIL_SO3_H_
#define GRAVCAL_SRC_UTIL_SO3_H_

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "gravcal/util/hat.h"

namespace gravcal {
namespace internal {

// The cross-product matrix Skew(v) * w = v x w (gravcal/util/hat.h), for
// any 3-vector expression.
inline Eigen::Matrix3d Skew(const Eigen::Vector3d& v) { return Hat<double>(v); }

// The rotation by `angle` (radians, right hand rule) about the unit `axis`.
inline Eigen::Quaterniond AxisAngle(double angle, const Eigen::Vector3d& axis) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis));
}

// The rotation exp([v]_x) by the rotation vector v = angle * axis, through
// the angle and the unit axis (the simulators' samples depend on these
// exact operations; strapdown's RotationVectorToQuaternion, with a series
// for tiny angles, is the integrator's).
inline Eigen::Quaterniond FromRotationVector(const Eigen::Vector3d& v) {
  const double angle = v.norm();
  if (angle == 0.0) return Eigen::Quaterniond::Identity();
  return AxisAngle(angle, v / angle);
}

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_UTIL_SO3_H_
