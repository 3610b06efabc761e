// gravcal/core/imu_model.h: the IMU error model, templated on the scalar so
// that the same object is evaluated by the corrector (T = double) and inside
// Ceres automatic differentiation (T = ceres::Jet), as Sophus templates its
// groups. The model does not own its numbers: it views named parameter
// blocks (pointers into a Ceres problem's blocks, or into a calibration's
// models), so no consumer indexes a flat parameter vector.
//
// Accelerometer, raw reading v (raw units), offsets dT = T - T_ref (degrees
// C) and dt = t - t_ref (s) (model_effects.h):
//
//   m = U (v - b)                  m/s^2, orthogonalised sensor frame
//   s = h^-1(m, dT, dt)            effect terms removed (model_effects.h)
//   a = R s                        m/s^2, housing frame
//
// b: bias (3, raw units). U: upper triangular (6: u00 u01 u02 u11 u12 u22,
// row-major, m/s^2 per raw unit; accel_model.h). R: the housing rotation
// (held: no residual estimates it; null = identity).
//
// Gyroscope, raw reading u (raw units), calibrated specific force f (m/s^2,
// the sensor frame of m above):
//
//   o = G' f + gamma dT + eta dt   raw units (the effects, model_effects.h)
//   w = M_g (u - b_g - o) - G f    rad/s
//
// b_g: bias (3, raw units). M_g: 9, row-major (null = identity, the raw
// units of the effect fit). G: 9, row-major, rad/s per m/s^2 (the
// g-sensitivity of the gyroscope calibration); G' the same effect in raw
// units (the effect fit). A null block is a term that is off: all null =
// the identity mapping.
//
// Each operation is written once here, in one order of operations; the
// residuals (include/gravcal/residuals/), the corrector
// (core/imu_corrector.h) and the models' Apply call it.
#ifndef GRAVCAL_CORE_IMU_MODEL_H_
#define GRAVCAL_CORE_IMU_MODEL_H_

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "gravcal/core/accel_model.h"
#include "gravcal/core/gyro_model.h"
#include "gravcal/core/model_effects.h"
#include "gravcal/util/hat.h"

namespace gravcal {

// The accelerometer's parameter blocks, by name. bias and upper are always
// set; effect[e] points at the values of effect e (null = off; only the
// accelerometer's effects are read).
template <typename T>
struct AccelBlocks {
  AccelBlocks() = default;
  // The blocks of the magnitude, trend and rotation residuals, in their
  // order: every accelerometer effect at its place in `effects_block`
  // (kAccelEffectParameters values; null = no effects).
  AccelBlocks(const T* bias_block, const T* upper_block, const T* effects_block)
      : bias(bias_block), upper(upper_block) {
    PointIntoBlocks<T>(effects_block, nullptr, effect);
  }

  const T* bias = nullptr;                    // b, 3
  const T* upper = nullptr;                   // U, 6
  const T* effect[kNumEffects] = {};          // the effects' values
  const Eigen::Matrix3d* rotation = nullptr;  // R, held
};

// The gyroscope's parameter blocks, by name. bias is always set; a null
// matrix is the identity; effect[e] points at the values of effect e (null
// = off; only the gyroscope's effects are read).
template <typename T>
struct GyroBlocks {
  const T* bias = nullptr;            // b_g, 3
  const T* matrix = nullptr;          // M_g, 9 row-major
  const T* g_sensitivity = nullptr;   // G (rad/s per m/s^2), 9 row-major
  const T* effect[kNumEffects] = {};  // G' (raw units per m/s^2), gamma, eta, ...
};

template <typename T>
class ImuModel {
 public:
  ImuModel() = default;
  ImuModel(const AccelBlocks<T>& accel, const GyroBlocks<T>& gyro) : accel_(accel), gyro_(gyro) {}
  explicit ImuModel(const AccelBlocks<T>& accel) : accel_(accel) {}
  explicit ImuModel(const GyroBlocks<T>& gyro) : gyro_(gyro) {}

  const AccelBlocks<T>& accel() const { return accel_; }
  const GyroBlocks<T>& gyro() const { return gyro_; }

