// gravcal/core/gyro_model.h: the gyroscope error model.
//
//   w = M_g (u - b_g)
//
// u is the raw gyroscope reading (any units), b_g its bias in raw units, w
// the angular rate in rad/s in the body frame. M_g holds scale factors on the
// diagonal and misalignment off it (a full 3x3 matrix: the accelerometer frame
// fixes the gauge). All zero errors = identity mapping.
#ifndef GRAVCAL_CORE_GYRO_MODEL_H_
#define GRAVCAL_CORE_GYRO_MODEL_H_

#include <Eigen/Core>
#include <random>

namespace gravcal {

struct GyroModel {
  Eigen::Vector3d bias = Eigen::Vector3d::Zero();
  Eigen::Matrix3d matrix = Eigen::Matrix3d::Identity();

  // w = M_g (u - b_g).
  Eigen::Vector3d Apply(const Eigen::Vector3d& raw) const { return matrix * (raw - bias); }
  // u = M_g^-1 w + b_g.
  Eigen::Vector3d Invert(const Eigen::Vector3d& rate) const;

  // Scale = nominal_scale * (1 + N(0, scale_std)), off-diagonal
  // N(0, misalignment_std) * nominal_scale, bias N(0, bias_std) raw units.
  static GyroModel Random(double nominal_scale, double scale_std, double misalignment_std,
                          double bias_std, std::mt19937_64* rng);
};

}  // namespace gravcal

#endif  // GRAVCAL_CORE_GYRO_MODEL_H_
