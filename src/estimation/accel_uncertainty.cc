#include "estimation/accel_uncertainty.h"

#include <Eigen/Geometry>
#include <cmath>

#include "util/so3.h"

namespace gravcal {
namespace internal {

void PropagateUncertainty(const RefinementResult& refinement, const HousingRotation* housing,
                          AccelCalibration* accel) {
  const AccelModel& model = accel->model;
  const std::vector<int> free = FreeUpperIndices(model.parameterization);
  const int nm = refinement.num_parameters;
  const int nr = housing != nullptr ? 3 : 0;
  const int np = nm + nr;
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(np, np);
  cov.topLeftCorner(nm, nm) = refinement.covariance;
  if (housing != nullptr) cov.bottomRightCorner(3, 3) = housing->angle_covariance;
  accel->covariance = cov;
  accel->covariance_names = refinement.parameter_names;
  if (housing != nullptr) {
    for (const char* name : {"rot_x", "rot_y", "rot_z"}) accel->covariance_names.push_back(name);
  }
  // Jacobian of (b, vec(M)) with respect to the parameters.
  Eigen::MatrixXd j = Eigen::MatrixXd::Zero(12, np);
  j.topLeftCorner<3, 3>().setIdentity();
  static const int kRow[6] = {0, 0, 0, 1, 1, 2};
  static const int kCol[6] = {0, 1, 2, 1, 2, 2};
  for (size_t i = 0; i < free.size(); ++i) {
    Eigen::Matrix3d e = Eigen::Matrix3d::Zero();
    e(kRow[free[i]], kCol[free[i]]) = 1.0;
    const Eigen::Matrix3d dm = model.rotation * e;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) j(3 + 3 * r + c, 3 + i) = dm(r, c);
    }
  }
  if (housing != nullptr) {
    const Eigen::Matrix3d m = model.matrix();
    for (int a = 0; a < 3; ++a) {
      const Eigen::Matrix3d dm = internal::Skew(Eigen::Vector3d::Unit(a)) * m;
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) j(3 + 3 * r + c, nm + a) = dm(r, c);
      }
    }
  }
  const Eigen::MatrixXd out = j * cov * j.transpose();
  // An entry is estimated when some parameter moves it.
  for (int i = 0; i < 3; ++i) accel->bias_std(i) = std::sqrt(out(i, i));
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      const int row = 3 + 3 * r + c;
      accel->matrix_std(r, c) = j.row(row).squaredNorm() > 0.0 ? std::sqrt(out(row, row)) : NAN;
    }
  }
  // Parameters in a null direction are not determined: no number.
  for (const std::string& name : refinement.observability.undetermined) {
    if (name.rfind("bias_", 0) == 0) {
      accel->bias_std(name[5] - 'x') = NAN;
    } else if (name.rfind("u_", 0) == 0) {
      // U(r, c) moves column c of M = R U: just that entry when R = I.
      if (housing == nullptr) {
        accel->matrix_std(name[2] - 'x', name[3] - 'x') = NAN;
      } else {
        accel->matrix_std.col(name[3] - 'x').setConstant(NAN);
      }
    }
  }
}

}  // namespace internal
}  // namespace gravcal
