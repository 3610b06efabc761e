// The weights of the rotations gyroscope calibration (gyro_problem.h).
#include <cmath>
#include <sstream>

#include "methods/direction_noise.h"
#include "methods/gyro_problem.h"
#include "util/so3.h"
#include "util/units.h"

namespace gravcal {
namespace internal {

// Weights of every residual at x: fills directions, tangent bases and
// square-root information of the rotations (and their sigma in degrees, and
// the integrated attitude change R(dq) of each) and the static poses'
// square-root information.
bool WeighGyroResiduals(const GyroPrepared& prep, const GyroLayout& layout,
                        const std::vector<double>& x, const AccelModel& accel_now,
                        const Normalization& norm, GyroWeights* weights, std::string* error) {
  const Eigen::Matrix3d m =
      Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(&x[layout.matrix]);
  const double* g = layout.g >= 0 ? &x[layout.g] : nullptr;
  // Covariance of the normalised calibrated rate per sample.
  const Eigen::Matrix3d rate_cov = m * (prep.gyro_cov * prep.scale * prep.scale) * m.transpose();
  const Eigen::Matrix3d am = accel_now.matrix();
  weights->rotations.clear();
  weights->sigma_deg.clear();
  weights->turns.clear();
  for (size_t j = 0; j < prep.segments.size(); ++j) {
    const GyroSegment& seg = prep.segments[j];
    GyroRotationData d = prep.rotations[j];
    const Position& from = prep.positions[seg.from];
    const Position& to = prep.positions[seg.to];
    const Eigen::Vector3d a_s = accel_now.Apply(from.raw_mean);
    const Eigen::Vector3d a_e = accel_now.Apply(to.raw_mean);
    d.start_direction = a_s.normalized();
    d.end_direction = a_e.normalized();
    d.start_raw = (from.raw_mean - norm.center) / norm.scale;
    d.end_raw = (to.raw_mean - norm.center) / norm.scale;
    d.tangent = TangentBasis(d.end_direction);

    const size_t n = d.t.size();
    std::vector<double> path(4 * n);
    double dq[4];
    IntegrateGyroRotation<double>(d, &x[layout.bias], &x[layout.matrix], g, dq, path.data());
    const Eigen::Matrix3d rn = RotationOf(dq);
    // Rate noise of sample i, weighted by its share of the trapezoid, moved
    // into the end frame: R_n^T R_i (c_i^2 Sigma_w) R_i^T R_n.
    Eigen::Matrix3d angle_cov = Eigen::Matrix3d::Zero();
    for (size_t i = 0; i < n; ++i) {
      const double before = i > 0 ? d.t[i] - d.t[i - 1] : 0.0;
      const double after = i + 1 < n ? d.t[i + 1] - d.t[i] : 0.0;
      const double c = 0.5 * (before + after);
      const Eigen::Matrix3d ri = RotationOf(&path[4 * i]);
      angle_cov += c * c * ri * rate_cov * ri.transpose();
    }
    angle_cov = rn.transpose() * angle_cov * rn;
    const Eigen::Vector3d predicted = rn.transpose() * d.start_direction;
    const Eigen::Matrix3d px = Skew(predicted);
    const Eigen::Matrix3d cov =
        DirectionCovariance(am, a_e, to.raw_mean_cov) +
        rn.transpose() * DirectionCovariance(am, a_s, from.raw_mean_cov) * rn +
        px * angle_cov * px.transpose();
    const Eigen::Matrix2d cov2 = d.tangent * cov * d.tangent.transpose();
    if (!SqrtInformation<2>(cov2, &d.sqrt_information)) {
      std::ostringstream s;
      s << "rotation " << j << " has no usable noise estimate";
      *error = s.str();
      return false;
    }
    weights->sigma_deg.push_back(std::sqrt(cov2.trace()) * kRadToDeg);
    weights->turns.push_back(rn);
    weights->rotations.push_back(d);
  }
  weights->static_information.clear();
  for (const Eigen::Matrix3d& c : prep.static_gyro_cov) {
    Eigen::Matrix3d w;
    if (!SqrtInformation<3>(Eigen::Matrix3d(m * c * m.transpose()), &w)) {
      *error = "a static pose has no usable gyroscope noise estimate";
      return false;
    }
    weights->static_information.push_back(w);
  }
  return true;
}

}  // namespace internal
}  // namespace gravcal
