#include "gravcal/estimation/coarse_fit.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <cmath>
#include <sstream>

#include "util/units.h"

namespace gravcal {

bool CoarseFitOptions::IsValid(std::string* error) const {
  if (!(axis_tolerance_deg > 0.0 && axis_tolerance_deg < 45.0)) {
    *error = "axis_tolerance_deg: must be in (0, 45) degrees";
    return false;
  }
  return true;
}

void AssignNominalAxes(const std::vector<Position>& positions, const AccelModel* model,
                       double tolerance_deg, std::vector<int>* nominal_up) {
  const size_t n = positions.size();
  nominal_up->assign(n, -1);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(HUGE_VAL);
  Eigen::Vector3d hi = -lo;
  for (const Position& p : positions) {
    lo = lo.cwiseMin(p.raw_mean);
    hi = hi.cwiseMax(p.raw_mean);
  }
  const Eigen::Vector3d mid = 0.5 * (lo + hi);
  Eigen::Vector3d half = 0.5 * (hi - lo);
  // An axis that never moved has no range of its own: borrow the largest.
  const double largest = half.maxCoeff();
  for (int i = 0; i < 3; ++i) {
    if (!(half(i) > 1e-3 * largest)) half(i) = largest;
  }
  const double cos_tol = std::cos(tolerance_deg * internal::kDegToRad);
  for (size_t k = 0; k < n; ++k) {
    if (positions[k].nominal_up >= 0) {
      (*nominal_up)[k] = positions[k].nominal_up;
      continue;
    }
    if (!(largest > 0.0)) continue;
    Eigen::Vector3d d = model != nullptr
                            ? model->Apply(positions[k].raw_mean)
                            : Eigen::Vector3d((positions[k].raw_mean - mid).cwiseQuotient(half));
    if (!(d.norm() > 0.0)) continue;
    d.normalize();
    int axis;
    const double c = d.cwiseAbs().maxCoeff(&axis);
    if (c >= cos_tol) (*nominal_up)[k] = 2 * axis + (d(axis) > 0.0 ? 0 : 1);
  }
}

bool SixPositionFit(const std::vector<Position>& positions, const std::vector<int>& nominal_up,
                    double gravity, Eigen::Vector3d* bias, Eigen::Matrix3d* matrix,
                    std::string* error) {
  // Normalise the raw readings (shift and scale) so G^T G is well conditioned
  // whatever the units; undone below.
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  int count = 0;
  for (size_t k = 0; k < positions.size(); ++k) {
    if (nominal_up[k] < 0) continue;
    center += positions[k].raw_mean;
    ++count;
  }
  if (count < 4) {
    std::ostringstream s;
    s << "six-position fit needs at least 4 positions with a known up axis, found " << count;
    *error = s.str();
    return false;
  }
  center /= count;
  double spread = 0.0;
  for (size_t k = 0; k < positions.size(); ++k) {
    if (nominal_up[k] >= 0) spread += (positions[k].raw_mean - center).squaredNorm();
  }
  spread = std::sqrt(spread / count);
  if (!(spread > 0.0)) {
    *error = "six-position fit: all positions have the same raw reading";
    return false;
  }
  Eigen::Matrix4d gtg = Eigen::Matrix4d::Zero();
  Eigen::Matrix<double, 4, 3> gty = Eigen::Matrix<double, 4, 3>::Zero();
  for (size_t k = 0; k < positions.size(); ++k) {
    if (nominal_up[k] < 0) continue;
    Eigen::Vector4d row;
    row << 1.0, (positions[k].raw_mean - center) / spread;
    gtg += row * row.transpose();
    gty += row * (gravity * NominalAxis(nominal_up[k])).transpose();
  }
  const Eigen::LDLT<Eigen::Matrix4d> ldlt(gtg);
  const Eigen::Vector4d d = ldlt.vectorD().cwiseAbs();
  if (ldlt.info() != Eigen::Success || !(d.minCoeff() > 1e-9 * d.maxCoeff())) {
    *error = "six-position fit: the axis-aligned positions do not span three dimensions";
    return false;
  }
  // Column i holds [B_i, M_i0, M_i1, M_i2] in normalised coordinates.
  const Eigen::Matrix<double, 4, 3> x = ldlt.solve(gty);
  const Eigen::Matrix3d m = x.bottomRows<3>().transpose() / spread;
  const Eigen::Vector3d b_affine = x.row(0).transpose() - m * center;
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(m);
  if (!lu.isInvertible()) {
    *error = "six-position fit: the fitted matrix is singular";
    return false;
  }
  *matrix = m;
  *bias = -lu.solve(b_affine);
  return true;
}

bool EllipsoidFit(const std::vector<Position>& positions, bool diagonal, double gravity,
                  AccelModel* model, std::string* error) {
  const int n = static_cast<int>(positions.size());
  const int needed = diagonal ? 6 : 9;
  if (n < needed) {
    std::ostringstream s;
    s << "ellipsoid fit needs at least " << needed << " positions, found " << n;
    *error = s.str();
    return false;
  }
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  for (const Position& p : positions) center += p.raw_mean;
  center /= n;
  double spread = 0.0;
  for (const Position& p : positions) spread += (p.raw_mean - center).squaredNorm();
  spread = std::sqrt(spread / n);
  if (!(spread > 0.0)) {
    *error = "ellipsoid fit: all positions have the same raw reading";
    return false;
  }
  // Quadric in normalised x: x^T Q x + p^T x + c = 0.
  const int cols = diagonal ? 7 : 10;
  Eigen::MatrixXd design(n, cols);
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector3d x = (positions[k].raw_mean - center) / spread;
    if (diagonal) {
      design.row(k) << x(0) * x(0), x(1) * x(1), x(2) * x(2), x(0), x(1), x(2), 1.0;
    } else {
      design.row(k) << x(0) * x(0), x(1) * x(1), x(2) * x(2), 2 * x(0) * x(1), 2 * x(0) * x(2),
          2 * x(1) * x(2), x(0), x(1), x(2), 1.0;
    }
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(design, Eigen::ComputeFullV);
  const Eigen::VectorXd coef = svd.matrixV().col(cols - 1);
  Eigen::Matrix3d q = Eigen::Matrix3d::Zero();
  Eigen::Vector3d p;
  double c;
  if (diagonal) {
    q.diagonal() << coef(0), coef(1), coef(2);
    p << coef(3), coef(4), coef(5);
    c = coef(6);
  } else {
    q << coef(0), coef(3), coef(4), coef(3), coef(1), coef(5), coef(4), coef(5), coef(2);
    p << coef(6), coef(7), coef(8);
    c = coef(9);
  }
  // Fix the overall sign so Q is positive definite when it is definite.
  if (q.trace() < 0.0) {
    q = -q;
    p = -p;
    c = -c;
  }
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(q);
  if (!lu.isInvertible()) {
    *error = "ellipsoid fit: the positions do not determine an ellipsoid (degenerate quadric)";
    return false;
  }
  const Eigen::Vector3d x0 = -0.5 * lu.solve(p);
  const double k = x0.dot(q * x0) - c;
  if (!(k > 0.0)) {
    *error = "ellipsoid fit: the fitted quadric is not an ellipsoid";
    return false;
  }
  const Eigen::Matrix3d a = q / k;  // (x - x0)^T a (x - x0) = 1
  const Eigen::LLT<Eigen::Matrix3d> llt(a);
  if (llt.info() != Eigen::Success) {
    *error = "ellipsoid fit: the fitted quadric is not an ellipsoid (not positive definite)";
    return false;
  }
  // a = L L^T; with U = g L^T / spread, |U (v - b)| = g on the ellipsoid.
  const Eigen::Matrix3d l = llt.matrixL();
  Eigen::Matrix3d upper = gravity * l.transpose() / spread;
  // LLT of a symmetric positive definite matrix gives U^T U = g^2 a, but U
  // must be upper triangular in v: L^T is upper triangular. Done.
  model->parameterization =
      diagonal ? AccelParameterization::kScale : AccelParameterization::kScaleMisalignment;
  model->bias = center + spread * x0;
  model->upper = upper;
  model->rotation.setIdentity();
  return true;
}

namespace {

// Casts a model to the parameterisation's shape.
void CastModel(AccelParameterization p, AccelModel* model) {
  model->parameterization = p;
  if (p == AccelParameterization::kAffine) return;
  if (p == AccelParameterization::kScale) {
    // Keep the length of each column of M as its scale: |M e_i| is what a
    // diagonal model can match of a misaligned sensor.
    const Eigen::Matrix3d m = model->matrix();
    model->upper = m.colwise().norm().asDiagonal();
  }
  model->rotation.setIdentity();
}

}  // namespace

bool CoarseFit(const std::vector<Position>& positions, double gravity,
               AccelParameterization parameterization, const CoarseFitOptions& options,
               CoarseFitResult* result) {
  *result = CoarseFitResult();
  std::string error;
  if (!options.IsValid(&error)) {
    result->message = error;
    return false;
  }
  const bool diagonal = parameterization == AccelParameterization::kScale;
  // A provisional ellipsoid, when there are enough positions, gives better
  // directions for assigning nominal axes than the range normalisation.
  AccelModel provisional;
  std::string ellipsoid_error;
  const bool have_ellipsoid =
      EllipsoidFit(positions, diagonal, gravity, &provisional, &ellipsoid_error);
  AssignNominalAxes(positions, have_ellipsoid ? &provisional : nullptr, options.axis_tolerance_deg,
                    &result->nominal_up);
  int faces_seen = 0;
  int axis_positions = 0;
  for (int up : result->nominal_up) {
    if (up >= 0) {
      ++axis_positions;
      faces_seen |= 1 << up;
    }
  }
  result->axis_positions = axis_positions;
  const bool all_faces = faces_seen == 0x3f;

  if ((all_faces && axis_positions >= 6) || !have_ellipsoid) {
    Eigen::Vector3d b;
    Eigen::Matrix3d m;
    if (SixPositionFit(positions, result->nominal_up, gravity, &b, &m, &error) &&
        AccelModel::FromMatrix(b, m, parameterization, &result->model)) {
      CastModel(parameterization, &result->model);
      result->method = CoarseMethod::kSixPosition;
      std::ostringstream s;
      s << "six-position least squares on " << axis_positions << " axis-aligned positions";
      result->message = s.str();
      return true;
    }
    if (!have_ellipsoid) {
      result->message = "no coarse fit possible: " + error + "; " + ellipsoid_error;
      return false;
    }
  }
  result->model = provisional;
  CastModel(parameterization, &result->model);
  result->method = CoarseMethod::kEllipsoid;
  std::ostringstream s;
  s << "ellipsoid fit on " << positions.size() << " positions (" << axis_positions
    << " axis-aligned)";
  result->message = s.str();
  return true;
}

}  // namespace gravcal
