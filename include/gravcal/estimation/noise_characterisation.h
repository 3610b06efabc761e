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

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "gravcal/core/imu_log.h"
#include "gravcal/core/noise_model.h"
#include "gravcal/detection/static_detector.h"
#include "gravcal/estimation/allan_deviation.h"
#include "gravcal/estimation/spectral_lines.h"

namespace gravcal {

struct NoiseOptions {
  // Nominal scales: m/s^2 per raw accelerometer unit and rad/s per raw
  // gyroscope unit (1 = the log is already in SI).
  double accel_scale = 1.0;
  double gyro_scale = 1.0;
  // The raw accelerometer value at zero specific force (unsigned counts
  // around 32768, volts around 1.65), per axis, raw units. Only the check of
  // the unit against gravity uses it: the Allan deviation removes the mean.
  Eigen::Vector3d accel_offset = Eigen::Vector3d::Zero();
  // The sample rate, Hz; 0 = from the time stamps (SampleTiming).
  double rate_hz = 0.0;
  // Time stamps that jitter are accepted while the bias they could cause in
  // the Allan deviation stays within this (relative) at the longest tau
  // (ResolveSampleTiming).
  // (A step off the median step by more than allan.time_step_tolerance of
  // it marks the time stamps as jittering: the rate then comes from least
  // squares.)
  double max_time_bias = 0.05;
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
  // The lines in each axis's spectrum (spectral_lines.h), SI units; the
  // fit leaves out the taus they disturb.
  std::array<std::vector<SpectralLine>, 3> accel_lines;
  std::array<std::vector<SpectralLine>, 3> gyro_lines;
  // The choices made, written in noise.json: the timing, the raw units
  // (scales, offset) and how the accelerometer's unit was checked.
  SampleTiming timing;
  double accel_scale = 1.0;
  double gyro_scale = 1.0;
  Eigen::Vector3d accel_offset = Eigen::Vector3d::Zero();
  std::string unit_check;
  std::string message = "CharacteriseNoise was not called";
};

// Returns false with result->message (one line naming the problem) on
// invalid options, an invalid log, no still interval or one too short for
// the tau asked, non-uniform sampling in it, or (find_still false) a log
// that turns.
bool CharacteriseNoise(const ImuLog& log, const NoiseOptions& options, ImuNoise* result);

}  // namespace gravcal

#endif  // GRAVCAL_ESTIMATION_NOISE_CHARACTERISATION_H_
