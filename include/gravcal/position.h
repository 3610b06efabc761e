// gravcal/position.h: one static position as the calibration sees it.
//
// The mean raw accelerometer vector of a static interval and the covariance
// of that mean (sample covariance / sample count, raw units^2), plus when and
// at what temperature it was taken. nominal_up names the housing axis that
// pointed up, when known: 0..5 = +x, -x, +y, -y, +z, -z; -1 = unknown.
#ifndef GRAVCAL_POSITION_H_
#define GRAVCAL_POSITION_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "gravcal/static_detector.h"

namespace gravcal {

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

#endif  // GRAVCAL_POSITION_H_
