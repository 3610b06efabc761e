// gravcal/util/hat.h: the cross-product matrix, written once for every
// scalar (double, and Ceres' Jet inside autodiff residuals). The model
// (core/imu_model.h) and the private rotation helpers (src/util/so3.h) use
// this one definition.
#ifndef GRAVCAL_UTIL_HAT_H_
#define GRAVCAL_UTIL_HAT_H_

#include <Eigen/Core>

namespace gravcal {

// The cross-product matrix: Hat(v) w = v x w.
//
//            [  0   -v_z   v_y ]
//   [v]_x =  [ v_z   0    -v_x ]
//            [-v_y   v_x   0   ]
template <typename T>
Eigen::Matrix<T, 3, 3> Hat(const Eigen::Matrix<T, 3, 1>& v) {
  Eigen::Matrix<T, 3, 3> s;
  s << T(0.0), -v(2), v(1), v(2), T(0.0), -v(0), -v(1), v(0), T(0.0);
  return s;
}

}  // namespace gravcal

#endif  // GRAVCAL_UTIL_HAT_H_
