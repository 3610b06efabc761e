// gravcal/estimation/noise_characterisation.h: the noise model of a whole
// IMU from a still log: the Allan deviation of each accelerometer and
// gyroscope axis (and of the temperature, curve only) and the fitted terms
// of core/noise_model.h, in SI units.
//
// The log is converted to SI with nominal scales (no calibration needed:
// noise densities are insensitive to percent-level scale errors). Unless
// told the log is still throughout, the static detector picks the longest
// still interval and only that is used; a log with none, or with one too
// short for the tau asked, is refused with the reason.
#ifndef GRAVCAL_ESTIMATION_NOISE_CHARACTERISATION_H_
#define GRAVCAL_ESTIMATION_NOISE_CHARACTERISATION_H_

#include <array>
#include <string>

#include "gravcal/core/imu_log.h"
#include "gravcal/core/noise_model.h"
#include "gravcal/detection/static_detector.h"
#include "gravcal/estimation/allan_deviation.h"

namespace gravcal {

struct NoiseOptions {
  // Nominal scales: m/s^2 per raw accelerometer unit and rad/s per raw
  // gyroscope unit (1 = the log is already in SI).
  double accel_scale = 1.0;
  double gyro_scale = 1.0;
  // Use the longest still interval the detector finds (true), or the whole
  // log, known to be still (false).
  bool find_still = true;
  // With find_still false, the log is refused as moving when the direction
  // of the mean accelerometer vector of one tenth of it differs from that of
  // the whole by more than this, degrees.
  double max_tilt_deg = 2.0;
  StaticDetectorOptions detector;
  AllanOptions allan;
  NoiseFitOptions fit;

  bool IsValid(std::string* error) const;
};

struct ImuNoise {
  // The fitted terms per axis (NaN for a gyroscope the log does not have),
  // the rate and the still interval used.
  ImuNoiseModel model;
  // The Allan curves, SI units, with the EDF of the term dominating each
  // point; empty when the log has no such sensor.
  std::array<AllanDeviation, 3> accel_curves;
  std::array<AllanDeviation, 3> gyro_curves;
  // Temperature in degrees Celsius: curve only, white-noise EDF.
  AllanDeviation temperature_curve;
  std::string message = "CharacteriseNoise was not called";
};

// Returns false with result->message (one line naming the problem) on
// invalid options, an invalid log, no still interval or one too short for
// the tau asked, non-uniform sampling in it, or (find_still false) a log
// that turns.
bool CharacteriseNoise(const ImuLog& log, const NoiseOptions& options, ImuNoise* result);

}  // namespace gravcal

#endif  // GRAVCAL_ESTIMATION_NOISE_CHARACTERISATION_H_
