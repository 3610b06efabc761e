// gravcal/residuals/gyro_rotation_residual.h: the per-rotation Ceres residual of the
// gyroscope calibration between static poses (Tedaldi et al. 2014,
// docs/methods.md section 4), and the integrator it uses.
//
// Frames: the body frame is the calibrated accelerometer's (a = M_a (v - b_a),
// accel_model.h); the gyroscope model maps into it. A rotation k runs from
// static pose s to static pose e. Its gyroscope samples u_0 .. u_{n-1} at
// times t_0 .. t_{n-1} start with the last sample of pose s and end with the
// first sample of pose e, so the whole motion lies inside [t_0, t_{n-1}]
// (the unit is still at both ends: neither a time offset of the gyroscope
// nor its sampling phase changes the integral).
//
//   w_i   = M_g (u_i - b_g) - G f_i                         rad/s, body
//   phi_i = h_i (-w_{i-1} + 13 w_i + 13 w_{i+1} - w_{i+2}) / 24
//           + h_i^2 (w_i x w_{i+1}) / 12,  h_i = t_{i+1} - t_i    rad
//   dq    = exp(phi_0) * exp(phi_1) * ... * exp(phi_{n-2})
//   d^    = R(dq)^T d_s
//   r_k   = W_k E_k (d^ - d_e)                               2 values
//
// phi_i is the two-term Magnus expansion of the step with the rate
// interpolated by the cubic through four samples (the second term is the
// coning correction): fourth order in the sample interval, where the
// trapezoid rule is second order once the axis moves (at the first and last
// step, where the unit is still, the trapezoid is used). The cubic assumes
// evenly spaced samples. dq is the attitude of the body
// at pose e relative to pose s (Hamilton, q_e = q_s * dq). d_s and d_e are
// the unit directions of the specific force at the two poses, from the
// calibrated accelerometer: d = M_a (v - b_a) / |M_a (v - b_a)|. Since the
// specific force at rest is fixed in the navigation frame, f_e = R(dq)^T f_s:
// a right gyroscope model turns d_s into d_e. f_i is the calibrated specific
// force at sample i (m/s^2) and G (rad/s per m/s^2) the g-sensitivity.
// E_k (2x3) spans the plane perpendicular to d_e (fixed at the start), so
// E_k (d^ - d_e) is the direction error in rad to first order; W_k (2x2) is
// its square-root information from the noise of d_s, d_e and of the
// integrated gyroscope, so r_k is dimensionless with unit variance.
//
// Parameter blocks: b_g (3, raw units), M_g (9, row-major, rad/s per raw
// unit), optionally G (9, row-major), and for a joint accelerometer fit the
// accelerometer bias b_a (3) and upper-triangular U (6, accel_model.h; M_a =
// R U with the housing rotation R held). Without the accelerometer blocks
// d_s and d_e are constants.
#ifndef GRAVCAL_RESIDUALS_GYRO_ROTATION_RESIDUAL_H_
#define GRAVCAL_RESIDUALS_GYRO_ROTATION_RESIDUAL_H_

#include <ceres/autodiff_cost_function.h>
#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Core>
#include <cmath>
#include <cstring>
#include <mutex>
#include <utility>
#include <vector>

#include "gravcal/core/imu_model.h"

