#include "gravcal/core/gyro_model.h"

#include <Eigen/LU>

namespace gravcal {

Eigen::Vector3d GyroModel::Invert(const Eigen::Vector3d& rate) const {
  return Eigen::Vector3d(matrix.partialPivLu().solve(rate)) + bias;
}

GyroModel GyroModel::Random(double nominal_scale, double scale_std, double misalignment_std,
                            double bias_std, std::mt19937_64* rng) {
  std::normal_distribution<double> n01(0.0, 1.0);
  GyroModel model;
  for (int i = 0; i < 3; ++i) {
    model.bias(i) = bias_std * n01(*rng);
    for (int j = 0; j < 3; ++j) {
      model.matrix(i, j) = i == j ? nominal_scale * (1.0 + scale_std * n01(*rng))
                                  : nominal_scale * misalignment_std * n01(*rng);
    }
  }
  return model;
}

}  // namespace gravcal