  // m = U (v - b).
  template <typename V>
  void SensorFrame(const V& raw, T* m) const {
    const T* b = accel_.bias;
    const T* u = accel_.upper;
    const T d0 = T(raw[0]) - b[0];
    const T d1 = T(raw[1]) - b[1];
    const T d2 = T(raw[2]) - b[2];
    m[0] = u[0] * d0 + u[1] * d1 + u[2] * d2;
    m[1] = u[3] * d1 + u[4] * d2;
    m[2] = u[5] * d2;
  }

  // s = h^-1(U (v - b), dT, dt); false when the quadratic term has no real
  // root (model_effects.h).
  template <typename V>
  bool CorrectedSensorFrame(const V& raw, double temperature_offset, double time_offset,
                            T* s) const {
    SensorFrame(raw, s);
    return RemoveAccelEffects<T>(accel_.effect, temperature_offset, time_offset, s);
  }

  // The rate of m = U (v - b) within a still pose at offsets (dT, dt) whose
  // temperature changes at Tdot (degC/s), m/s^2/s (effect_registry.h).
  void EffectRate(const T* m, double temperature_offset, double time_offset,
                  double temperature_slope, T* rate) const {
    AccelEffectRate<T>(accel_.effect, m, temperature_offset, time_offset, temperature_slope, rate);
  }

  // a = R s (R null: a = s); a may alias nothing in s.
  void ToHousing(const T* s, T* a) const {
    if (accel_.rotation == nullptr) {
      for (int i = 0; i < 3; ++i) a[i] = s[i];
      return;
    }
    const Eigen::Matrix3d& r = *accel_.rotation;
    for (int i = 0; i < 3; ++i) a[i] = r(i, 0) * s[0] + r(i, 1) * s[1] + r(i, 2) * s[2];
  }

  // a = R h^-1(U (v - b), dT, dt).
  template <typename V>
  bool CorrectAccel(const V& raw, double temperature_offset, double time_offset, T* a) const {
    T s[3];
    if (!CorrectedSensorFrame(raw, temperature_offset, time_offset, s)) return false;
    ToHousing(s, a);
    return true;
  }

  // The unit direction R s / |s| of the corrected reading (|R s| = |s|).
  template <typename V>
  bool Direction(const V& raw, double temperature_offset, double time_offset, T* d) const {
    T s[3];
    if (!CorrectedSensorFrame(raw, temperature_offset, time_offset, s)) return false;
    using std::sqrt;
    const T norm = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    if (accel_.rotation == nullptr) {
      for (int i = 0; i < 3; ++i) d[i] = s[i] / norm;
      return true;
    }
    T a[3];
    ToHousing(s, a);
    for (int i = 0; i < 3; ++i) d[i] = a[i] / norm;
    return true;
  }

  // y = U^-1 x by back substitution (U upper triangular).
  void UpperSolve(const T* x, T* y) const {
    const T* u = accel_.upper;
    y[2] = x[2] / u[5];
    y[1] = (x[1] - u[4] * y[2]) / u[3];
    y[0] = (x[0] - u[1] * y[1] - u[2] * y[2]) / u[0];
  }

  // o = G' f + gamma dT + eta dt (raw units). The force f (3 values) is
  // read only with G' and G; it may be null without them.
  void GyroOffset(const double* force, double temperature_offset, double time_offset, T* o) const {
    GyroEffectOffset<T>(gyro_.effect, force, temperature_offset, time_offset, o);
  }

  // e = u - b_g - o (raw units): the rest level's error with the effects.
  template <typename U>
  void GyroRestError(const U& raw, const double* force, double temperature_offset,
                     double time_offset, T* e) const {
    T o[3];
    GyroOffset(force, temperature_offset, time_offset, o);
    for (int i = 0; i < 3; ++i) e[i] = T(raw[i]) - gyro_.bias[i] - o[i];
  }