namespace gravcal {

// The data of one rotation, in the units the parameters use.
struct GyroRotationData {
  // Sample times (s) and raw gyroscope vectors of the rotation.
  std::vector<double> t;
  std::vector<Eigen::Vector3d> gyro;
  // Calibrated specific force at each sample, m/s^2 (for G; may be empty
  // when G is not estimated).
  std::vector<Eigen::Vector3d> force;
  // Start and end directions (unit), used when the accelerometer is fixed.
  Eigen::Vector3d start_direction = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d end_direction = Eigen::Vector3d::UnitZ();
  // Mean raw accelerometer vectors of the two poses, used by the joint fit.
  Eigen::Vector3d start_raw = Eigen::Vector3d::Zero();
  Eigen::Vector3d end_raw = Eigen::Vector3d::Zero();
  // Housing rotation R of the accelerometer (held in the joint fit).
  Eigen::Matrix3d accel_rotation = Eigen::Matrix3d::Identity();
  // E_k: rows span the plane perpendicular to the end direction.
  Eigen::Matrix<double, 2, 3> tangent = Eigen::Matrix<double, 2, 3>::Zero();
  // W_k: square-root information of E_k (d^ - d_e).
  Eigen::Matrix2d sqrt_information = Eigen::Matrix2d::Identity();
};

// The per-sample helpers below are forced inline into the integrators'
// loops: GCC left them as calls, and the two were a tenth of discovery's
// profile. Inlining keeps every operation and its order, so the bits.
#if defined(__GNUC__)
#define GRAVCAL_TURN_INLINE __attribute__((always_inline)) inline
#else
#define GRAVCAL_TURN_INLINE inline
#endif

// Weights of w_{i-1}, w_i, w_{i+1}, w_{i+2} in the first Magnus term of step
// i (0 <= i < n - 1) of the scheme above: the integral over [t_i, t_{i+1}]
// of the cubic through the four samples, h (-1, 13, 13, -1) / 24, and the
// trapezoid h (0, 1, 1, 0) / 2 at the first and last step. Summed over the
// steps every inner sample weighs h, as in the trapezoid rule, so the
// correction costs no noise.
GRAVCAL_TURN_INLINE void GyroStepWeights(const std::vector<double>& t, size_t i,
                                         double weights[4]) {
  const size_t n = t.size();
  const double h = t[i + 1] - t[i];
  const bool inner = i >= 1 && i + 2 < n;
  const double edge = inner ? -h / 24.0 : 0.0;
  weights[0] = edge;
  weights[1] = 0.5 * h - edge;
  weights[2] = 0.5 * h - edge;
  weights[3] = edge;
}

// w = M_g (u_i - b_g) - G f_i of sample i (G = 0 when g_sensitivity is null).
template <typename T>
GRAVCAL_TURN_INLINE void CalibratedGyroRate(const GyroRotationData& data, size_t i, const T* bias,
                                            const T* matrix, const T* g_sensitivity, T* w) {
  GyroBlocks<T> gyro;
  gyro.bias = bias;
  gyro.matrix = matrix;
  gyro.g_sensitivity = g_sensitivity;
  const double* force = g_sensitivity != nullptr ? data.force[i].data() : nullptr;
  ImuModel<T>(gyro).GyroRate(data.gyro[i], force, w);
}

// phi_i of step i (the scheme above) from the rates of samples i - 1 .. i + 2
// (before and after are read only at inner steps).
template <typename T>
GRAVCAL_TURN_INLINE void GyroStepRotation(const std::vector<double>& t, size_t i, const T* before,
                                          const T* a, const T* b, const T* after, T* phi) {
  const double h = t[i + 1] - t[i];
  double c[4];
  GyroStepWeights(t, i, c);
  const T coning(h * h / 12.0);
  for (int j = 0; j < 3; ++j) phi[j] = c[1] * a[j] + c[2] * b[j];
  if (c[0] != 0.0) {
    for (int j = 0; j < 3; ++j) phi[j] += c[0] * before[j] + c[3] * after[j];
  }
  phi[0] += coning * (a[1] * b[2] - a[2] * b[1]);
  phi[1] += coning * (a[2] * b[0] - a[0] * b[2]);
  phi[2] += coning * (a[0] * b[1] - a[1] * b[0]);
}

// Integrates the calibrated rate over the samples (the scheme above) into
// dq = (w, x, y, z). bias, matrix and g_sensitivity as in the parameter
// blocks; g_sensitivity may be null (G = 0). When path is not null it
// receives the attitude at every sample relative to the first (4 values per
// sample, data.t.size() samples).
template <typename T>
void IntegrateGyroRotation(const GyroRotationData& data, const T* bias, const T* matrix,
                           const T* g_sensitivity, T* dq, T* path = nullptr) {
  dq[0] = T(1.0);
  dq[1] = dq[2] = dq[3] = T(0.0);
  const size_t n = data.t.size();
  if (path != nullptr && n > 0) {
    for (int j = 0; j < 4; ++j) path[j] = dq[j];
  }
  if (n < 2) return;
  auto rate = [&](size_t i, T* w) {
    CalibratedGyroRate<T>(data, i, bias, matrix, g_sensitivity, w);
  };
  // w[k] holds the rate of sample i - 1 + k (k = 0..3), a window that
  // slides by one sample per step.
  T w[4][3];
  rate(0, w[1]);
  rate(1, w[2]);
  if (n > 2) rate(2, w[3]);
  for (int j = 0; j < 3; ++j) w[0][j] = w[1][j];
  for (size_t i = 0; i + 1 < n; ++i) {
    T phi[3];
    GyroStepRotation<T>(data.t, i, w[0], w[1], w[2], w[3], phi);
    T step[4], next[4];
    ceres::AngleAxisToQuaternion(phi, step);
    ceres::QuaternionProduct(dq, step, next);
    for (int j = 0; j < 4; ++j) dq[j] = next[j];
    if (path != nullptr) {
      for (int j = 0; j < 4; ++j) path[4 * (i + 1) + j] = dq[j];
    }
    // Slide the window.
    for (int k = 0; k < 3; ++k) {
      for (int j = 0; j < 3; ++j) w[k][j] = w[k + 1][j];
    }
    if (i + 3 < n) rate(i + 3, w[3]);
  }
}

// The turn dq of IntegrateGyroRotation (same values, same order of
// operations) and its Jacobian with respect to the parameters: columns 0-2
// b_g, 3-11 M_g and 12-20 G (both row-major; the G columns are zero when
// g_sensitivity is null).
//
// Automatic differentiation would carry every parameter through every
// sample. Instead, with S_i = exp(phi_{i+1}) * ... * exp(phi_{n-2}) the
// part of the turn after step i and J_r the right Jacobian of the
// exponential (exp(phi + d) = exp(phi) * exp(J_r(phi) d)),
//
//   d dq = dq * (0, e / 2),   e = sum_i R(S_i)^T J_r(phi_i) d phi_i,
//
// because S^* * (0, v) * S = (0, R(S)^T v). d phi_i is linear in the
// changes of the rates of the step's samples (weights c of GyroStepWeights,
// kappa = h^2 / 12 for the coning term):
//
//   d phi_i = sum_j c_j d w_{i-1+j} + kappa (d w_i x w_{i+1} + w_i x d w_{i+1}),
//
// so e = sum_k H_k d w_k, with H_k gathered from the steps that use sample
// k, and d w_k = -M_g d b_g + (d M_g)(u_k - b_g) - (d G) f_k. One pass
// forward for the steps, one backward for S_i and the H_k.
//
//   J_r(phi) = I - (1 - cos t) / t^2 [phi]x + (t - sin t) / t^3 [phi]x^2,  t = |phi|
//
// Each step costs one sincos(t / 2) (the step's quaternion; 1 - cos t is
// 2 sin^2(t / 2) from the same value) and, only for steps above 0.01 rad,
// one sin(t): sin t = 2 sin(t / 2) cos(t / 2) would round differently and
// change the bits of the fit. The buffers are kept per thread (or per
// GyroTurnCache), so a call allocates nothing once a turn that long has been
// seen.
inline void SinCos(double x, double* sine, double* cosine) {
#if defined(__GLIBC__)
  ::sincos(x, sine, cosine);
#else
  *sine = std::sin(x);
  *cosine = std::cos(x);
#endif
}

// The forward pass of a turn at one set of parameters: the rates w_k, the
// steps phi_i, their quaternions and sin(|phi_i| / 2), and the turn dq. The
// backward pass (the Jacobian) needs all of them; a plain evaluation makes
// them on its way to dq, so a residual that keeps them (GyroTurnCache)
// spends only the backward pass when the solver then asks for the Jacobian
// at the same parameters (it does after every accepted step).
struct GyroTurnForward {
  std::vector<Eigen::Vector3d> w;
  // The attitude at every sample relative to the first (path[0] = 1).
  std::vector<Eigen::Vector4d> path;
  std::vector<Eigen::Vector3d> phi;
  std::vector<Eigen::Vector4d> steps;
  // sin(|phi_i| / 2) of each step.
  std::vector<double> half_sin;
  double dq[4] = {1.0, 0.0, 0.0, 0.0};
};

// Fills *f at (bias, matrix, g_sensitivity): the same values, in the same
// order of operations, as IntegrateGyroRotation<double> (f->dq and f->path
// have its bits).
inline void GyroTurnForwardPass(const GyroRotationData& data, const double* bias,
                                const double* matrix, const double* g_sensitivity,
                                GyroTurnForward* f) {
  double* dq = f->dq;
  dq[0] = 1.0;
  dq[1] = dq[2] = dq[3] = 0.0;
  const size_t n = data.t.size();
  f->path.resize(n);
  if (n > 0) f->path[0] = Eigen::Vector4d(dq[0], dq[1], dq[2], dq[3]);
  if (n < 2) return;
  if (f->w.size() < n) {
    f->w.resize(n);
    f->phi.resize(n);
    f->steps.resize(n);
    f->half_sin.resize(n);
  }
  std::vector<Eigen::Vector3d>& w = f->w;
  // The rates w_k, as IntegrateGyroRotation<double> computes them.
  for (size_t k = 0; k < n; ++k) {
    CalibratedGyroRate<double>(data, k, bias, matrix, g_sensitivity, w[k].data());
  }
  // The steps phi_i and the turn. The step's quaternion is
  // ceres::AngleAxisToQuaternion's, operation for operation.
  for (size_t i = 0; i + 1 < n; ++i) {
    // Samples i - 1 and i + 2 exist (and are read) only at inner steps.
    const double* before = w[i > 0 ? i - 1 : i].data();
    const double* after = w[i + 2 < n ? i + 2 : i + 1].data();
    GyroStepRotation<double>(data.t, i, before, w[i].data(), w[i + 1].data(), after,
                             f->phi[i].data());
    const double* a = f->phi[i].data();
    const double theta_squared = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
    double* q = f->steps[i].data();
    if (theta_squared > 0.0) {
      const double theta = std::sqrt(theta_squared);
      double sine, cosine;
      SinCos(theta * 0.5, &sine, &cosine);
      const double k = sine / theta;
      f->half_sin[i] = sine;
      q[0] = cosine;
      q[1] = a[0] * k;
      q[2] = a[1] * k;
      q[3] = a[2] * k;
    } else {
      f->half_sin[i] = 0.0;
      q[0] = 1.0;
      q[1] = a[0] * 0.5;
      q[2] = a[1] * 0.5;
      q[3] = a[2] * 0.5;
    }
    double next[4];
    ceres::QuaternionProduct(dq, q, next);
    for (int j = 0; j < 4; ++j) dq[j] = next[j];
    f->path[i + 1] = Eigen::Vector4d(dq[0], dq[1], dq[2], dq[3]);
  }
}

// The Jacobian of f.dq (columns as IntegrateGyroRotationJacobian's) from
// the forward pass *f made at the same parameters.
inline void GyroTurnBackwardPass(const GyroRotationData& data, const double* bias,
                                 const double* matrix, const double* g_sensitivity,
                                 const GyroTurnForward& f, Eigen::Matrix<double, 4, 21>* jacobian) {
  jacobian->setZero();
  const size_t n = data.t.size();
  if (n < 2) return;
  thread_local std::vector<Eigen::Matrix3d> h_k;
  if (h_k.size() < n) h_k.resize(n);
  const std::vector<Eigen::Vector3d>& w = f.w;
  const std::vector<Eigen::Vector3d>& phi = f.phi;
  const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> m(matrix);
  // S_i and H_k.
  for (size_t k = 0; k < n; ++k) h_k[k].setZero();
  double s[4] = {1.0, 0.0, 0.0, 0.0};
  for (size_t i = n - 1; i-- > 0;) {
    const double t2 = phi[i].squaredNorm();
    double alpha, beta;
    if (t2 < 1e-4) {
      alpha = 0.5 - t2 / 24.0 + t2 * t2 / 720.0;
      beta = 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0;
    } else {
      const double t = std::sqrt(t2);
      const double half = f.half_sin[i];
      alpha = 2.0 * half * half / t2;
      beta = (t - std::sin(t)) / (t2 * t);
    }
    const Eigen::Matrix3d k = Hat<double>(phi[i]);
    const Eigen::Matrix3d right = Eigen::Matrix3d::Identity() - alpha * k + beta * k * k;
    Eigen::Matrix<double, 3, 3, Eigen::RowMajor> rotation;
    ceres::QuaternionToRotation(s, rotation.data());
    const Eigen::Matrix3d g = rotation.transpose() * right;
    const double step = data.t[i + 1] - data.t[i];
    double c[4];
    GyroStepWeights(data.t, i, c);
    const double coning = step * step / 12.0;
    h_k[i] += g * (c[1] * Eigen::Matrix3d::Identity() - coning * Hat<double>(w[i + 1]));
    h_k[i + 1] += g * (c[2] * Eigen::Matrix3d::Identity() + coning * Hat<double>(w[i]));
    if (c[0] != 0.0) {
      h_k[i - 1] += c[0] * g;
      h_k[i + 2] += c[3] * g;
    }
    double next[4];
    ceres::QuaternionProduct(f.steps[i].data(), s, next);
    for (int j = 0; j < 4; ++j) s[j] = next[j];
  }
  // e = E dp, then d dq = dq * (0, e / 2).
  Eigen::Matrix<double, 3, 21> e = Eigen::Matrix<double, 3, 21>::Zero();
  Eigen::Matrix3d h_sum = Eigen::Matrix3d::Zero();
  const Eigen::Vector3d b_g(bias[0], bias[1], bias[2]);
  for (size_t k = 0; k < n; ++k) {
    h_sum += h_k[k];
    const Eigen::Vector3d d = data.gyro[k] - b_g;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        e.col(3 + 3 * r + c) += h_k[k].col(r) * d(c);
        if (g_sensitivity != nullptr) e.col(12 + 3 * r + c) -= h_k[k].col(r) * data.force[k](c);
      }
    }
  }
  e.leftCols<3>() = -h_sum * m;
  const double* dq = f.dq;
  const Eigen::Vector3d v(dq[1], dq[2], dq[3]);
  for (int j = 0; j < 21; ++j) {
    const Eigen::Vector3d half = 0.5 * e.col(j);
    (*jacobian)(0, j) = -v.dot(half);
    jacobian->block<3, 1>(1, j) = dq[0] * half + v.cross(half);
  }
}

