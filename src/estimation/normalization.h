// Private: a change of raw units that makes the magnitude fit well
// conditioned whatever the sensor's units.
//
// Raw counts put the bias near 1e3 and U near 1e-3, and J^T J then has a
// condition number near 1e15. With v' = (v - c) / s, c the initial bias and s
// the raw units per m/s^2 of the initial model, the model becomes
// b' = (b - c) / s and U' = s U: b' is near 0 and U' near the identity. The
// fit is done in the primed variables and mapped back; the covariance maps
// back linearly (b = c + s b', U = U' / s).
#ifndef GRAVCAL_SRC_ESTIMATION_NORMALIZATION_H_
#define GRAVCAL_SRC_ESTIMATION_NORMALIZATION_H_

#include <Eigen/Core>
#include <vector>

#include "gravcal/core/accel_model.h"
#include "gravcal/core/position.h"

namespace gravcal {
namespace internal {

struct Normalization {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double scale = 1.0;

  static Normalization For(const AccelModel& initial) {
    Normalization n;
    n.center = initial.bias;
    const double mean_diag = initial.upper.diagonal().cwiseAbs().mean();
    n.scale = mean_diag > 0.0 ? 1.0 / mean_diag : 1.0;
    return n;
  }

  std::vector<Position> Apply(const std::vector<Position>& positions) const {
    std::vector<Position> out = positions;
    for (Position& p : out) {
      p.raw_mean = (p.raw_mean - center) / scale;
      p.raw_mean_cov /= scale * scale;
    }
    return out;
  }

  AccelModel Apply(const AccelModel& model) const {
    AccelModel out = model;
    out.bias = (model.bias - center) / scale;
    out.upper = model.upper * scale;
    return out;
  }

  AccelModel Undo(const AccelModel& model) const {
    AccelModel out = model;
    out.bias = center + scale * model.bias;
    out.upper = model.upper / scale;
    return out;
  }

  // Covariance of (b, free entries of U) from that of (b', U').
  Eigen::MatrixXd Undo(const Eigen::MatrixXd& covariance) const {
    Eigen::VectorXd d = Eigen::VectorXd::Constant(covariance.rows(), 1.0 / scale);
    d.head<3>().setConstant(scale);
    return d.asDiagonal() * covariance * d.asDiagonal();
  }
};

}  // namespace internal

}  // namespace gravcal

#endif  // GRAVCAL_SRC_ESTIMATION_NORMALIZATION_H_
