#include "methods/gyro_initial_matrix.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "util/so3.h"

namespace gravcal {
namespace internal {
namespace {

// Length of the windows of the linear initial estimate, s.
constexpr double kInitialWindowSeconds = 0.05;

}  // namespace

bool GyroInitialMatrix(const ImuLog& log, const std::vector<GyroSegment>& segments,
                       const std::vector<std::vector<Eigen::Vector3d>>& forces,
                       const Eigen::Vector3d& center, GyroParameterization p, Eigen::Matrix3d* m0,
                       std::string* error) {
  Eigen::Matrix<double, 9, 9> normal = Eigen::Matrix<double, 9, 9>::Zero();
  Eigen::Matrix<double, 9, 1> rhs = Eigen::Matrix<double, 9, 1>::Zero();
  double aa = 0.0, ab = 0.0;
  const Eigen::Matrix<double, 9, 1> identity =
      (Eigen::Matrix<double, 9, 1>() << 1, 0, 0, 0, 1, 0, 0, 0, 1).finished();
  for (size_t n = 0; n < segments.size(); ++n) {
    const GyroSegment& s = segments[n];
    const std::vector<Eigen::Vector3d>& force = forces[n];
    const double dt = (log.t[s.last] - log.t[s.first]) / static_cast<double>(s.last - s.first);
    const size_t window = std::max<size_t>(1, std::lround(kInitialWindowSeconds / dt));
    for (size_t i = s.first; i + window <= s.last; i += window) {
      // d([f]x M d)/dM(r, c) = [f]x e_r d_c: column 3 r + c (row-major vec(M)).
      Eigen::Matrix<double, 3, 9> k = Eigen::Matrix<double, 3, 9>::Zero();
      for (size_t j = i; j < i + window; ++j) {
        const double h = log.t[j + 1] - log.t[j];
        for (size_t e : {j, j + 1}) {
          const Eigen::Vector3d d = log.gyro[e] - center;
          const Eigen::Matrix3d fx = Skew(force[e - s.first]);
          for (int r = 0; r < 3; ++r) {
            for (int c = 0; c < 3; ++c) k.col(3 * r + c) += 0.5 * h * d(c) * fx.col(r);
          }
        }
      }
      const Eigen::Vector3d df = force[i + window - s.first] - force[i - s.first];
      const Eigen::Vector3d iso = k * identity;
      aa += iso.squaredNorm();
      ab += iso.dot(df);
      normal += k.transpose() * k;
      rhs += k.transpose() * df;
    }
  }
  if (!(aa > 0.0) || !std::isfinite(ab)) {
    *error = "the log shows no rotation between the static poses";
    return false;
  }
  const double s = ab / aa;
  if (!(std::fabs(s) > 0.0) || !std::isfinite(s)) {
    *error = "the initial gyroscope scale could not be estimated from the rotations";
    return false;
  }
  Eigen::Matrix<double, 9, 1> m = s * identity;
  if (p != GyroParameterization::kBias) {
    std::vector<int> free;
    for (int i = 0; i < 9; ++i) {
      if (p == GyroParameterization::kFull || i % 4 == 0) free.push_back(i);
    }
    const int nf = static_cast<int>(free.size());
    Eigen::MatrixXd n(nf, nf);
    Eigen::VectorXd g(nf);
    for (int i = 0; i < nf; ++i) {
      g(i) = rhs(free[i]);
      for (int j = 0; j < nf; ++j) n(i, j) = normal(free[i], free[j]);
    }
    const double lambda = 1e-3 * n.trace() / nf;
    Eigen::VectorXd prior(nf);
    for (int i = 0; i < nf; ++i) prior(i) = s * identity(free[i]);
    n += lambda * Eigen::MatrixXd::Identity(nf, nf);
    g += lambda * prior;
    const Eigen::VectorXd x = n.ldlt().solve(g);
    for (int i = 0; i < nf; ++i) m(free[i]) = x(i);
  }
  *m0 = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(m.data());
  if (!m0->allFinite() || !(std::fabs(m0->determinant()) > 0.0)) {
    *error =
        "the initial gyroscope matrix is singular: the rotations do not show the gyroscope "
        "turning";
    return false;
  }
  return true;
}

}  // namespace internal
}  // namespace gravcal
