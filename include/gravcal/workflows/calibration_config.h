// gravcal/workflows/calibration_config.h: the calibration part of a Config
// (config.h): the method and the options every calibration reads, and
// nothing of the simulator or of discovery. A library user who calibrates
// arrays in memory fills this part alone.
//
// Its config sections (src/workflows/config/*_keys.cc) bind keys to these
// fields only: general, input, gravity, detector, pose noise, model, solver,
// gyro, alignment, handheld_kalman, effects and noise.
#ifndef GRAVCAL_WORKFLOWS_CALIBRATION_CONFIG_H_
#define GRAVCAL_WORKFLOWS_CALIBRATION_CONFIG_H_

#include <string>
#include <vector>

#include "gravcal/core/model_effects.h"
#include "gravcal/core/types.h"
#include "gravcal/estimation/noise_characterisation.h"
#include "gravcal/io/log_reader.h"
#include "gravcal/methods/gyro_calibration.h"
#include "gravcal/methods/handheld_kalman.h"
#include "gravcal/methods/ten_position.h"
#include "gravcal/methods/thermal_calibration.h"
#include "gravcal/methods/twelve_position.h"

namespace gravcal {

struct CalibrationConfig {
  // Calibration method (its registry entry: method_registry.h).
  Method method = Method::kTwelvePosition;
  LogReaderOptions input;
  CalibrationOptions calibration;
  // Gyroscope from the rotations between the poses (gyro_model != none).
  GyroCalibrationOptions gyro;
  // Issue 3: the ten-position method's alignment settings.
  TenPositionOptions ten_position;
  // Write accel.covariance into the calibration JSON.
  bool output_covariance = true;
  // Issue 4: the handheld Kalman calibration (method handheld_kalman; its
  // gravity and accelerometer nominal scale come from `calibration`).
  HandheldKalmanOptions handheld;
  // Issue 6: effects beyond the textbook model fitted by `calibrate` (and
  // already in the baseline of `discover`).
  std::vector<Effect> effects;
  // Issue 14: `gravcal noise` (its scales and detector come from the keys
  // nominal_scale, gyro_nominal_scale and the detector section).
  NoiseOptions noise;
  // Issue 35: the thermal calibration (method thermal).
  ThermalCalibrationOptions thermal;
};

}  // namespace gravcal

#endif  // GRAVCAL_WORKFLOWS_CALIBRATION_CONFIG_H_
