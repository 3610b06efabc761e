// gravcal/simulation/handheld_simulator.h: simulated motion sessions with known truth for
// the handheld Kalman calibration and its baselines.
//
// Profiles:
// - handheld: a still period, then the unit turned by hand about its x, then
//   y, then z axis while that axis is roughly horizontal (the unit is tilted
//   90 degrees to bring z horizontal, and back), then still again. The
//   hand's rate is irregular, the turning axis wobbles, the unit sways by a
//   few centimetres and trembles. Each turn is a whole number of half turns,
//   so the next axis starts horizontal.
// - turntable: the same sequence on a three-axis table: exact axes, constant
//   rate with smooth ramps, whole turns ("back to zero"), no sway or tremor.
// - vertical: turns only about the vertical axis (z up throughout): the
//   motion that excites nothing (Sun, Ding, Yan fig. 2).
// - rate_table: each axis in turn pointing up on a single-axis rate table,
//   turned at +rate and then -rate; the constant-rate parts are returned as
//   rate-table segments (rate_table.h).
//
// Frames as in strapdown.h: navigation East-North-Up, gravity (0, 0, -g);
// the true specific force is f^b = C_nb^T (a^n + (0, 0, g)) with a^n the
// sensor's acceleration (sway, tremor, and the lever arm's centripetal and
// tangential terms), and the body rate w^b is exactly the one the attitude
// was integrated from (Simpson's rule plus the coning term on a grid four
// times finer than the samples). Samples are instantaneous values. The sensor model and noise
// come from SimulatorOptions (simulator.h): v = M^-1 f + b + n_a, u =
// M_g^-1 w + b_g + n_g, optional bias random walks, counts or SI units. Its
// scheme, hold, rotation, placement and tremor fields are not used here.
#ifndef GRAVCAL_SIMULATION_HANDHELD_SIMULATOR_H_
#define GRAVCAL_SIMULATION_HANDHELD_SIMULATOR_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "gravcal/core/rate_table_segment.h"
#include "gravcal/core/types.h"
#include "gravcal/simulation/simulator.h"

namespace gravcal {

struct MotionOptions {
  MotionProfile profile = MotionProfile::kHandheld;
  // Still at the start and at the end, seconds.
  double initial_still_seconds = 5.0;
  double final_still_seconds = 10.0;
  // Time spent turning about each axis (rate table: per direction), s.
  double seconds_per_axis = 12.0;
  // Mean turning rate, deg/s (rate table: the table rate).
  double rate_dps = 90.0;
  // Handheld: relative variation of the hand's rate (0 = steady).
  double rate_variation = 0.5;
  // Handheld: rms wobble of the turning axis, degrees.
  double axis_wobble_deg = 3.0;
  // Handheld and vertical: hand sway, m rms per axis, with frequencies up to
  // sway_hz.
  double sway = 0.01;
  double sway_hz = 0.5;
  // Handheld and vertical: tremor at 8-12 Hz, acceleration m/s^2 rms per
  // axis and angular rate rad/s rms per axis.
  double tremor = 0.05;
  double angular_tremor = 0.01;
  // Handheld, turntable and vertical: times through the x, y, z sequence.
  int rounds = 1;
  // Distance of the sensor from the point the hand turns about, m (a fixed
  // random direction in the body frame).
  double lever_arm = 0.0;

  bool IsValid(std::string* error) const;
};

struct MotionSession {
  // The log (accelerometer and gyroscope) and the truth sensor models.
  SimulatedSession sensor;
  // Truth per sample: attitude C_nb, position and velocity of the sensor.
  std::vector<Eigen::Quaterniond> attitude;
  std::vector<Eigen::Vector3d> position;
  std::vector<Eigen::Vector3d> velocity;
  // The sensor's position relative to the point the hand turns about, body
  // frame, m (MotionOptions::lever_arm in a random direction).
  Eigen::Vector3d lever_arm = Eigen::Vector3d::Zero();
  // rate_table profile: the constant-rate segments with their true rates.
  std::vector<RateTableSegment> segments;
};

// Simulates one session. Deterministic for a given (options, seed).
bool SimulateMotion(const SimulatorOptions& sensor, const MotionOptions& motion, uint64_t seed,
                    MotionSession* session, std::string* error);

// The truth of the filter's sensor model (error_state_layout.h) in SI units
// after the nominal scales: the accelerometer's f_m = (I + E_a) f + b_a with
// E_a = nominal * M^-1 - I and b_a = nominal * b, same for the gyroscope.
struct SensorErrorTruth {
  Eigen::Vector3d accel_bias;
  Eigen::Matrix3d accel_e;
  Eigen::Vector3d gyro_bias;
  Eigen::Matrix3d gyro_e;
};
SensorErrorTruth ErrorTruth(const SimulatedSession& session);

}  // namespace gravcal

#endif  // GRAVCAL_SIMULATION_HANDHELD_SIMULATOR_H_
