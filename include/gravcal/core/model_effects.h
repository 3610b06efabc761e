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
// specific force s (same frame): the shape terms from the innermost out,
// then the offsets (effect_registry.h); with the effects of the first
// catalogue
//
//   m_i = (1 + c_i dT) (s_i + k2_i s_i^2) + beta_i dT + delta_i dt
//
// and its exact inverse, the correction applied in a fit:
//
//   q_i = (m_i - beta_i dT - delta_i dt) / (1 + c_i dT)
//   a_i = 2 q_i / (1 + sqrt(1 + 4 k2_i q_i))        (solves a + k2 a^2 = q)
//
// The gyroscope at rest (w = 0), raw units, with f the calibrated specific
// force (m/s^2, the frame above): u = b_g + o, o the sum of the gyroscope
// effects' terms, e.g.
//
//   o = G f + gamma dT + eta dt
//
// G, gamma and eta are in raw gyroscope units per m/s^2, per degree C and per
// second (the static data cannot separate them from the gyroscope's scale
// matrix: G here is M_g^-1 G_true). The accelerometer's non-orthogonality
// (accel_misalignment) is the off-diagonal of U, an effect only when the
// baseline parameterisation is `scale`. Each effect's own file in
// core/effects/ holds its term's equation.
//
// All parameters zero = no effect (the textbook model). Each effect is
// defined once, with its equation, in core/effects/ and registered in
// core/effect_registry.h; this catalogue, the storage below and the model's
// terms (imu_model.h) are derived from the registry.
#ifndef GRAVCAL_CORE_MODEL_EFFECTS_H_
#define GRAVCAL_CORE_MODEL_EFFECTS_H_

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "gravcal/core/effect_registry.h"
#include "gravcal/core/types.h"

namespace gravcal {

// One effect's definition as data (from its file in core/effects/).
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
  // How its term enters the model; kInUpper (accel_misalignment) has no
  // stored values (it frees the off-diagonal of U).
  EffectForm form = EffectForm::kAccelOffset;
  // The simulator's truth spread (key null: none of its own).
  EffectSimulation simulation;
};

// Every effect, in catalogue (registry) order.
const std::vector<EffectInfo>& EffectCatalogue();
const EffectInfo& Info(Effect effect);
// Parses names into effects; on an unknown name returns false with a message
// listing the catalogue. Duplicates are dropped.
bool ParseEffects(const std::vector<std::string>& names, std::vector<Effect>* effects,
                  std::string* error);
std::vector<std::string> EffectNames(const std::vector<Effect>& effects);
bool Contains(const std::vector<Effect>& effects, Effect effect);

// The values of every effect's parameters (zero = off), stored in the two
// blocks of the registry's layout: the accelerometer's terms and the
// gyroscope's. An effect's values are in EffectInfo::parameter_names order
// (a 3x3 matrix row-major).
struct EffectParameters {
  std::array<double, kAccelEffectParameters> accel{};
  std::array<double, kGyroEffectParameters> gyro{};
  // T_ref (degrees C) and t_ref (s).
  double reference_temperature = 0.0;
  double reference_time = 0.0;

  // The values of one effect (null for accel_misalignment, which lives in
  // U).
  double* Block(Effect effect);
  const double* Block(Effect effect) const;
  // An effect of 3 parameters as a vector, of 9 as a matrix (row-major).
  Eigen::Map<Eigen::Vector3d> Vector(Effect effect) {
    return Eigen::Map<Eigen::Vector3d>(Block(effect));
  }
  Eigen::Map<const Eigen::Vector3d> Vector(Effect effect) const {
    return Eigen::Map<const Eigen::Vector3d>(Block(effect));
  }
  Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> Matrix(Effect effect) {
    return Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(Block(effect));
  }
  Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> Matrix(Effect effect) const {
    return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(Block(effect));
  }
  // The parameter values of one effect (empty for accel_misalignment).
  std::vector<double> Values(Effect effect) const;
  // Sets one effect's values (EffectInfo::num_parameters of them;
  // accel_misalignment sets nothing). False when the count is wrong.
  bool SetValues(Effect effect, const std::vector<double>& values);
  // pointers[e] at the values of every effect in `active` (others null):
  // the blocks ImuModel<double> views.
  void Pointers(const std::vector<Effect>& active, const double* (&pointers)[kNumEffects]) const;
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

// T - T_ref, or 0 when the temperature is unknown (NaN).
double TemperatureOffset(const EffectParameters& p, double temperature);

// The forward accelerometer model (for simulation): m from the true s, every
// effect's term (zero values = no term).
Eigen::Vector3d ApplyAccelEffects(const EffectParameters& p, const Eigen::Vector3d& s,
                                  double temperature, double time);

// The inverse with the parameters of `effects` only (others treated as
// zero): a from m. False when a shape term has no inverse here.
bool CorrectAccel(const EffectParameters& p, const std::vector<Effect>& effects,
                  const Eigen::Vector3d& m, double temperature, double time, Eigen::Vector3d* a);

// The gyroscope offset of `effects` at rest (raw units).
Eigen::Vector3d GyroOffset(const EffectParameters& p, const std::vector<Effect>& effects,
                           const Eigen::Vector3d& force, double temperature, double time);

}  // namespace gravcal

#endif  // GRAVCAL_CORE_MODEL_EFFECTS_H_
