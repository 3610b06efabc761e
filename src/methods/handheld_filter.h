// Private: the error-state Kalman filter of the handheld calibration
// (handheld_kalman.h) over one pass of the log: the strapdown navigation
// with the sensor estimates fed back, the process model accumulated per IMU
// sample (handheld_filter.cc) and the zero-velocity, zero-position
// pseudo-measurement update (handheld_update.cc).
#ifndef GRAVCAL_SRC_METHODS_HANDHELD_FILTER_H_
#define GRAVCAL_SRC_METHODS_HANDHELD_FILTER_H_

#include <Eigen/Core>
#include <Eigen/LU>

#include "estimation/strapdown.h"
#include "gravcal/estimation/error_state_layout.h"
#include "gravcal/methods/handheld_kalman.h"

namespace gravcal {
namespace internal {

// One sensor's current estimate: y_hat = (I + E)^-1 (y_m - b).
struct HandheldSensorEstimate {
  Eigen::Vector3d bias = Eigen::Vector3d::Zero();
  Eigen::Matrix3d e = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d inverse = Eigen::Matrix3d::Identity();

  Eigen::Vector3d Correct(const Eigen::Vector3d& measured) const {
    return inverse * (measured - bias);
  }
  void Refresh() { inverse = (Eigen::Matrix3d::Identity() + e).inverse(); }
};

// The error-state filter over one pass of the log (see handheld_kalman.h).
class HandheldFilter {
 public:
  using Mat3 = Eigen::Matrix3d;
  using Vec3 = Eigen::Vector3d;
  using Mat9 = Eigen::Matrix<double, 9, 9>;
  using Mat9X = Eigen::Matrix<double, 9, Eigen::Dynamic>;

  HandheldFilter(const HandheldKalmanOptions& options, double gravity,
                 const ErrorStateLayout& layout);

  // Starts from sensor estimates (accel, gyro) at the coarse levelling of
  // the mean measured specific force f_mean of the still period, corrected
  // with `accel`.
  void Initialize(const Vec3& f_mean, const HandheldSensorEstimate& accel,
                  const HandheldSensorEstimate& gyro);

  // One IMU step from sample (f0, w0) to (f1, w1), measured values in SI.
  void Step(double dt, const Vec3& f0_m, const Vec3& w0_m, const Vec3& f1_m, const Vec3& w1_m);

  double elapsed() const { return elapsed_; }

  // Covariance to now: P = Phi P Phi^T + Q.
  void Propagate();

  // Zero-velocity and zero-position pseudo-measurements, Joseph form,
  // closed-loop feedback. Returns the normalised innovation squared.
  double Update();

  bool Healthy() const;

  // Current estimate of each state in layout order (navigation errors are
  // zero after feedback; sensor states are the estimates themselves).
  double SensorValue(int state) const;

  const Eigen::MatrixXd& covariance() const { return p_; }
  const Eigen::MatrixXd& initial_covariance() const { return p_initial_; }
  const HandheldSensorEstimate& accel() const { return accel_; }
  const HandheldSensorEstimate& gyro() const { return gyro_; }

 private:
  // Accumulates the transition and process noise of one IMU step.
  void Accumulate(const StrapdownStep& s);
  // Moves the estimated errors x into the navigation state and the sensor
  // estimates.
  void Feedback(const Eigen::VectorXd& x);

  const HandheldKalmanOptions& options_;
  const ErrorStateLayout& layout_;
  Strapdown strapdown_;
  HandheldSensorEstimate accel_;
  HandheldSensorEstimate gyro_;
  Eigen::MatrixXd p_;
  Eigen::MatrixXd p_initial_;
  Eigen::MatrixXd joseph_;
  Eigen::Matrix<double, 6, Eigen::Dynamic> h_;
  // Lever arm estimate (zero when not estimated) and the latest corrected
  // body rate.
  Vec3 lever_ = Vec3::Zero();
  Vec3 rate_ = Vec3::Zero();
  // Accumulated since the last epoch: navigation transition, navigation <-
  // sensor transition, navigation process noise.
  Mat9 a_;
  Mat9X b_;
  Mat9 q_;
  double elapsed_ = 0.0;
};

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_METHODS_HANDHELD_FILTER_H_