  // w = M_g d - G f for a d = u - b_g - o already formed.
  void GyroRateFrom(const T* d, const double* force, T* w) const {
    const T* m = gyro_.matrix;
    const T* g = gyro_.g_sensitivity;
    for (int r = 0; r < 3; ++r) {
      w[r] = m == nullptr ? d[r] : m[3 * r] * d[0] + m[3 * r + 1] * d[1] + m[3 * r + 2] * d[2];
      if (g != nullptr) {
        w[r] -= g[3 * r] * force[0] + g[3 * r + 1] * force[1] + g[3 * r + 2] * force[2];
      }
    }
  }

  // w = M_g (u - b_g) - G f (no effect offset).
  template <typename U>
  void GyroRate(const U& raw, const double* force, T* w) const {
    const T* b = gyro_.bias;
    const T d[3] = {T(raw[0]) - b[0], T(raw[1]) - b[1], T(raw[2]) - b[2]};
    GyroRateFrom(d, force, w);
  }

  // w = M_g (u - b_g - o) - G f, the whole gyroscope model.
  template <typename U>
  void CorrectGyro(const U& raw, const double* force, double temperature_offset, double time_offset,
                   T* w) const {
    T e[3];
    GyroRestError(raw, force, temperature_offset, time_offset, e);
    GyroRateFrom(e, force, w);
  }

 private:
  AccelBlocks<T> accel_;
  GyroBlocks<T> gyro_;
};

// The free parameters of the accelerometer model of a static fit: 6
// (kScale) or 9 for the baseline, plus the parameters of the accelerometer
// effects in `effects` (accel_misalignment only adds to kScale, which
// lacks it).
int AccelModelParameterCount(AccelParameterization parameterization,
                             const std::vector<Effect>& effects);

// The numbers of a whole model, owned, in the block layouts above: what a
// calibration's models and effects hold, ready to be viewed as an
// ImuModel<double>. Effects that are not switched on have no block.
class ImuParameters {
 public:
  // gyro null: no gyroscope model. Only the effects in `active` are on.
  ImuParameters(const AccelModel& accel, const GyroModel* gyro, const EffectParameters& effects,
                const std::vector<Effect>& active)
      : rotation_(accel.rotation), effects_(effects) {
    for (int i = 0; i < 3; ++i) accel_bias_[i] = accel.bias(i);
    accel.GetUpper(upper_);
    accel_.bias = accel_bias_;
    accel_.upper = upper_;
    accel_.rotation = &rotation_;
    const double* on[kNumEffects];
    effects_.Pointers(active, on);
    for (int k = 0; k < kNumEffects; ++k) accel_.effect[k] = gyro_.effect[k] = on[k];
    if (gyro == nullptr) {
      for (const double*& p : gyro_.effect) p = nullptr;
      return;
    }
    for (int i = 0; i < 3; ++i) gyro_bias_[i] = gyro->bias(i);
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) gyro_matrix_[3 * r + c] = gyro->matrix(r, c);
    }
    gyro_.bias = gyro_bias_;
    gyro_.matrix = gyro_matrix_;
  }
  ImuParameters(const ImuParameters&) = delete;
  ImuParameters& operator=(const ImuParameters&) = delete;

  // A view of the blocks (valid while this object lives).
  ImuModel<double> Model() const { return ImuModel<double>(accel_, gyro_); }
  bool has_gyro() const { return gyro_.bias != nullptr; }
  // dT = T - T_ref (0 when T is NaN) and dt = t - t_ref.
  double TemperatureOffset(double temperature) const {
    return std::isfinite(temperature) ? temperature - effects_.reference_temperature : 0.0;
  }
  double TimeOffset(double time) const { return time - effects_.reference_time; }

 private:
  double accel_bias_[3] = {0.0, 0.0, 0.0};
  double upper_[6] = {1.0, 0.0, 0.0, 1.0, 0.0, 1.0};
  Eigen::Matrix3d rotation_;
  double gyro_bias_[3], gyro_matrix_[9];
  const EffectParameters effects_;
  AccelBlocks<double> accel_;
  GyroBlocks<double> gyro_;
};

}  // namespace gravcal

#endif  // GRAVCAL_CORE_IMU_MODEL_H_
