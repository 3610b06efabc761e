// gravcal/core/imu_corrector.h: everything a calibration holds, applied to one
// sample. The one place the full correction is written: `gravcal apply`, the
// exporters' truncation errors, the generated C corrector's reference and the
// Python bindings all call it.
//
// Accelerometer, raw reading v (raw units), temperature T (degrees C), time t
// (s), result a in m/s^2 in the housing frame:
//
//   m = U (v - b)                      linear model in the orthogonalised
//                                      sensor frame (accel_model.h)
//   s = h^-1(m, T - T_ref, t - t_ref)  effect terms removed (model_effects.h:
//                                      temperature and drift bias, temperature
//                                      scale, quadratic nonlinearity)
//   a = R s                            housing alignment
//
// Gyroscope, raw reading u (raw units), corrected specific force a (housing
// frame, m/s^2, the output above), result w in rad/s:
//
//   w = M_g (u - b_g - G R^T a - gamma (T - T_ref) - eta (t - t_ref))
//
// G, gamma, eta in raw gyroscope units (model_effects.h); R^T a is the
// specific force in the sensor frame G was fitted in. Effects that are not
// switched on are zero; all zero = the textbook model M (v - b), M_g (u - b_g).
// Issue 35: with an active thermal model (thermal_model.h) the linear model
// becomes m = (I + D(x))^-1 U (v - b - db(x)) and the gyroscope's
// M_g (u - ...) becomes (I + D_g(x))^-1 M_g (u - db_g(x) - ...), x the
// clamped, lag-corrected temperature offset; the effects act after it.
// A temperature of NaN contributes no temperature term (callers that need a
// temperature check RequiresTemperature() first).
#ifndef GRAVCAL_CORE_IMU_CORRECTOR_H_
#define GRAVCAL_CORE_IMU_CORRECTOR_H_

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include "gravcal/core/accel_model.h"
#include "gravcal/core/gyro_model.h"
#include "gravcal/core/model_effects.h"
#include "gravcal/core/thermal_model.h"

namespace gravcal {

struct ImuCorrector {
  AccelModel accel;
  bool has_gyro = false;
  GyroModel gyro;
  // The values of the effects (zero = off) and which are switched on.
  EffectParameters effects;
  std::vector<Effect> active_effects;
  // Issue 35: the thermal model (inactive = none).
  ThermalModel thermal;

  // True when an active effect uses the temperature (T) or the time (t).
  bool RequiresTemperature() const;
  bool RequiresTime() const;
  // True when the thermal model is active (it then uses the temperature).
  bool HasThermal() const { return thermal.active(); }

  // a from v. False (a unchanged) only when the quadratic term has no real
  // root for this reading (a reading far outside the sensor's range).
  bool CorrectAccel(const Eigen::Vector3d& raw, double temperature, double time,
                    Eigen::Vector3d* a) const;
  // w from u and the corrected a. Without a gyroscope model, returns u.
  Eigen::Vector3d CorrectGyro(const Eigen::Vector3d& raw, const Eigen::Vector3d& accel,
                              double temperature, double time) const;
  // One row of a log, in place: *accel v -> a (CorrectAccel), then, when
  // `gyro` is not null, *gyro u -> w with that a (CorrectGyro). False (both
  // unchanged) when CorrectAccel fails. The row step of `gravcal apply` and
  // Python's Calibration.apply, so the two give the same numbers.
  bool CorrectRow(double temperature, double time, Eigen::Vector3d* accel,
                  Eigen::Vector3d* gyro) const;
  // The same with the temperature's rate of change (degrees C per s; NaN =
  // unknown, no lag term), which the thermal model's lag uses; `clamped`
  // (may be null) is set when the temperature lay outside the thermal
  // model's valid range and was clamped.
  bool CorrectRow(double temperature, double temperature_rate, double time, Eigen::Vector3d* accel,
                  Eigen::Vector3d* gyro, bool* clamped) const;
  // CorrectRow over the rows [0, n) of a block, the same numbers row by row,
  // with the model set up once (gravcal apply): accel[i] and gyro[i] (gyro
  // may be null) corrected in place, clamped[i] set. Returns the first row
  // that fails (left unchanged, the rows after it untouched), n when none.
  size_t CorrectRows(size_t n, const double* temperature, const double* temperature_rate,
                     const double* time, Eigen::Vector3d* accel, Eigen::Vector3d* gyro,
                     bool* clamped) const;

  // The same model with only the terms a target can hold: the effects in
  // `keep` (others dropped). Used to measure what an export truncates.
  ImuCorrector WithEffects(const std::vector<Effect>& keep) const;
};

}  // namespace gravcal

#endif  // GRAVCAL_CORE_IMU_CORRECTOR_H_
