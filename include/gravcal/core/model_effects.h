// gravcal/core/model_effects.h: the catalogue of sensor effects beyond the
// textbook model, as optional terms switched on by name.
//
// Frames and units. m = U (v - b) is the accelerometer reading after the
// linear calibration, m/s^2, in the orthogonalised sensor frame (the gauge of
// the magnitude fit, accel_model.h; the housing rotation R is not involved).
// dT = T - T_ref is the temperature offset, degrees C; dt = t - t_ref the
// time offset, seconds; T_ref and t_ref are fixed reference values (the
// means over the static positions in a fit). Sign convention as everywhere:
// a unit at rest reads +g on the axis that points up.
//
// The sensor (forward) model of the accelerometer, per axis i, from the true
// specific force s (same frame):
//
//   m_i = (1 + c_i dT) (s_i + k2_i s_i^2) + beta_i dT + delta_i dt
//
// and its exact inverse, the correction applied in a fit:
//
//   q_i = (m_i - beta_i dT - delta_i dt) / (1 + c_i dT)
//   a_i = 2 q_i / (1 + sqrt(1 + 4 k2_i q_i))        (solves a + k2 a^2 = q)
//
// The gyroscope at rest (w = 0), raw units, with f the calibrated specific
// force (m/s^2, the frame above):
//
//   u = b_g + G f + gamma dT + eta dt
//
// G, gamma and eta are in raw gyroscope units per m/s^2, per degree C and per
// second (the static data cannot separate them from the gyroscope's scale
// matrix: G here is M_g^-1 G_true). The accelerometer's non-orthogonality
// (accel_misalignment) is the off-diagonal of U, an effect only when the
// baseline parameterisation is `scale`.
//
// All parameters zero = no effect (the textbook model).
#ifndef GRAVCAL_CORE_MODEL_EFFECTS_H_
#define GRAVCAL_CORE_MODEL_EFFECTS_H_

#include <Eigen/Core>
#include <cmath>
#include <string>
#include <vector>

#include "gravcal/core/types.h"

namespace gravcal {

struct EffectInfo {
  Effect effect;
  // Physical meaning, one sentence.
  const char* description;
  EffectSensor sensor;
  EffectRegressor regressor;
  int num_parameters;
  // Names of the parameters (num_parameters of them) and their unit.
  std::vector<std::string> parameter_names;
  const char* unit;
  // Name in configs and discovery.json, e.g. "accel_temperature_bias":
  // ToString(effect).
  const char* name = nullptr;
};

// Every effect, in catalogue order.
const std::vector<EffectInfo>& EffectCatalogue();
const EffectInfo& Info(Effect effect);
// Parses names into effects; on an unknown name returns false with a message
// listing the catalogue. Duplicates are dropped.
bool ParseEffects(const std::vector<std::string>& names, std::vector<Effect>* effects,
                  std::string* error);
std::vector<std::string> EffectNames(const std::vector<Effect>& effects);
bool Contains(const std::vector<Effect>& effects, Effect effect);

// The values of every effect's parameters (zero = off).
struct EffectParameters {
  // k2 per axis, 1/(m/s^2): the reading is a + k2 a^2.
  Eigen::Vector3d accel_quadratic = Eigen::Vector3d::Zero();
  // beta per axis, m/s^2 per degree C.
  Eigen::Vector3d accel_temperature_bias = Eigen::Vector3d::Zero();
  // c per axis, fraction per degree C.
  Eigen::Vector3d accel_temperature_scale = Eigen::Vector3d::Zero();
  // delta per axis, m/s^2 per second.
  Eigen::Vector3d accel_bias_drift = Eigen::Vector3d::Zero();
  // G, raw gyroscope units per m/s^2 (row = gyroscope axis).
  Eigen::Matrix3d gyro_g_sensitivity = Eigen::Matrix3d::Zero();
  // gamma, raw gyroscope units per degree C.
  Eigen::Vector3d gyro_temperature_bias = Eigen::Vector3d::Zero();
  // eta, raw gyroscope units per second.
  Eigen::Vector3d gyro_bias_drift = Eigen::Vector3d::Zero();
  // T_ref (degrees C) and t_ref (s).
  double reference_temperature = 0.0;
  double reference_time = 0.0;

