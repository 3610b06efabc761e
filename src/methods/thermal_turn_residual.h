// methods/thermal_turn_residual.h (private): the residual of one turn
// between two static poses of a thermal session, the layout of the turn
// fit's parameters (the equations are in thermal_turns.h) and the dense
// Jacobian and covariance helpers of that fit.
#ifndef GRAVCAL_METHODS_THERMAL_TURN_RESIDUAL_H_
#define GRAVCAL_METHODS_THERMAL_TURN_RESIDUAL_H_

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>

#include "gravcal/core/thermal_model.h"
#include "methods/thermal_turns.h"

namespace gravcal {
namespace internal {

// The orders of the turn fit's terms and the accelerometer frame entries it
// fits, with the parameter layout [M_g (9), scale (3 x scale), misalignment
// (6 x misalignment), frame (one per fitted entry of N)].
struct TurnLayout {
  int scale = 0;
  int misalignment = 0;
  // Which of N's entries n01, n02, n12 are fitted.
  std::array<bool, 3> frame = {false, false, false};
  int frames() const { return frame[0] + frame[1] + frame[2]; }
  int size() const { return 9 + 3 * scale + 6 * misalignment + frames(); }
  int scale_at() const { return 9; }
  int misalignment_at() const { return 9 + 3 * scale; }
  int frame_at() const { return 9 + 3 * scale + 6 * misalignment; }
};

// e = E (R^T d_s' - d_e') / sigma for one turn (header), with
// d' = N d / |N d|.
class TurnResidual final {
 public:
  TurnResidual(const ThermalTurn& turn, const TurnLayout& layout, double sigma)
      : turn_(turn), layout_(layout), inv_sigma_(1.0 / sigma) {
    // E: two unit vectors orthogonal to d_e.
    const Eigen::Vector3d d = turn.to;
    Eigen::Vector3d a = std::abs(d.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
    a = (a - d * d.dot(a)).normalized();
    basis_.row(0) = a.transpose();
    basis_.row(1) = d.cross(a).transpose();
  }

  template <typename T>
  bool operator()(T const* const* parameters, T* residuals) const {
    const T* m = parameters[0];
    ThermalBlocks<T> blocks;
    blocks.sensor = ThermalSensor::kGyro;
    blocks.scale = layout_.scale > 0 ? m + layout_.scale_at() : nullptr;
    blocks.scale_order = layout_.scale;
    blocks.misalignment = layout_.misalignment > 0 ? m + layout_.misalignment_at() : nullptr;
    blocks.misalignment_order = layout_.misalignment;
    // A = (I + D_g(x))^-1 M_g, column by column.
    T a[9];
    for (int j = 0; j < 3; ++j) {
      T c[3] = {m[j], m[3 + j], m[6 + j]};
      blocks.RemoveScale(turn_.x, c);
      for (int i = 0; i < 3; ++i) a[3 * i + j] = c[i];
    }
    // R = prod_k exp([A u_k]^) in doubles at A's value A0, and its first
    // order change with A, R(A0 + dA) = R exp([G vec(dA)]^) (vec row-major):
    // G accumulates over the increments as G <- E_k^T G + J_r(theta_k) U_k,
    // E_k = exp([theta_k]^), theta_k = A0 u_k, U_k = d theta_k / d vec(A)
    // and J_r the right Jacobian of exp, J_r(th) = I - (1 - cos t) / t^2
    // [th]^ + (t - sin t) / t^3 [th]^2, t = |th|. The value is the one a
    // product of Jets gives; the derivative is exact (first order is all
    // a Jet carries), at a 16th of the Jet product's cost.
    double a0[9];
    for (int k = 0; k < 9; ++k) a0[k] = ValueOf(a[k]);
    double r0[9] = {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};
    Eigen::Matrix<double, 3, 9> g = Eigen::Matrix<double, 3, 9>::Zero();
    for (const Eigen::Vector3d& u : turn_.increments) {
      double angle[3];
      for (int i = 0; i < 3; ++i) {
        angle[i] = a0[3 * i] * u.x() + a0[3 * i + 1] * u.y() + a0[3 * i + 2] * u.z();
      }
      double e[9];
      ceres::AngleAxisToRotationMatrix(angle, ceres::RowMajorAdapter3x3(e));
      double n[9];
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
          n[3 * i + j] = r0[3 * i] * e[j] + r0[3 * i + 1] * e[3 + j] + r0[3 * i + 2] * e[6 + j];
        }
      }
      std::copy(n, n + 9, r0);
      const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> em(e);
      const Eigen::Map<const Eigen::Vector3d> th(angle);
      const Eigen::Matrix3d jr = RightJacobian(th);
      Eigen::Matrix<double, 3, 9> next = em.transpose() * g;
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) next.col(3 * i + j) += jr.col(i) * u(j);
      }
      g = next;
    }
    T phi[3];
    for (int i = 0; i < 3; ++i) {
      phi[i] = T(0.0);
      for (int k = 0; k < 9; ++k) phi[i] += g(i, k) * (a[k] - T(a0[k]));
    }
    // R (I + [phi]^), [phi]^ = [[0, -p2, p1], [p2, 0, -p0], [-p1, p0, 0]].
    const T hat[9] = {T(0.0), -phi[2], phi[1], phi[2], T(0.0), -phi[0], -phi[1], phi[0], T(0.0)};
    T r[9];
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        r[3 * i + j] = T(r0[3 * i + j]) + r0[3 * i] * hat[j] + r0[3 * i + 1] * hat[3 + j] +
                       r0[3 * i + 2] * hat[6 + j];
      }
    }
    // N = I + the fitted strictly upper entries (n01, n02, n12).
    T n[3] = {T(0.0), T(0.0), T(0.0)};
    for (int k = 0, at = layout_.frame_at(); k < 3; ++k) {
      if (layout_.frame[k]) n[k] = m[at++];
    }
    T from[3], to[3];
    Frame(turn_.from, n, from);
    Frame(turn_.to, n, to);
    T v[3];
    for (int j = 0; j < 3; ++j) {
      v[j] = r[j] * from[0] + r[3 + j] * from[1] + r[6 + j] * from[2] - to[j];
    }
    for (int i = 0; i < 2; ++i) {
      residuals[i] =
          (basis_(i, 0) * v[0] + basis_(i, 1) * v[1] + basis_(i, 2) * v[2]) * T(inv_sigma_);
    }
    return true;
  }

 private:
  static double ValueOf(double v) { return v; }
  template <int N>
  static double ValueOf(const ceres::Jet<double, N>& v) {
    return v.a;
  }

  // J_r(th) (above); its series below t = 1e-4.
  static Eigen::Matrix3d RightJacobian(const Eigen::Vector3d& th) {
    const double t2 = th.squaredNorm();
    const double t = std::sqrt(t2);
    const double c1 = t < 1e-4 ? 0.5 - t2 / 24.0 : (1.0 - std::cos(t)) / t2;
    const double c2 = t < 1e-4 ? 1.0 / 6.0 - t2 / 120.0 : (t - std::sin(t)) / (t2 * t);
    Eigen::Matrix3d k;
    k << 0.0, -th.z(), th.y(), th.z(), 0.0, -th.x(), -th.y(), th.x(), 0.0;
    return Eigen::Matrix3d::Identity() - c1 * k + c2 * k * k;
  }

  // out = N d / |N d|.
  template <typename T>
  static void Frame(const Eigen::Vector3d& d, const T* n, T* out) {
    out[0] = d.x() + n[0] * d.y() + n[1] * d.z();
    out[1] = d.y() + n[2] * d.z();
    out[2] = T(d.z());
    using std::sqrt;
    const T norm = sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2]);
    for (int i = 0; i < 3; ++i) out[i] = out[i] / norm;
  }

  const ThermalTurn& turn_;
  const TurnLayout layout_;
  const double inv_sigma_;
  Eigen::Matrix<double, 2, 3> basis_;
};

