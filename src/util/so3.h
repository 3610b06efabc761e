// util/so3.h: the small rotation helpers the estimators share.
#ifndef GRAVCAL_SRC_UTIL_SO3_H_
#define GRAVCAL_SRC_UTIL_SO3_H_

#include <Eigen/Core>

namespace gravcal {
namespace internal {

// The cross-product matrix: Skew(v) * w = v x w.
//
//            [  0   -v_z   v_y ]
//   [v]_x =  [ v_z   0    -v_x ]
//            [-v_y   v_x   0   ]
inline Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d s;
  s << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return s;
}

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_UTIL_SO3_H_