  // The parameter values of one effect, in EffectInfo::parameter_names order
  // (for accel_misalignment, which lives in U, empty).
  std::vector<double> Values(Effect effect) const;
};

// One effect's estimate, as written to calibration and discovery JSON.
struct EffectEstimate {
  Effect effect = Effect::kAccelQuadratic;
  std::vector<std::string> names;
  std::vector<double> values;
  // NaN where not determined.
  std::vector<double> std;
  std::string unit;
};

// The effects of a calibration (calibration JSON key `effects`).
struct EffectCalibration {
  std::vector<EffectEstimate> estimates;
  // T_ref (degrees C; NaN without temperature) and t_ref (s, log time).
  double reference_temperature = NAN;
  double reference_time = NAN;
};

// ---------------------------------------------------------------------------
// The terms, templated so that Ceres autodiff residuals can use them. Each
// works on one 3-vector in place.

// accel_temperature_bias and accel_bias_drift: q = m - beta dT - delta dt.
template <typename T>
void RemoveAccelBiasTerm(const T* coefficient, double offset, T* m) {
  for (int i = 0; i < 3; ++i) m[i] -= coefficient[i] * T(offset);
}

// accel_temperature_scale: q_i = m_i / (1 + c_i dT).
template <typename T>
void RemoveAccelScaleTerm(const T* c, double temperature_offset, T* m) {
  for (int i = 0; i < 3; ++i) m[i] /= T(1.0) + c[i] * T(temperature_offset);
}

// accel_quadratic_nonlinearity: the root of a + k2 a^2 = q near q,
// a = 2 q / (1 + sqrt(1 + 4 k2 q)), smooth at k2 = 0. False when 1 + 4 k2 q
// <= 0 (no real root: the coefficient is far outside any sensor's range).
template <typename T>
bool RemoveAccelQuadraticTerm(const T* k2, T* m) {
  using std::sqrt;
  for (int i = 0; i < 3; ++i) {
    const T d = T(1.0) + T(4.0) * k2[i] * m[i];
    if (!(d > T(0.0))) return false;
    m[i] = T(2.0) * m[i] / (T(1.0) + sqrt(d));
  }
  return true;
}

// All accelerometer terms in the order of the inverse model above; a null
// pointer skips a term.
template <typename T>
bool CorrectAccelEffects(const T* quadratic, const T* temperature_bias, const T* temperature_scale,
                         const T* drift, double temperature_offset, double time_offset, T* m) {
  if (temperature_bias != nullptr) RemoveAccelBiasTerm(temperature_bias, temperature_offset, m);
  if (drift != nullptr) RemoveAccelBiasTerm(drift, time_offset, m);
  if (temperature_scale != nullptr) RemoveAccelScaleTerm(temperature_scale, temperature_offset, m);
  if (quadratic != nullptr) return RemoveAccelQuadraticTerm(quadratic, m);
  return true;
}

// The gyroscope offset at rest: G f + gamma dT + eta dt (raw units); null
// pointers skip terms. g_sensitivity is row-major.
template <typename T>
void GyroEffectOffset(const T* g_sensitivity, const T* temperature_bias, const T* drift,
                      const double* force, double temperature_offset, double time_offset,
                      T* offset) {
  for (int i = 0; i < 3; ++i) {
    offset[i] = T(0.0);
    if (g_sensitivity != nullptr) {
      for (int j = 0; j < 3; ++j) offset[i] += g_sensitivity[3 * i + j] * T(force[j]);
    }
    if (temperature_bias != nullptr) offset[i] += temperature_bias[i] * T(temperature_offset);
    if (drift != nullptr) offset[i] += drift[i] * T(time_offset);
  }
}

// T - T_ref, or 0 when the temperature is unknown (NaN).
double TemperatureOffset(const EffectParameters& p, double temperature);

// The forward accelerometer model (for simulation): m from the true s.
Eigen::Vector3d ApplyAccelEffects(const EffectParameters& p, const Eigen::Vector3d& s,
                                  double temperature, double time);

// The inverse with the parameters of `effects` only (others treated as
// zero): a from m. False when the quadratic term has no real root.
bool CorrectAccel(const EffectParameters& p, const std::vector<Effect>& effects,
                  const Eigen::Vector3d& m, double temperature, double time, Eigen::Vector3d* a);

// The gyroscope offset of `effects` at rest (raw units).
Eigen::Vector3d GyroOffset(const EffectParameters& p, const std::vector<Effect>& effects,
                           const Eigen::Vector3d& force, double temperature, double time);

}  // namespace gravcal

#endif  // GRAVCAL_CORE_MODEL_EFFECTS_H_