// The forward pass buffer of this thread, for the turns no cache keeps.
inline GyroTurnForward& GyroTurnScratch() {
  thread_local GyroTurnForward forward;
  return forward;
}

inline void IntegrateGyroRotationJacobian(const GyroRotationData& data, const double* bias,
                                          const double* matrix, const double* g_sensitivity,
                                          double* dq, Eigen::Matrix<double, 4, 21>* jacobian) {
  GyroTurnForward& forward = GyroTurnScratch();
  GyroTurnForwardPass(data, bias, matrix, g_sensitivity, &forward);
  for (int j = 0; j < 4; ++j) dq[j] = forward.dq[j];
  GyroTurnBackwardPass(data, bias, matrix, g_sensitivity, forward, jacobian);
}

// The turn of one rotation at the parameters it was last evaluated at: its
// forward pass, and its Jacobian once asked for. The solver evaluates a
// residual at plain values (a trial step) and, when it takes the step, with
// its Jacobian at the same parameters; then again at the same parameters
// (the check of the free columns and the covariance). The cache answers
// those with a comparison, and the Jacobian after a plain evaluation with
// the backward pass alone; the values are those of an evaluation from
// scratch, bit for bit. One cache serves one turn's data (t, gyro, force);
// residuals of several problems on the same turn may share it (the
// accelerometer effect fit's gyroscope-alone start and its joint solve).
// The forward pass takes 120 bytes per sample: it is kept only for turns of
// at most kMaxSamples samples (about 1 MB; 8 s at 1 kHz), so that a long
// log's turns do not hold their whole length in memory; a longer turn
// keeps dq and the Jacobian only. Safe when one rotation is evaluated from
// several threads (they take turns).
class GyroTurnCache {
 public:
  static constexpr size_t kMaxSamples = 8192;

