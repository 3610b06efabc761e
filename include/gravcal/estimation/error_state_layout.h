// gravcal/estimation/error_state_layout.h: where each error state sits in the handheld
// Kalman filter's state vector, and which sensor error terms it estimates.
//
// Sensor error model, the same form for the accelerometer and the gyroscope
// (Sun, Ding, Yan eq. 1 with E diagonal):
//
//   y_measured = (I + E) y + b + n
//
// y is the true specific force (m/s^2) or body rate (rad/s), b the bias in
// the same units, E a 3x3 matrix of dimensionless errors: its diagonal holds
// the scale-factor errors, its off-diagonal the cross-axis (misalignment)
// terms. Only the entries listed in SensorErrorTerms are estimated; the rest
// are held at zero. All zero = a perfect sensor.
//
// The state vector is
//   [ attitude error phi (3), velocity error (3), position error (3),
//     accel bias (3), accel E entries (n_a), gyro bias (3), gyro E entries (n_g),
//     lever arm (0 or 3) ]
// 21 states for the paper's model (n_a = n_g = 3, the diagonals). Adding the
// cross-axis terms is a matter of listing more entries: the filter takes
// every offset and size from this layout.
#ifndef GRAVCAL_ESTIMATION_ERROR_STATE_LAYOUT_H_
#define GRAVCAL_ESTIMATION_ERROR_STATE_LAYOUT_H_

#include <string>
#include <utility>
#include <vector>

namespace gravcal {

enum class StateBlock {
  kAttitude,
  kVelocity,
  kPosition,
  kAccelBias,
  kAccelMatrix,
  kGyroBias,
  kGyroMatrix,
  // Optional: the sensor's position relative to the point the unit turns
  // about, body frame, m (size 0 when not estimated).
  kLeverArm,
};

struct SensorErrorTerms {
  // (row, col) entries of E that are estimated, in state order.
  std::vector<std::pair<int, int>> matrix_entries = {{0, 0}, {1, 1}, {2, 2}};

  // The paper's model: scale-factor errors only (the default).
  static SensorErrorTerms ScaleOnly();
  // Scale factors and all six cross-axis terms.
  static SensorErrorTerms ScaleAndCrossAxis();
  // Scale factors and the upper-triangular cross-axis terms (0,1), (0,2),
  // (1,2): E upper triangular, so the sensor's x axis and xy plane define
  // the body frame (the gauge-free choice of accel_model.h). Gravity and
  // pseudo-measurements cannot see a rotation of all sensor axes together,
  // so with full cross-axis terms on both sensors three combinations are
  // not determined; this form for the accelerometer with the full form for
  // the gyroscope leaves none.
  static SensorErrorTerms ScaleAndUpperCrossAxis();

  // Entries inside 0..2 and not repeated.
  bool IsValid(std::string* error) const;
};

class ErrorStateLayout {
 public:
  // The navigation error states: attitude, velocity, position.
  static constexpr int kNavigationSize = 9;

  ErrorStateLayout(const SensorErrorTerms& accel = SensorErrorTerms(),
                   const SensorErrorTerms& gyro = SensorErrorTerms(), bool lever_arm = false);

  int size() const { return size_; }
  int offset(StateBlock block) const { return offset_[static_cast<int>(block)]; }
  int block_size(StateBlock block) const { return size_of_[static_cast<int>(block)]; }
  const SensorErrorTerms& accel() const { return accel_; }
  const SensorErrorTerms& gyro() const { return gyro_; }

  // One name per state: attitude_x, velocity_x, position_x, accel_bias_x,
  // accel_scale_x (diagonal entry) or accel_cross_xy (entry x, y),
  // gyro_bias_x, gyro_scale_x, gyro_cross_xy, lever_arm_x.
  const std::vector<std::string>& names() const { return names_; }

 private:
  SensorErrorTerms accel_;
  SensorErrorTerms gyro_;
  int offset_[8];
  int size_of_[8];
  int size_ = 0;
  std::vector<std::string> names_;
};

}  // namespace gravcal

#endif  // GRAVCAL_ESTIMATION_ERROR_STATE_LAYOUT_H_
