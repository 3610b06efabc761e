// The consumer programs' shared fixture: a known accelerometer a = U (v - b)
// seen at twelve static directions without noise, and a relative-error check.
#ifndef GRAVCAL_CONSUMER_KNOWN_SENSOR_H_
#define GRAVCAL_CONSUMER_KNOWN_SENSOR_H_

#include <Eigen/Core>
#include <Eigen/LU>
#include <iostream>
#include <vector>

#include "gravcal/core/position.h"

namespace consumer {

constexpr double kGravity = 9.80665;
constexpr double kTolerance = 1e-6;

struct KnownSensor {
  Eigen::Vector3d bias{0.12, -0.08, 0.05};
  Eigen::Matrix3d upper = (Eigen::Matrix3d() << 1.01, 0.004, -0.003,  //
                           0.0, 0.985, 0.006,                         //
                           0.0, 0.0, 1.02)
                              .finished();

  // The raw reading when the specific force is `f` (m/s^2).
  Eigen::Vector3d Raw(const Eigen::Vector3d& f) const { return upper.inverse() * f + bias; }

  // Twelve static positions: the six axes and six diagonals, no noise in the
  // mean, a nominal covariance so that sigma is defined.
  std::vector<gravcal::Position> Positions() const {
    const std::vector<Eigen::Vector3d> directions = {
        {1, 0, 0}, {-1, 0, 0}, {0, 1, 0},  {0, -1, 0}, {0, 0, 1},   {0, 0, -1},
        {1, 1, 0}, {-1, 0, 1}, {0, -1, 1}, {1, 1, 1},  {-1, -1, 1}, {1, -1, -1}};
    std::vector<gravcal::Position> positions;
    for (const Eigen::Vector3d& d : directions) {
      gravcal::Position p;
      p.raw_mean = Raw(kGravity * d.normalized());
      p.raw_mean_cov = 1e-8 * Eigen::Matrix3d::Identity();
      p.sample_count = 1000;
      positions.push_back(p);
    }
    return positions;
  }
};

// ||estimate - truth|| / ||truth|| <= kTolerance; otherwise prints both.
inline bool CheckClose(const char* what, const Eigen::MatrixXd& estimate,
                       const Eigen::MatrixXd& truth) {
  const double error = (estimate - truth).norm() / truth.norm();
  if (!(error <= kTolerance)) {
    std::cerr << "consumer: " << what << " is off by " << error << " relative (limit " << kTolerance
              << ")\nestimate:\n"
              << estimate << "\ntruth:\n"
              << truth << "\n";
    return false;
  }
  return true;
}

}  // namespace consumer

#endif  // GRAVCAL_CONSUMER_KNOWN_SENSOR_H_
