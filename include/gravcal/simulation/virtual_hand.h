// gravcal/simulation/virtual_hand.h: a person placing a unit where gravcal
// record says, as a stream of samples (the closed loop of issue 37).
//
// Independent of simulator.h on purpose: a sensor drawn once from the seed
// (AccelModel::Random, GyroModel::Random), and a hand that, told an up
// direction, waits its reaction time, picks the unit up (a lift and its
// linear acceleration), turns it along the shortest path (minimum jerk) to
// the attitude that puts that direction up, with a placement error of
// placement_error_deg per level axis and a random heading, and holds it
// there with tremor until told the next one. The raw outputs are
//   v = M^-1 (f + n_a) + b,   u = M_g^-1 (w + n_g) + b_g,
// f the specific force (gravity up, plus the lift and the tremor while
// held), w the body rate of the turn, n white; rounded to counts, and
// clipped at +-saturate_counts when that is set.
#ifndef GRAVCAL_SIMULATION_VIRTUAL_HAND_H_
#define GRAVCAL_SIMULATION_VIRTUAL_HAND_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <random>
#include <string>

#include "gravcal/core/accel_model.h"
#include "gravcal/core/gyro_model.h"
#include "gravcal/io/imu_stream.h"

namespace gravcal {

struct VirtualHandOptions {
  double sample_rate = 100.0;
  double gravity = 9.80665;
  double accel_counts_per_g = 16384.0;
  double gyro_counts_per_dps = 131.0;
  // White noise per sample: m/s^2, rad/s.
  double accel_noise = 0.02;
  double gyro_noise = 0.002;
  // Hand tremor while held: m/s^2 rms, first-order with this time constant.
  double tremor = 0.005;
  double tremor_seconds = 0.05;
  double placement_error_deg = 2.0;
  // Seconds from an instruction to the start of the move; the move.
  double reaction_seconds = 0.5;
  double move_seconds = 2.5;
  // The unit's sensor (truth) is drawn with these standard deviations.
  double accel_bias_std = 0.3;  // m/s^2
  double accel_scale_std = 0.02;
  double accel_misalignment_std = 0.01;  // rad
  double gyro_bias_std = 0.02;           // rad/s
  double gyro_scale_std = 0.02;
  double gyro_misalignment_std = 0.005;  // rad
  // > 0: raw values clipped at +-this many counts.
  double saturate_counts = 0.0;

  bool IsValid(std::string* error) const;
};

class VirtualHand {
 public:
  // Starts held with +Z up (placement error and heading as for any pose).
  VirtualHand(const VirtualHandOptions& options, uint64_t seed);

  // The next instruction: point `up` (sensor frame) up. Ignored while a
  // move is under way (the person finishes it first).
  void MoveTo(const Eigen::Vector3d& up);
  // The next sample (time from 0 at sample_rate).
  ImuSample Next();
  bool moving() const { return move_end_ > t_; }

  const AccelModel& accel_truth() const { return accel_truth_; }
  const GyroModel& gyro_truth() const { return gyro_truth_; }
  double accel_scale() const { return accel_scale_; }

 private:
  Eigen::Quaterniond Placement(const Eigen::Vector3d& up);

  VirtualHandOptions options_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  AccelModel accel_truth_;
  GyroModel gyro_truth_;
  double accel_scale_ = 1.0;
  double t_ = 0.0;
  size_t index_ = 0;
  // The attitude (body to navigation, z up) held, and the move under way.
  Eigen::Quaterniond held_ = Eigen::Quaterniond::Identity();
  Eigen::Quaterniond from_ = Eigen::Quaterniond::Identity();
  Eigen::AngleAxisd turn_;
  double move_begin_ = 0.0;
  double move_end_ = 0.0;
  Eigen::Vector3d tremor_ = Eigen::Vector3d::Zero();
};

}  // namespace gravcal

#endif  // GRAVCAL_SIMULATION_VIRTUAL_HAND_H_
