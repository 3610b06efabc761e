#include "methods/handheld_filter.h"

#include <Eigen/Geometry>
#include <cmath>

#include "util/so3.h"

namespace gravcal {
namespace internal {
namespace {

using Mat3 = HandheldFilter::Mat3;
using Vec3 = HandheldFilter::Vec3;

// The transition of one IMU step on the navigation error rows, A_k =
//   [[I - dt W,        0,            0],
//    [dt [(C f) x],    I - 2 dt W,   0],
//    [0,               dt I,         I]]      (W = [w_ie x]),
// applied to the rows of a 9-row matrix: x <- A_k x.
struct NavigationStep {
  double dt = 0.0;
  Mat3 velocity_from_attitude;  // dt [(C f) x]
  bool earth_rate = false;
  Mat3 attitude_attitude;  // I - dt W
  Mat3 velocity_velocity;  // I - 2 dt W

  template <typename Matrix>
  void Apply(Matrix* x) const {
    auto phi = x->template topRows<3>();
    auto vel = x->template middleRows<3>(3);
    auto pos = x->template bottomRows<3>();
    pos += dt * vel;
    if (earth_rate) {
      const Eigen::Matrix<double, 3, Matrix::ColsAtCompileTime> v_old = vel;
      vel.noalias() = velocity_velocity * v_old;
      vel.noalias() += velocity_from_attitude * phi;
      const Eigen::Matrix<double, 3, Matrix::ColsAtCompileTime> phi_old = phi;
      phi.noalias() = attitude_attitude * phi_old;
    } else {
      vel.noalias() += velocity_from_attitude * phi;
    }
  }
};

StrapdownOptions StrapdownFor(const HandheldKalmanOptions& options, double gravity) {
  StrapdownOptions s;
  s.gravity = gravity;
  s.earth_rate = options.earth_rate;
  s.latitude_deg = options.gravity.latitude;
  return s;
}

}  // namespace

HandheldFilter::HandheldFilter(const HandheldKalmanOptions& options, double gravity,
                               const ErrorStateLayout& layout)
    : options_(options), layout_(layout), strapdown_(StrapdownFor(options, gravity)) {
  const int n = layout_.size();
  p_.setZero(n, n);
  b_.setZero(9, n - 9);
  a_.setIdentity();
  q_.setZero();
  joseph_.setZero(n, n);
  h_.setZero(6, n);
}

void HandheldFilter::Initialize(const Vec3& f_mean, const HandheldSensorEstimate& accel,
                                const HandheldSensorEstimate& gyro) {
  accel_ = accel;
  gyro_ = gyro;
  lever_.setZero();
  rate_.setZero();
  const Vec3 f0 = accel_.Correct(f_mean);
  const Eigen::Quaterniond q0 = LevelAttitude(f0);
  NavigationState start;
  start.attitude = q0;
  strapdown_.SetState(start);
  const int n = layout_.size();
  Eigen::VectorXd prior(n);
  auto set = [&](StateBlock block, double std) {
    prior.segment(layout_.offset(block), layout_.block_size(block)).setConstant(std * std);
  };
  set(StateBlock::kAttitude, options_.initial_attitude_std);
  set(StateBlock::kVelocity, options_.velocity_noise);
  set(StateBlock::kPosition, options_.position_noise);
  set(StateBlock::kAccelBias, options_.accel_bias_std);
  set(StateBlock::kGyroBias, options_.gyro_bias_std);
  auto set_matrix = [&](StateBlock block, const SensorErrorTerms& terms, double scale_std) {
    const int offset = layout_.offset(block);
    for (size_t j = 0; j < terms.matrix_entries.size(); ++j) {
      const bool diagonal = terms.matrix_entries[j].first == terms.matrix_entries[j].second;
      const double std = diagonal ? scale_std : options_.cross_axis_std;
      prior(offset + static_cast<int>(j)) = std * std;
    }
  };
  set_matrix(StateBlock::kAccelMatrix, layout_.accel(), options_.accel_scale_std);
  set_matrix(StateBlock::kGyroMatrix, layout_.gyro(), options_.gyro_scale_std);
  if (layout_.block_size(StateBlock::kLeverArm) > 0) {
    set(StateBlock::kLeverArm, options_.lever_arm_std);
  }
  // phi = phi_independent + L C0 df, df = -(I + E)^-1 (db_a + dE_a f0),
  // with phi_x = -(C0 df)_y / g and phi_y = (C0 df)_x / g.
  const double g = f0.norm();
  Mat3 l = Mat3::Zero();
  l(0, 1) = -1.0 / g;
  l(1, 0) = 1.0 / g;
  const Mat3 lc = l * q0.toRotationMatrix() * accel_.inverse;
  Eigen::MatrixXd t = Eigen::MatrixXd::Identity(n, n);
  t.block<3, 3>(0, layout_.offset(StateBlock::kAccelBias)) = -lc;
  const int am = layout_.offset(StateBlock::kAccelMatrix);
  for (size_t j = 0; j < layout_.accel().matrix_entries.size(); ++j) {
    const auto [r, c] = layout_.accel().matrix_entries[j];
    t.block<3, 1>(0, am + static_cast<int>(j)) = -lc.col(r) * f0(c);
  }
  // With a lever arm the navigation origin is the turning point and the
  // sensor starts at C0 r, estimated 0: dp0 = -C0 r = C0 dr.
  if (layout_.block_size(StateBlock::kLeverArm) > 0) {
    t.block<3, 3>(6, layout_.offset(StateBlock::kLeverArm)) = q0.toRotationMatrix();
  }
  p_ = t * prior.asDiagonal() * t.transpose();
  p_initial_ = p_;
}

void HandheldFilter::Step(double dt, const Vec3& f0_m, const Vec3& w0_m, const Vec3& f1_m,
                          const Vec3& w1_m) {
  const Vec3 f0 = accel_.Correct(f0_m);
  const Vec3 f1 = accel_.Correct(f1_m);
  const Vec3 w0 = gyro_.Correct(w0_m);
  const Vec3 w1 = gyro_.Correct(w1_m);
  StrapdownStep s;
  strapdown_.Step(dt, f0, w0, f1, w1, &s);
  rate_ = w1;
  Accumulate(s);
  elapsed_ += dt;
}

void HandheldFilter::Propagate() {
  const int ns = layout_.size() - 9;
  const Mat9 pnn = p_.topLeftCorner<9, 9>();
  const Mat9X pns = p_.topRightCorner(9, ns);
  const Eigen::MatrixXd& full = p_;
  Mat9X t2 = a_ * pns;
  t2.noalias() += b_ * full.bottomRightCorner(ns, ns);
  Mat9 t1 = a_ * pnn;
  t1.noalias() += b_ * pns.transpose();
  Mat9 new_nn = t1 * a_.transpose();
  new_nn.noalias() += t2 * b_.transpose();
  p_.topLeftCorner<9, 9>() = new_nn + q_;
  p_.topRightCorner(9, ns) = t2;
  p_.bottomLeftCorner(ns, 9) = t2.transpose();
  const double walk[2] = {options_.accel_bias_walk, options_.gyro_bias_walk};
  const StateBlock bias[2] = {StateBlock::kAccelBias, StateBlock::kGyroBias};
  for (int s = 0; s < 2; ++s) {
    if (walk[s] <= 0.0) continue;
    const int o = layout_.offset(bias[s]);
    for (int i = 0; i < 3; ++i) p_(o + i, o + i) += walk[s] * walk[s] * elapsed_;
  }
  a_.setIdentity();
  b_.setZero();
  q_.setZero();
  elapsed_ = 0.0;
}

void HandheldFilter::Accumulate(const StrapdownStep& s) {
  const double dt = s.dt;
  const Mat3 ka = s.attitude_mid * accel_.inverse;
  const Mat3 kg = s.attitude_mid * gyro_.inverse;
  NavigationStep step;
  step.dt = dt;
  step.velocity_from_attitude = dt * Skew(s.attitude_mid * s.specific_force_mid);
  const Vec3& w_ie = strapdown_.earth_rate();
  if (w_ie.squaredNorm() > 0.0) {
    step.earth_rate = true;
    step.attitude_attitude = Mat3::Identity() - dt * Skew(w_ie);
    step.velocity_velocity = Mat3::Identity() - 2.0 * dt * Skew(w_ie);
  }
  step.Apply(&a_);
  step.Apply(&b_);
  step.Apply(&q_);
  q_.transposeInPlace();
  step.Apply(&q_);
  // Sensor columns of this step: B += B_k.
  const int ab = layout_.offset(StateBlock::kAccelBias) - 9;
  const int am = layout_.offset(StateBlock::kAccelMatrix) - 9;
  const int gb = layout_.offset(StateBlock::kGyroBias) - 9;
  const int gm = layout_.offset(StateBlock::kGyroMatrix) - 9;
  b_.block<3, 3>(3, ab) -= dt * ka;
  for (size_t j = 0; j < layout_.accel().matrix_entries.size(); ++j) {
    const auto [r, c] = layout_.accel().matrix_entries[j];
    b_.block<3, 1>(3, am + static_cast<int>(j)) -= (dt * s.specific_force_mid(c)) * ka.col(r);
  }
  b_.block<3, 3>(0, gb) += dt * kg;
  for (size_t j = 0; j < layout_.gyro().matrix_entries.size(); ++j) {
    const auto [r, c] = layout_.gyro().matrix_entries[j];
    b_.block<3, 1>(0, gm + static_cast<int>(j)) += (dt * s.rate_mid(c)) * kg.col(r);
  }
  const double ga = options_.accel_noise_density;
  const double gg = options_.gyro_noise_density;
  q_.topLeftCorner<3, 3>().noalias() += (gg * gg * dt) * kg * kg.transpose();
  q_.block<3, 3>(3, 3).noalias() += (ga * ga * dt) * ka * ka.transpose();
}

bool HandheldFilter::Healthy() const {
  return p_.allFinite() && strapdown_.state().velocity.allFinite() &&
         p_.diagonal().minCoeff() >= 0.0;
}

double HandheldFilter::SensorValue(int state) const {
  const int ab = layout_.offset(StateBlock::kAccelBias);
  const int am = layout_.offset(StateBlock::kAccelMatrix);
  const int gb = layout_.offset(StateBlock::kGyroBias);
  const int gm = layout_.offset(StateBlock::kGyroMatrix);
  const int lever = layout_.offset(StateBlock::kLeverArm);
  if (state >= lever) return lever_(state - lever);
  if (state >= gm) {
    const auto [r, c] = layout_.gyro().matrix_entries[state - gm];
    return gyro_.e(r, c);
  }
  if (state >= gb) return gyro_.bias(state - gb);
  if (state >= am) {
    const auto [r, c] = layout_.accel().matrix_entries[state - am];
    return accel_.e(r, c);
  }
  if (state >= ab) return accel_.bias(state - ab);
  return 0.0;
}

}  // namespace internal
}  // namespace gravcal
