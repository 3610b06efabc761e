// gravcal/core/position.h: one static interval of a log and the static
// position the calibration makes of it.
//
// The mean raw accelerometer vector of a static interval and the covariance
// of that mean (sample covariance / sample count, raw units^2), plus when and
// at what temperature it was taken. nominal_up names the housing axis that
// pointed up, when known: 0..5 = +x, -x, +y, -y, +z, -z; -1 = unknown.
#ifndef GRAVCAL_CORE_POSITION_H_
#define GRAVCAL_CORE_POSITION_H_

#include <Eigen/Core>
#include <string>
#include <vector>

namespace gravcal {

// One static interval: samples [begin, end) of the log, and their statistics.
struct StaticInterval {
  size_t begin = 0;
  size_t end = 0;
  double t_begin = 0.0;
  double t_end = 0.0;
  Eigen::Vector3d accel_mean = Eigen::Vector3d::Zero();
  // Sample covariance of the raw accelerometer over the interval.
  Eigen::Matrix3d accel_cov = Eigen::Matrix3d::Zero();
  // Smallest nonzero step between consecutive raw accelerometer samples in
  // the interval (its first 256 samples), per axis: the quantisation step for
  // integer counts; 0 when the axis never changed.
  Eigen::Vector3d accel_resolution = Eigen::Vector3d::Zero();
  // Zero when the log has no gyroscope.
  Eigen::Vector3d gyro_mean = Eigen::Vector3d::Zero();
  Eigen::Matrix3d gyro_cov = Eigen::Matrix3d::Zero();
  // NaN when the log has no temperature.
  double temperature_mean = 0.0;

  size_t count() const { return end - begin; }
};

struct Position {
  Eigen::Vector3d raw_mean = Eigen::Vector3d::Zero();
  Eigen::Matrix3d raw_mean_cov = Eigen::Matrix3d::Identity();
  double t_begin = 0.0;
  double t_end = 0.0;
  size_t sample_count = 0;
  double temperature = 0.0;
  int nominal_up = -1;
};

// The unit vector (body frame) of nominal axis 0..5 (+x, -x, +y, -y, +z, -z).
Eigen::Vector3d NominalAxis(int nominal_up);
// "+x", "-x", ... or "?" for -1.
std::string NominalAxisName(int nominal_up);

// One Position per interval, with the covariance of the mean.
std::vector<Position> PositionsFromIntervals(const std::vector<StaticInterval>& intervals);

}  // namespace gravcal

#endif  // GRAVCAL_CORE_POSITION_H_