  // dq at key (21 values: b_g, M_g, G; G is used when with_g), with
  // jacobian not null its Jacobian (IntegrateGyroRotationJacobian's
  // columns), and with path not null the attitude at every sample
  // (IntegrateGyroRotation's path, 4 values per sample).
  void Evaluate(const GyroRotationData& data, const double* key, bool with_g, double* dq,
                Eigen::Matrix<double, 4, 21>* jacobian, double* path = nullptr) {
    std::lock_guard<std::mutex> lock(mutex_);
    const double* g = with_g ? key + 12 : nullptr;
    if (!valid_ || std::memcmp(key, key_, sizeof(key_)) != 0) {
      std::memcpy(key_, key, sizeof(key_));
      valid_ = forward_kept_ = jacobian_valid_ = false;
    }
    const bool need_jacobian = jacobian != nullptr && !jacobian_valid_;
    const GyroTurnForward* f = &forward_;
    if (!forward_kept_ && (!valid_ || need_jacobian || path != nullptr)) {
      const bool keep = data.t.size() <= kMaxSamples;
      GyroTurnForward* target = keep ? &forward_ : &GyroTurnScratch();
      GyroTurnForwardPass(data, key, key + 3, g, target);
      std::memcpy(dq_, target->dq, sizeof(dq_));
      valid_ = true;
      forward_kept_ = keep;
      f = target;
    }
    if (need_jacobian) {
      GyroTurnBackwardPass(data, key, key + 3, g, *f, &jacobian_);
      jacobian_valid_ = true;
    }
    std::memcpy(dq, dq_, sizeof(dq_));
    if (jacobian != nullptr) *jacobian = jacobian_;
    if (path != nullptr) {
      for (size_t i = 0; i < data.t.size(); ++i) {
        for (int j = 0; j < 4; ++j) path[4 * i + j] = f->path[i](j);
      }
    }
  }

