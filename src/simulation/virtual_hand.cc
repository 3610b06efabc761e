// A person placing a unit where gravcal record says (virtual_hand.h).
#include "gravcal/simulation/virtual_hand.h"

#include <algorithm>
#include <cmath>

#include "util/units.h"

namespace gravcal {

namespace {

// Peak linear acceleration of the lift during a move, m/s^2.
constexpr double kLift = 2.0;

}  // namespace

bool VirtualHandOptions::IsValid(std::string* error) const {
  if (!(sample_rate > 0.0) || !(gravity > 0.0) || !(accel_counts_per_g > 0.0) ||
      !(gyro_counts_per_dps > 0.0)) {
    *error = "virtual hand: sample rate, gravity and counts must be positive";
  } else if (!(accel_noise >= 0.0) || !(gyro_noise >= 0.0) || !(tremor >= 0.0) ||
             !(tremor_seconds > 0.0) || !(placement_error_deg >= 0.0)) {
    *error = "virtual hand: noise, tremor and placement error must not be negative";
  } else if (!(reaction_seconds >= 0.0) || !(move_seconds > 0.0)) {
    *error = "virtual hand: the move must take time";
  } else if (!(saturate_counts >= 0.0)) {
    *error = "virtual hand: saturate_counts must not be negative";
  } else {
    return true;
  }
  return false;
}

VirtualHand::VirtualHand(const VirtualHandOptions& options, uint64_t seed)
    : options_(options), rng_(seed ^ 0x5eed1e55a11ce5ull) {
  accel_scale_ = options.gravity / options.accel_counts_per_g;
  const double gyro_scale = internal::kDegToRad / options.gyro_counts_per_dps;
  accel_truth_ = AccelModel::Random(AccelParameterization::kScaleMisalignment, accel_scale_,
                                    options.accel_scale_std, options.accel_misalignment_std,
                                    options.accel_bias_std / accel_scale_, &rng_);
  gyro_truth_ = GyroModel::Random(gyro_scale, options.gyro_scale_std, options.gyro_misalignment_std,
                                  options.gyro_bias_std / gyro_scale, &rng_);
  held_ = Placement(Eigen::Vector3d::UnitZ());
  from_ = held_;
  turn_ = Eigen::AngleAxisd(0.0, Eigen::Vector3d::UnitX());
}

Eigen::Quaterniond VirtualHand::Placement(const Eigen::Vector3d& up) {
  // Up onto navigation z, a random heading, then the placement error.
  const Eigen::Quaterniond level =
      Eigen::Quaterniond::FromTwoVectors(up.normalized(), Eigen::Vector3d::UnitZ());
  std::uniform_real_distribution<double> heading(-M_PI, M_PI);
  const double e = options_.placement_error_deg * internal::kDegToRad;
  const Eigen::Quaterniond error = Eigen::AngleAxisd(e * normal_(rng_), Eigen::Vector3d::UnitX()) *
                                   Eigen::AngleAxisd(e * normal_(rng_), Eigen::Vector3d::UnitY());
  return (error * Eigen::AngleAxisd(heading(rng_), Eigen::Vector3d::UnitZ()) * level).normalized();
}

void VirtualHand::MoveTo(const Eigen::Vector3d& up) {
  if (moving() || !(up.norm() > 0.0)) return;
  from_ = held_;
  held_ = Placement(up);
  turn_ = Eigen::AngleAxisd(from_.conjugate() * held_);
  std::uniform_real_distribution<double> spread(0.8, 1.2);
  move_begin_ = t_ + options_.reaction_seconds;
  move_end_ = move_begin_ + options_.move_seconds * spread(rng_);
}

ImuSample VirtualHand::Next() {
  t_ = static_cast<double>(index_++) / options_.sample_rate;
  const double g = options_.gravity;
  Eigen::Quaterniond attitude = held_;
  Eigen::Vector3d rate = Eigen::Vector3d::Zero();
  Eigen::Vector3d linear = Eigen::Vector3d::Zero();
  if (t_ < move_end_) {
    attitude = from_;
    if (t_ >= move_begin_) {
      // Minimum jerk along the turn, body frame: q = from * R(axis, s angle).
      const double length = move_end_ - move_begin_;
      const double x = (t_ - move_begin_) / length;
      const double s = x * x * x * (10.0 - 15.0 * x + 6.0 * x * x);
      const double ds = 30.0 * x * x * (1.0 - x) * (1.0 - x) / length;
      attitude = from_ * Eigen::Quaterniond(Eigen::AngleAxisd(s * turn_.angle(), turn_.axis()));
      rate = turn_.axis() * turn_.angle() * ds;
      linear = Eigen::Vector3d(0.0, 0.0, kLift * std::sin(2.0 * M_PI * x));
    }
  }
  // First-order tremor while held (the move has its own disturbance).
  const double a = std::exp(-1.0 / (options_.sample_rate * options_.tremor_seconds));
  for (int i = 0; i < 3; ++i) {
    tremor_(i) = a * tremor_(i) + std::sqrt(1.0 - a * a) * options_.tremor * normal_(rng_);
  }
  const Eigen::Vector3d force =
      attitude.conjugate() * (Eigen::Vector3d(0.0, 0.0, g) + linear) + tremor_;
  Eigen::Vector3d noise_a, noise_g;
  for (int i = 0; i < 3; ++i) {
    noise_a(i) = options_.accel_noise * normal_(rng_);
    noise_g(i) = options_.gyro_noise * normal_(rng_);
  }
  ImuSample sample;
  sample.t = t_;
  sample.accel = accel_truth_.Invert(force + noise_a);
  sample.gyro = gyro_truth_.Invert(rate + noise_g);
  for (int i = 0; i < 3; ++i) {
    sample.accel(i) = std::round(sample.accel(i));
    sample.gyro(i) = std::round(sample.gyro(i));
    if (options_.saturate_counts > 0.0) {
      const double c = options_.saturate_counts;
      sample.accel(i) = std::clamp(sample.accel(i), -c, c);
      sample.gyro(i) = std::clamp(sample.gyro(i), -c, c);
    }
  }
  return sample;
}

}  // namespace gravcal