// The Jacobian of `problem`'s residuals at its parameters, dense.
inline Eigen::MatrixXd TurnDenseJacobian(ceres::Problem* problem) {
  ceres::CRSMatrix crs;
  problem->Evaluate(ceres::Problem::EvaluateOptions(), nullptr, nullptr, nullptr, &crs);
  Eigen::MatrixXd j = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int row = 0; row < crs.num_rows; ++row) {
    for (int at = crs.rows[row]; at < crs.rows[row + 1]; ++at) {
      j(row, crs.cols[at]) = crs.values[at];
    }
  }
  return j;
}

// (J^T J)^-1 with column scaling; a direction J leaves open gets an
// infinite (1e30) variance.
inline Eigen::MatrixXd TurnScaledInverse(Eigen::MatrixXd j) {
  Eigen::VectorXd d = j.colwise().norm().transpose();
  for (int c = 0; c < d.size(); ++c) {
    if (!(d(c) > 0.0)) d(c) = 1.0;
    j.col(c) /= d(c);
  }
  const Eigen::MatrixXd info = j.transpose() * j;
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(info, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::VectorXd sv = svd.singularValues();
  Eigen::VectorXd inv = Eigen::VectorXd::Zero(sv.size());
  for (int i = 0; i < sv.size(); ++i) inv(i) = sv(i) > 1e-12 * sv(0) ? 1.0 / sv(i) : 1e30;
  return d.cwiseInverse().asDiagonal() *
         (svd.matrixV() * inv.asDiagonal() * svd.matrixU().transpose()) *
         d.cwiseInverse().asDiagonal();
}

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_METHODS_THERMAL_TURN_RESIDUAL_H_
