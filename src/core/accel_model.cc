#include "gravcal/core/accel_model.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/QR>
#include <cmath>

#include "gravcal/core/imu_model.h"
#include "util/random_vector.h"

namespace gravcal {

int NumParameters(AccelParameterization p) {
  switch (p) {
    case AccelParameterization::kScale:
      return 6;
    case AccelParameterization::kScaleMisalignment:
      return 9;
    case AccelParameterization::kAffine:
      return 12;
  }
  return 0;
}

Eigen::Vector3d AccelModel::Apply(const Eigen::Vector3d& raw) const {
  double u[6];
  GetUpper(u);
  AccelBlocks<double> blocks;
  blocks.bias = bias.data();
  blocks.upper = u;
  blocks.rotation = &rotation;
  Eigen::Vector3d a;
  ImuModel<double>(blocks).CorrectAccel(raw, 0.0, 0.0, a.data());
  return a;
}

Eigen::Vector3d AccelModel::Invert(const Eigen::Vector3d& specific_force) const {
  // U is triangular: back-substitution, no general inverse.
  const Eigen::Vector3d w = rotation.transpose() * specific_force;
  return Eigen::Vector3d(upper.triangularView<Eigen::Upper>().solve(w)) + bias;
}

void AccelModel::GetUpper(double* u6) const {
  u6[0] = upper(0, 0);
  u6[1] = upper(0, 1);
  u6[2] = upper(0, 2);
  u6[3] = upper(1, 1);
  u6[4] = upper(1, 2);
  u6[5] = upper(2, 2);
}

void AccelModel::SetUpper(const double* u6) {
  upper << u6[0], u6[1], u6[2], 0.0, u6[3], u6[4], 0.0, 0.0, u6[5];
}

bool AccelModel::FromMatrix(const Eigen::Vector3d& bias, const Eigen::Matrix3d& m,
                            AccelParameterization p, AccelModel* model) {
  // The sign of det(M) from M / max|m_ij|, which does not underflow for a
  // well-conditioned M of tiny scale (det(1e-120 I) is 0 in double).
  const double scale = m.cwiseAbs().maxCoeff();
  if (!m.allFinite() || !bias.allFinite() || !(scale > 0.0) || (m / scale).determinant() <= 0.0) {
    return false;
  }
  const Eigen::HouseholderQR<Eigen::Matrix3d> qr(m);
  Eigen::Matrix3d q = qr.householderQ();
  Eigen::Matrix3d r = qr.matrixQR().triangularView<Eigen::Upper>();
  // Make diag(R) positive: M = (Q S)(S R) with S = diag(+-1).
  for (int i = 0; i < 3; ++i) {
    if (r(i, i) < 0.0) {
      r.row(i) *= -1.0;
      q.col(i) *= -1.0;
    }
  }
  if (r.diagonal().minCoeff() <= 0.0) return false;
  model->parameterization = p;
  model->bias = bias;
  model->upper = r;
  model->rotation = q;
  return true;
}

AccelModel AccelModel::Random(AccelParameterization p, double nominal_scale, double scale_std,
                              double misalignment_std, double bias_std, std::mt19937_64* rng) {
  std::normal_distribution<double> n01(0.0, 1.0);
  AccelModel model;
  model.parameterization = p;
  for (int i = 0; i < 3; ++i) {
    model.bias(i) = bias_std * n01(*rng);
    model.upper(i, i) = nominal_scale * (1.0 + scale_std * n01(*rng));
  }
  if (p != AccelParameterization::kScale) {
    model.upper(0, 1) = nominal_scale * misalignment_std * n01(*rng);
    model.upper(0, 2) = nominal_scale * misalignment_std * n01(*rng);
    model.upper(1, 2) = nominal_scale * misalignment_std * n01(*rng);
  }
  if (p == AccelParameterization::kAffine) {
    const Eigen::Vector3d angles =
        misalignment_std * internal::DrawVector3([&] { return n01(*rng); });
    model.rotation =
        Eigen::AngleAxisd(angles.norm(), angles.norm() > 0.0 ? Eigen::Vector3d(angles.normalized())
                                                             : Eigen::Vector3d::UnitX())
            .toRotationMatrix();
  }
  return model;
}

}  // namespace gravcal