 private:
  std::mutex mutex_;
  // key_ and dq_ hold; forward_ is kept for key_; jacobian_ is key_'s.
  bool valid_ = false;
  bool forward_kept_ = false;
  bool jacobian_valid_ = false;
  double key_[21] = {};
  double dq_[4] = {1.0, 0.0, 0.0, 0.0};
  GyroTurnForward forward_;
  Eigen::Matrix<double, 4, 21> jacobian_;
};

// The value part of a parameter (a plain value, or a Jet's).
inline double TurnScalar(double x) { return x; }
template <int N>
double TurnScalar(const ceres::Jet<double, N>& x) {
  return x.a;
}

// The key of a turn's cache: (b_g, M_g, G), G = 0 when not estimated.
template <typename T>
void GyroTurnKey(const T* bias, const T* matrix, const T* g_sensitivity, double* key) {
  for (int i = 0; i < 3; ++i) key[i] = TurnScalar(bias[i]);
  for (int i = 0; i < 9; ++i) {
    key[3 + i] = TurnScalar(matrix[i]);
    key[12 + i] = g_sensitivity != nullptr ? TurnScalar(g_sensitivity[i]) : 0.0;
  }
}

// IntegrateGyroRotation for Ceres: at plain values, or for automatic
// differentiation with the derivatives of dq chained from
// IntegrateGyroRotationJacobian into the N of the residual's parameters
// (through `cache` when not null).
inline void IntegrateGyroTurn(const GyroRotationData& data, const double* bias,
                              const double* matrix, const double* g_sensitivity, double* dq,
                              GyroTurnCache* cache = nullptr) {
  if (cache == nullptr) {
    IntegrateGyroRotation<double>(data, bias, matrix, g_sensitivity, dq);
    return;
  }
  double key[21];
  GyroTurnKey(bias, matrix, g_sensitivity, key);
  cache->Evaluate(data, key, g_sensitivity != nullptr, dq, nullptr);
}
template <int N>
void IntegrateGyroTurn(const GyroRotationData& data, const ceres::Jet<double, N>* bias,
                       const ceres::Jet<double, N>* matrix,
                       const ceres::Jet<double, N>* g_sensitivity, ceres::Jet<double, N>* dq,
                       GyroTurnCache* cache = nullptr) {
  double key[21];
  GyroTurnKey(bias, matrix, g_sensitivity, key);
  double q[4];
  Eigen::Matrix<double, 4, 21> jacobian;
  if (cache == nullptr) {
    IntegrateGyroRotationJacobian(data, key, key + 3, g_sensitivity != nullptr ? key + 12 : nullptr,
                                  q, &jacobian);
  } else {
    cache->Evaluate(data, key, g_sensitivity != nullptr, q, &jacobian);
  }
  for (int k = 0; k < 4; ++k) {
    dq[k].a = q[k];
    dq[k].v.setZero();
    for (int i = 0; i < 3; ++i) dq[k].v += jacobian(k, i) * bias[i].v;
    for (int i = 0; i < 9; ++i) dq[k].v += jacobian(k, 3 + i) * matrix[i].v;
    if (g_sensitivity != nullptr) {
      for (int i = 0; i < 9; ++i) dq[k].v += jacobian(k, 12 + i) * g_sensitivity[i].v;
    }
  }
}

