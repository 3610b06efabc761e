// gravcal/simulation/plate_simulator.h: several IMUs on one rigid plate
// (issue 38), with known truth.
//
// The plate follows one session of static poses joined by turns
// (simulator.h; its scheme, holds and turns): f_p(t) and w_p(t) are the true
// specific force and rate in the plate frame. IMU i is mounted with the
// rotation Q_i (plate from housing) and its own sensor (simulator.h's
// random truth of seed + i: b, U, R; b_g, M_g, noise), so its housing frame
// sees
//
//   f_i(t) = Q_i^T f_p(t),   w_i(t) = Q_i^T w_p(t),
//
// and its raw samples are v = M^-1 f_i + b + n_a, u = M_g^-1 w_i + b_g + n_g
// (quantised when the options say counts). Its clock: the sample stamped t
// holds the plate at t - tau_i(t), tau_i(t) = offset_i + drift_i t (s; a
// positive offset stamps late). All IMUs share the stamps (one log, columns
// imu<i>.ax ... imu<i>.gz), sampled at the options' rate.
//
// Mistakes on demand: one unit permuted (Q_i times a 90 or 180 degree turn
// about an axis, the truth keeps it; its stated mounting does not), and one
// unit that slips on the plate during one turn (Q_i turns by slip_deg about
// a random axis, smoothly, while the plate turns).
#ifndef GRAVCAL_SIMULATION_PLATE_SIMULATOR_H_
#define GRAVCAL_SIMULATION_PLATE_SIMULATOR_H_

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "gravcal/core/accel_model.h"
#include "gravcal/core/gyro_model.h"
#include "gravcal/core/imu_log.h"
#include "gravcal/simulation/simulator.h"

namespace gravcal {

struct PlateSimulatorOptions {
  // Each IMU's sensor, noise and the plate's session (scheme, holds,
  // turns, sample rate). Its effects beyond the textbook model are ignored.
  SimulatorOptions imu;
  int imus = 3;
  // Mounting: aligned (every Q_i near the identity, by mounting_error_deg
  // per axis) or random (uniformly random rotations).
  PlateMounting mounting = PlateMounting::kRandom;
  double mounting_error_deg = 1.0;
  // Clock offsets uniform in [0, max_clock_offset] s (IMU 0: 0), and clock
  // drift N(0, clock_drift_std) (s per s; IMU 0: 0).
  double max_clock_offset = 0.030;
  double clock_drift_std = 0.0;
  // The unit permuted: its true Q is the stated one times a rotation by
  // permuted_angle_deg (90 or 180) about housing axis permuted_axis (0..2).
  // -1 = none.
  int permuted_imu = -1;
  int permuted_axis = 2;
  double permuted_angle_deg = 90.0;
  // The unit whose axis flipped_axis (0..2) reads with the wrong sign, in
  // both its accelerometer and gyroscope (left-handed axes: a wiring or
  // driver mistake). -1 = none.
  int flipped_imu = -1;
  int flipped_axis = 0;
  // The unit that slips by slip_deg during turn slip_turn (the turn into
  // pose slip_turn + 1). -1 = none.
  int slip_imu = -1;
  int slip_turn = 5;
  double slip_deg = 2.0;
  // The plate's truth is sampled this many times faster than the IMUs and
  // interpolated (cubic) at each IMU's clock.
  int oversample = 8;

  bool IsValid(std::string* error) const;
};

struct PlateImuTruth {
  std::string name;  // "imu<i>"
  AccelModel accel;  // raw -> housing (b, U, R)
  GyroModel gyro;    // raw -> housing
  // Q_i, plate from housing: the stated one (what a config would say) and
  // the true one at the start and at the end (they differ for a slip).
  Eigen::Matrix3d stated_mounting = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d mounting_start = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d mounting_end = Eigen::Matrix3d::Identity();
  double clock_offset = 0.0;  // s
  double clock_drift = 0.0;   // s per s
  double accel_units_per_si = 1.0;
  double gyro_units_per_si = 1.0;
};

struct SimulatedPlate {
  // One log per IMU, sample for sample on the same stamps.
  std::vector<ImuLog> logs;
  std::vector<PlateImuTruth> truth;
  // The plate's static poses (sample ranges of the logs, attitude).
  std::vector<SimulatedPose> poses;
  double gravity = 9.80665;
  uint64_t seed = 0;
};

// Simulates a plate. Deterministic for (options, seed).
bool SimulatePlate(const PlateSimulatorOptions& options, uint64_t seed, SimulatedPlate* plate,
                   std::string* error);

// The plate's logs as one CSV text: t, then imu<i>.ax .. imu<i>.gz per IMU.
std::string PlateToCsv(const SimulatedPlate& plate);

// The truth as JSON: each IMU's models, mountings, clock, and the poses.
std::string PlateTruthToJson(const SimulatedPlate& plate);

// The truth relative to IMU 0's orthogonalised accelerometer frame (the
// frame the multi-IMU estimate reports, methods/multi_imu.h): for IMU i the
// rotation from its orthogonalised accelerometer frame to IMU 0's,
//   C_i = (Q_0 R_0)^T Q_i R_i   (start mountings),
// and its gyroscope matrix in its own orthogonalised frame, R_i^T M_g.
Eigen::Matrix3d PlateTruthRotation(const SimulatedPlate& plate, int imu);
Eigen::Matrix3d PlateTruthGyroMatrix(const SimulatedPlate& plate, int imu);

}  // namespace gravcal

#endif  // GRAVCAL_SIMULATION_PLATE_SIMULATOR_H_
