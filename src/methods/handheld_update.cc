// The zero-velocity, zero-position pseudo-measurement update of the
// handheld filter (handheld_filter.h) and its closed-loop feedback.
#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include "estimation/strapdown.h"
#include "methods/handheld_filter.h"
#include "util/so3.h"

namespace gravcal {
namespace internal {

double HandheldFilter::Update() {
  const NavigationState& nav = strapdown_.state();
  const Mat3& c = strapdown_.attitude_matrix();
  // The point held still: the sensor, or with a lever arm r the point the
  // unit turns about, at p - C r with velocity v - C (w x r). To first
  // order (u = C (w x r)):
  //   z_v = dv - [u x] phi - C [r x] (I+E_g)^-1 (db_g + dE_g w) - C [w x] dr
  //   z_p = dp - [(C r) x] phi - C dr
  const Vec3 u = c * rate_.cross(lever_);
  Eigen::Matrix<double, 6, 1> z;
  z << nav.velocity - u, nav.position - c * lever_;
  h_.setZero();
  h_.block<3, 3>(0, 3).setIdentity();
  h_.block<3, 3>(3, 6).setIdentity();
  const int lever = layout_.offset(StateBlock::kLeverArm);
  if (layout_.block_size(StateBlock::kLeverArm) > 0) {
    h_.block<3, 3>(0, 0) = -Skew(u);
    h_.block<3, 3>(3, 0) = -Skew(c * lever_);
    const Mat3 kr = -c * Skew(lever_) * gyro_.inverse;
    h_.block<3, 3>(0, layout_.offset(StateBlock::kGyroBias)) = kr;
    const int gm = layout_.offset(StateBlock::kGyroMatrix);
    for (size_t j = 0; j < layout_.gyro().matrix_entries.size(); ++j) {
      const auto [r, col] = layout_.gyro().matrix_entries[j];
      h_.block<3, 1>(0, gm + static_cast<int>(j)) = kr.col(r) * rate_(col);
    }
    h_.block<3, 3>(0, lever) = -c * Skew(rate_);
    h_.block<3, 3>(3, lever) = -c;
  }
  Eigen::Matrix<double, 6, 1> r;
  r << Vec3::Constant(options_.velocity_noise * options_.velocity_noise),
      Vec3::Constant(options_.position_noise * options_.position_noise);
  const Eigen::Matrix<double, Eigen::Dynamic, 6> pht = p_ * h_.transpose();
  Eigen::Matrix<double, 6, 6> s = h_ * pht;
  s.diagonal() += r;
  const Eigen::LLT<Eigen::Matrix<double, 6, 6>> llt(s);
  const Eigen::Matrix<double, Eigen::Dynamic, 6> k = llt.solve(pht.transpose()).transpose();
  const double nis = z.dot(llt.solve(z));
  const Eigen::VectorXd x = k * z;
  // Joseph form: P = (I - K H) P (I - K H)^T + K R K^T.
  joseph_.setIdentity();
  joseph_.noalias() -= k * h_;
  Eigen::MatrixXd p = joseph_ * p_ * joseph_.transpose();
  p.noalias() += k * r.asDiagonal() * k.transpose();
  p_ = 0.5 * (p + p.transpose());
  Feedback(x);
  return nis;
}

void HandheldFilter::Feedback(const Eigen::VectorXd& x) {
  NavigationState nav = strapdown_.state();
  nav.attitude = RotationVectorToQuaternion(x.head<3>()) * nav.attitude;
  nav.velocity -= x.segment<3>(3);
  nav.position -= x.segment<3>(6);
  strapdown_.SetState(nav);
  accel_.bias -= x.segment<3>(layout_.offset(StateBlock::kAccelBias));
  gyro_.bias -= x.segment<3>(layout_.offset(StateBlock::kGyroBias));
  const int am = layout_.offset(StateBlock::kAccelMatrix);
  for (size_t j = 0; j < layout_.accel().matrix_entries.size(); ++j) {
    const auto [r, c] = layout_.accel().matrix_entries[j];
    accel_.e(r, c) -= x(am + static_cast<int>(j));
  }
  const int gm = layout_.offset(StateBlock::kGyroMatrix);
  for (size_t j = 0; j < layout_.gyro().matrix_entries.size(); ++j) {
    const auto [r, c] = layout_.gyro().matrix_entries[j];
    gyro_.e(r, c) -= x(gm + static_cast<int>(j));
  }
  if (layout_.block_size(StateBlock::kLeverArm) > 0) {
    lever_ -= x.segment<3>(layout_.offset(StateBlock::kLeverArm));
  }
  accel_.Refresh();
  gyro_.Refresh();
}

}  // namespace internal
}  // namespace gravcal