// r = W E (R(dq)^T d_s - d_e), the whitened direction error of a turn dq
// (w, x, y, z) from start direction d_s to end direction d_e.
template <typename T>
void WhitenedTurnError(const T* dq, const T* start, const T* end,
                       const Eigen::Matrix<double, 2, 3>& tangent, const Eigen::Matrix2d& w,
                       T* residual) {
  // R(dq)^T d_s: rotate by the conjugate.
  const T conjugate[4] = {dq[0], -dq[1], -dq[2], -dq[3]};
  T predicted[3];
  ceres::UnitQuaternionRotatePoint(conjugate, start, predicted);
  T e[2];
  for (int j = 0; j < 2; ++j) {
    e[j] = T(0.0);
    for (int i = 0; i < 3; ++i) e[j] += tangent(j, i) * (predicted[i] - end[i]);
  }
  residual[0] = w(0, 0) * e[0] + w(0, 1) * e[1];
  residual[1] = w(1, 0) * e[0] + w(1, 1) * e[1];
}

struct GyroRotationResidual {
  explicit GyroRotationResidual(GyroRotationData data) : data_(std::move(data)) {}

  // Accelerometer fixed, G = 0.
  template <typename T>
  bool operator()(const T* const bias, const T* const matrix, T* residual) const {
    return Evaluate<T>(bias, matrix, nullptr, nullptr, nullptr, residual);
  }
  // Accelerometer fixed, G estimated.
  template <typename T>
  bool operator()(const T* const bias, const T* const matrix, const T* const g_sensitivity,
                  T* residual) const {
    return Evaluate<T>(bias, matrix, g_sensitivity, nullptr, nullptr, residual);
  }
  // Joint with the accelerometer, G = 0.
  template <typename T>
  bool operator()(const T* const bias, const T* const matrix, const T* const accel_bias,
                  const T* const accel_upper, T* residual) const {
    return Evaluate<T>(bias, matrix, nullptr, accel_bias, accel_upper, residual);
  }
  // Joint with the accelerometer, G estimated.
  template <typename T>
  bool operator()(const T* const bias, const T* const matrix, const T* const g_sensitivity,
                  const T* const accel_bias, const T* const accel_upper, T* residual) const {
    return Evaluate<T>(bias, matrix, g_sensitivity, accel_bias, accel_upper, residual);
  }

  // The cost function for the blocks above: (b_g, M_g[, G][, b_a, U]).
  static ceres::CostFunction* Create(GyroRotationData data, bool g_sensitivity, bool joint) {
    auto* functor = new GyroRotationResidual(std::move(data));
    if (g_sensitivity && joint) {
      return new ceres::AutoDiffCostFunction<GyroRotationResidual, 2, 3, 9, 9, 3, 6>(functor);
    }
    if (g_sensitivity) {
      return new ceres::AutoDiffCostFunction<GyroRotationResidual, 2, 3, 9, 9>(functor);
    }
    if (joint) return new ceres::AutoDiffCostFunction<GyroRotationResidual, 2, 3, 9, 3, 6>(functor);
    return new ceres::AutoDiffCostFunction<GyroRotationResidual, 2, 3, 9>(functor);
  }

 private:
  template <typename T>
  bool Evaluate(const T* bias, const T* matrix, const T* g_sensitivity, const T* accel_bias,
                const T* accel_upper, T* residual) const {
    T start[3], end[3];
    if (accel_bias != nullptr) {
      // d = R U (v - b) / |U (v - b)|.
      AccelBlocks<T> accel;
      accel.bias = accel_bias;
      accel.upper = accel_upper;
      accel.rotation = &data_.accel_rotation;
      const ImuModel<T> model(accel);
      model.Direction(data_.start_raw, 0.0, 0.0, start);
      model.Direction(data_.end_raw, 0.0, 0.0, end);
    } else {
      for (int i = 0; i < 3; ++i) {
        start[i] = T(data_.start_direction(i));
        end[i] = T(data_.end_direction(i));
      }
    }
    T dq[4];
    IntegrateGyroTurn(data_, bias, matrix, g_sensitivity, dq, &cache_);
    WhitenedTurnError<T>(dq, start, end, data_.tangent, data_.sqrt_information, residual);
    return true;
  }

  const GyroRotationData data_;
  mutable GyroTurnCache cache_;
};

}  // namespace gravcal

#endif  // GRAVCAL_RESIDUALS_GYRO_ROTATION_RESIDUAL_H_
