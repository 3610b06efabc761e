#include "gravcal/methods/gyro_calibration.h"

#include <ceres/ceres.h>
#include <ceres/covariance.h>
#include <ceres/manifold.h>
#include <glog/logging.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <sstream>

#include "estimation/accel_uncertainty.h"
#include "gravcal/residuals/gravity_magnitude_residual.h"
#include "gravcal/residuals/gyro_rotation_residual.h"
#include "gravcal/residuals/gyro_static_residual.h"
#include "gravcal/estimation/observability.h"
#include "gravcal/core/position.h"
#include "estimation/normalization.h"
#include "estimation/robust_loss.h"
#include "util/statistics.h"

namespace gravcal {

bool GyroCalibrationOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& what) {
    if (error) *error = what;
    return false;
  };
  if (!(loss_scale > 0.0 && std::isfinite(loss_scale))) {
    return fail("gyro_loss_scale: must be positive");
  }
  if (!(max_matrix_std > 0.0) || !(max_g_sensitivity_std > 0.0)) {
    return fail("gyro max_matrix_std, max_g_sensitivity_std: must be positive");
  }
  if (!(max_rotation_seconds > 0.0)) return fail("gyro max_rotation_seconds: must be positive");
  if (!(edge_seconds >= 0.0 && std::isfinite(edge_seconds))) {
    return fail("gyro edge_seconds: must be zero or positive");
  }
  if (max_iterations < 1) return fail("gyro max_iterations: must be at least 1");
  if (!(function_tolerance > 0.0) || !(gradient_tolerance > 0.0) || !(parameter_tolerance > 0.0)) {
    return fail("gyro solver tolerances: must be positive");
  }
  return true;
}

namespace {

constexpr double kRadToDeg = 180.0 / M_PI;
constexpr const char* kAxisNames = "xyz";
// Length of the windows of the linear initial estimate, s.
constexpr double kInitialWindowSeconds = 0.05;
// Rotations needed at least, per parameterization (2 residuals each; the
// bias comes from the static poses).
int MinRotations(GyroParameterization p) {
  switch (p) {
    case GyroParameterization::kBias:
      return 1;
    case GyroParameterization::kScale:
      return 2;
    default:
      return 5;
  }
}

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d s;
  s << 0.0, -v(2), v(1), v(2), 0.0, -v(0), -v(1), v(0), 0.0;
  return s;
}

// W with W C W^T = I: the inverse of the lower Cholesky factor of C.
template <int N>
bool SqrtInformation(const Eigen::Matrix<double, N, N>& c, Eigen::Matrix<double, N, N>* w) {
  Eigen::LLT<Eigen::Matrix<double, N, N>> llt(c);
  if (llt.info() != Eigen::Success) return false;
  *w = llt.matrixL().solve(Eigen::Matrix<double, N, N>::Identity());
  return w->allFinite();
}

// Covariance of d = a / |a|, a = M (v - b), from the covariance of v.
Eigen::Matrix3d DirectionCovariance(const Eigen::Matrix3d& m, const Eigen::Vector3d& a,
                                    const Eigen::Matrix3d& raw_cov) {
  const Eigen::Vector3d d = a.normalized();
  const Eigen::Matrix3d p = (Eigen::Matrix3d::Identity() - d * d.transpose()) / a.norm();
  return p * m * raw_cov * m.transpose() * p.transpose();
}

// Two orthonormal rows perpendicular to the unit vector d.
Eigen::Matrix<double, 2, 3> TangentBasis(const Eigen::Vector3d& d) {
  int least = 0;
  d.cwiseAbs().minCoeff(&least);
  const Eigen::Vector3d e1 = d.cross(Eigen::Vector3d::Unit(least)).normalized();
  const Eigen::Vector3d e2 = d.cross(e1);
  Eigen::Matrix<double, 2, 3> basis;
  basis.row(0) = e1.transpose();
  basis.row(1) = e2.transpose();
  return basis;
}

// The rotation matrix of a (w, x, y, z) quaternion.
Eigen::Matrix3d RotationOf(const double* q) {
  return Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
}

// M = s I, the only free direction of the common-scale model.
class IsotropicScaleManifold : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 9; }
  int TangentSize() const override { return 1; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override {
    for (int i = 0; i < 9; ++i) x_plus_delta[i] = x[i] + (i % 4 == 0 ? delta[0] : 0.0);
    return true;
  }
  bool PlusJacobian(const double* /*x*/, double* jacobian) const override {
    for (int i = 0; i < 9; ++i) jacobian[i] = i % 4 == 0 ? 1.0 : 0.0;
    return true;
  }
  bool Minus(const double* y, const double* x, double* y_minus_x) const override {
    y_minus_x[0] = (y[0] - x[0] + y[4] - x[4] + y[8] - x[8]) / 3.0;
    return true;
  }
  bool MinusJacobian(const double* /*x*/, double* jacobian) const override {
    for (int i = 0; i < 9; ++i) jacobian[i] = i % 4 == 0 ? 1.0 / 3.0 : 0.0;
    return true;
  }
};

// One rotation: samples first..last, between intervals from and to.
struct Segment {
  int from = 0;
  int to = 0;
  size_t first = 0;
  size_t last = 0;
};

// The ambient parameter vector: b' (3), M' (9), [G (9)], [b_a' (3), U' (6)]
// in normalised units (see Problem below), with the free directions.
struct Layout {
  int bias = 0;
  int matrix = 3;
  int g = -1;
  int accel_bias = -1;
  int accel_upper = -1;
  int size = 12;
  std::vector<std::string> names;

  Layout(bool with_g, bool joint) {
    for (int i = 0; i < 3; ++i) names.push_back(std::string("bias_") + kAxisNames[i]);
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        names.push_back(std::string("m_") + kAxisNames[r] + kAxisNames[c]);
      }
    }
    if (with_g) {
      g = size;
      size += 9;
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) {
          names.push_back(std::string("g_") + kAxisNames[r] + kAxisNames[c]);
        }
      }
    }
    if (joint) {
      accel_bias = size;
      accel_upper = size + 3;
      size += 9;
      for (const std::string& n : MagnitudeParameterNames(AccelParameterization::kAffine)) {
        names.push_back("accel_" + n);
      }
    }
  }
};

// Everything the problem needs, prepared once.
struct Prepared {
  std::vector<Segment> segments;
  // Normalised raw gyroscope: u' = (u - center) * scale.
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double scale = 1.0;
  // Per-sample covariance of the raw gyroscope (pooled over the poses).
  Eigen::Matrix3d gyro_cov = Eigen::Matrix3d::Zero();
  // Static poses: normalised mean gyroscope, its covariance (normalised),
  // calibrated mean force.
  std::vector<Eigen::Vector3d> static_gyro;
  std::vector<Eigen::Matrix3d> static_gyro_cov;
  std::vector<Eigen::Vector3d> static_force;
  std::vector<Position> positions;
  // The positions in the accelerometer's normalised units (joint fit).
  std::vector<Position> normalized_positions;
  // Rotation data without weights (t, normalised gyro, force, raw means).
  std::vector<GyroRotationData> rotations;
};

// The smallest nonzero step between consecutive raw gyroscope samples in
// the static intervals (the quantisation step), or 0.
double GyroStep(const ImuLog& log, const std::vector<StaticInterval>& intervals) {
  double step = 0.0;
  for (const StaticInterval& s : intervals) {
    const size_t end = std::min(s.end, s.begin + 256);
    for (size_t i = s.begin + 1; i < end; ++i) {
      for (int a = 0; a < 3; ++a) {
        const double d = std::fabs(log.gyro[i](a) - log.gyro[i - 1](a));
        if (d > 0.0 && (step == 0.0 || d < step)) step = d;
      }
    }
  }
  return step;
}

// Linear initial M_g from df/dt = f x w over short windows of the
// rotations: f(t + T) - f(t) = sum_i h_i [f_i]x M (u_i - c), one 3x9 block
// per window (row-major vec(M)). The common scale is fitted first; the free
// entries are then pulled weakly towards it, so an axis the rotations do not
// excite stays at the common scale instead of at noise.
bool InitialMatrix(const ImuLog& log, const std::vector<Segment>& segments,
                   const std::vector<std::vector<Eigen::Vector3d>>& forces,
                   const Eigen::Vector3d& center, GyroParameterization p, Eigen::Matrix3d* m0,
                   std::string* error) {
  Eigen::Matrix<double, 9, 9> normal = Eigen::Matrix<double, 9, 9>::Zero();
  Eigen::Matrix<double, 9, 1> rhs = Eigen::Matrix<double, 9, 1>::Zero();
  double aa = 0.0, ab = 0.0;
  const Eigen::Matrix<double, 9, 1> identity =
      (Eigen::Matrix<double, 9, 1>() << 1, 0, 0, 0, 1, 0, 0, 0, 1).finished();
  for (size_t n = 0; n < segments.size(); ++n) {
    const Segment& s = segments[n];
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

// Cuts the log into rotations and prepares the normalised data. On bad input
// returns false with *error set.
bool Prepare(const ImuLog& log, const std::vector<StaticInterval>& intervals,
             const AccelModel& accel, const GyroCalibrationOptions& options, Prepared* prep,
             Eigen::Matrix3d* m0, std::vector<std::string>* warnings, std::string* error) {
  const std::string name = log.source.empty() ? "log" : log.source;
  if (!log.Validate(error)) return false;
  if (!log.has_gyro()) {
    *error = name +
             ": the log has no gyroscope columns (gx, gy, gz); the gyroscope calibration needs "
             "them (set gyro_model: none to calibrate the accelerometer only)";
    return false;
  }
  if (intervals.size() < 2) {
    std::ostringstream s;
    s << name << ": found " << intervals.size()
      << " static poses; the gyroscope calibration needs at least two (and rotations between "
         "them)";
    *error = s.str();
    return false;
  }
  std::vector<StaticInterval> poses;
  for (size_t k = 0; k < intervals.size(); ++k) {
    const StaticInterval& iv = intervals[k];
    if (iv.begin + 2 > iv.end || iv.end > log.size() ||
        (k > 0 && iv.begin < intervals[k - 1].end)) {
      std::ostringstream s;
      s << name << ": static interval " << k << " (samples " << iv.begin << ".." << iv.end
        << ") is empty, outside the log or not after the previous one";
      *error = s.str();
      return false;
    }
    // The core of the interval: its edges go to the rotations.
    const double dt =
        (log.t[iv.end - 1] - log.t[iv.begin]) / static_cast<double>(iv.end - 1 - iv.begin);
    const size_t edge =
        std::min<size_t>(std::lround(options.edge_seconds / dt), (iv.end - iv.begin) / 4);
    poses.push_back(MakeInterval(log, iv.begin + edge, iv.end - edge));
  }
  prep->positions = PositionsFromIntervals(poses);

  // Rotations: from the last sample of one pose to the first of the next.
  for (size_t k = 0; k + 1 < poses.size(); ++k) {
    Segment seg;
    seg.from = static_cast<int>(k);
    seg.to = static_cast<int>(k + 1);
    seg.first = poses[k].end - 1;
    seg.last = poses[k + 1].begin;
    const double seconds = log.t[seg.last] - log.t[seg.first];
    if (seconds > options.max_rotation_seconds) {
      std::ostringstream s;
      s.precision(3);
      s << "the " << seconds << " s between static poses " << k << " and " << k + 1
        << " (t = " << log.t[seg.first] << " s) is longer than max_rotation_seconds; it is not "
        << "used as a rotation";
      warnings->push_back(s.str());
      continue;
    }
    prep->segments.push_back(seg);
  }

  if (static_cast<int>(prep->segments.size()) < MinRotations(options.parameterization)) {
    std::ostringstream s;
    s << name << ": found " << prep->segments.size() << " rotations between static poses; the '"
      << ToString(options.parameterization) << "' gyroscope model needs at least "
      << MinRotations(options.parameterization);
    *error = s.str();
    return false;
  }

  // Gyroscope noise: pooled per-sample covariance of the static poses.
  Eigen::Matrix3d pooled = Eigen::Matrix3d::Zero();
  double weight = 0.0, count = 0.0;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  for (const StaticInterval& s : poses) {
    const double n = static_cast<double>(s.count());
    pooled += (n - 1.0) * s.gyro_cov;
    weight += n - 1.0;
    center += n * s.gyro_mean;
    count += n;
  }
  pooled /= weight;
  center /= count;
  Eigen::Matrix3d unused;
  if (!SqrtInformation<3>(pooled, &unused)) {
    // Quantised output that never changes while still: the mean is known to
    // the uniform quantisation error, step^2 / 12.
    const double step = GyroStep(log, poses);
    pooled.diagonal().array() += step > 0.0 ? step * step / 12.0 : 0.0;
    if (!SqrtInformation<3>(pooled, &unused)) {
      *error = name +
               ": the gyroscope shows no noise at all in the static poses; its noise "
               "cannot be estimated";
      return false;
    }
  }
  prep->gyro_cov = pooled;
  prep->center = center;

  // Calibrated specific force along every rotation.
  std::vector<std::vector<Eigen::Vector3d>> forces;
  for (const Segment& seg : prep->segments) {
    std::vector<Eigen::Vector3d> f;
    for (size_t i = seg.first; i <= seg.last; ++i) f.push_back(accel.Apply(log.accel[i]));
    forces.push_back(f);
  }
  Eigen::Matrix3d initial = Eigen::Matrix3d::Identity();
  if (!InitialMatrix(log, prep->segments, forces, center, options.parameterization, &initial,
                     error)) {
    *error = name + ": " + *error;
    return false;
  }
  *m0 = initial;
  prep->scale = std::cbrt(std::fabs(initial.determinant()));

  // Normalised data.
  const double k = prep->scale;
  for (size_t j = 0; j < prep->segments.size(); ++j) {
    const Segment& seg = prep->segments[j];
    GyroRotationData d;
    for (size_t i = seg.first; i <= seg.last; ++i) {
      d.t.push_back(log.t[i]);
      d.gyro.push_back((log.gyro[i] - center) * k);
    }
    d.force = forces[j];
    d.accel_rotation = accel.rotation;
    prep->rotations.push_back(d);
  }
  for (size_t k2 = 0; k2 < poses.size(); ++k2) {
    const StaticInterval& s = poses[k2];
    const double n = static_cast<double>(s.count());
    prep->static_gyro.push_back((s.gyro_mean - center) * k);
    Eigen::Matrix3d cov = s.gyro_cov / n;
    if (!SqrtInformation<3>(cov, &unused)) cov = pooled / n;
    prep->static_gyro_cov.push_back(cov * k * k);
    prep->static_force.push_back(accel.Apply(s.accel_mean));
  }
  return true;
}

// Free directions of the ambient vector: column j of `basis` holds the
// ambient entries free column j moves (the tangent space Ceres sees, in the
// same order: blocks in layout order, entries ascending).
struct FreeColumns {
  std::vector<std::string> names;
  Eigen::MatrixXd basis;
};

FreeColumns MakeFreeColumns(const Layout& layout, GyroParameterization gp, AccelParameterization ap,
                            const std::vector<bool>& held) {
  std::vector<std::pair<std::string, std::vector<int>>> columns;
  for (int i = 0; i < 3; ++i) columns.push_back({layout.names[i], {i}});
  if (gp == GyroParameterization::kBias) {
    columns.push_back({"scale", {layout.matrix, layout.matrix + 4, layout.matrix + 8}});
  } else {
    for (int i = 0; i < 9; ++i) {
      const int a = layout.matrix + i;
      if ((gp == GyroParameterization::kFull || i % 4 == 0) && !held[a]) {
        columns.push_back({layout.names[a], {a}});
      }
    }
  }
  if (layout.g >= 0) {
    for (int i = 0; i < 9; ++i) {
      if (!held[layout.g + i]) columns.push_back({layout.names[layout.g + i], {layout.g + i}});
    }
  }
  if (layout.accel_bias >= 0) {
    for (int i = 0; i < 3; ++i) {
      columns.push_back({layout.names[layout.accel_bias + i], {layout.accel_bias + i}});
    }
    for (int i : FreeUpperIndices(ap)) {
      columns.push_back({layout.names[layout.accel_upper + i], {layout.accel_upper + i}});
    }
  }
  FreeColumns out;
  out.basis = Eigen::MatrixXd::Zero(layout.size, columns.size());
  for (size_t j = 0; j < columns.size(); ++j) {
    out.names.push_back(columns[j].first);
    for (int a : columns[j].second) out.basis(a, j) = 1.0;
  }
  return out;
}

// The accelerometer at x (joint) or the fixed one.
AccelModel AccelAt(const std::vector<double>& x, const Layout& layout, const AccelModel& accel,
                   const Normalization& norm) {
  if (layout.accel_bias < 0) return accel;
  AccelModel n = norm.Apply(accel);
  n.bias =
      Eigen::Vector3d(x[layout.accel_bias], x[layout.accel_bias + 1], x[layout.accel_bias + 2]);
  n.SetUpper(&x[layout.accel_upper]);
  return norm.Undo(n);
}

// Weights of every residual at x: fills directions, tangent bases and
// square-root information of the rotations (and their sigma in degrees, and
// the integrated attitude change R(dq) of each) and the static poses'
// square-root information.
bool Weigh(const Prepared& prep, const Layout& layout, const std::vector<double>& x,
           const AccelModel& accel_now, const Normalization& norm,
           std::vector<GyroRotationData>* rotations, std::vector<double>* sigma_deg,
           std::vector<Eigen::Matrix3d>* turns, std::vector<Eigen::Matrix3d>* static_information,
           std::string* error) {
  const Eigen::Matrix3d m =
      Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(&x[layout.matrix]);
  const double* g = layout.g >= 0 ? &x[layout.g] : nullptr;
  // Covariance of the normalised calibrated rate per sample.
  const Eigen::Matrix3d rate_cov = m * (prep.gyro_cov * prep.scale * prep.scale) * m.transpose();
  const Eigen::Matrix3d am = accel_now.matrix();
  rotations->clear();
  sigma_deg->clear();
  turns->clear();
  for (size_t j = 0; j < prep.segments.size(); ++j) {
    const Segment& seg = prep.segments[j];
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
    sigma_deg->push_back(std::sqrt(cov2.trace()) * kRadToDeg);
    turns->push_back(rn);
    rotations->push_back(d);
  }
  static_information->clear();
  for (const Eigen::Matrix3d& c : prep.static_gyro_cov) {
    Eigen::Matrix3d w;
    if (!SqrtInformation<3>(Eigen::Matrix3d(m * c * m.transpose()), &w)) {
      *error = "a static pose has no usable gyroscope noise estimate";
      return false;
    }
    static_information->push_back(w);
  }
  return true;
}

// One Ceres problem at one set of weights.
struct Built {
  std::unique_ptr<ceres::Problem> problem;
  struct Block {
    const ceres::CostFunction* cost = nullptr;
    std::vector<int> offsets;
  };
  std::vector<Block> blocks;
  int rows = 0;
  // The non-constant parameter blocks, in layout order.
  std::vector<const double*> free_blocks;
};

void Build(const Prepared& prep, const Layout& layout, const GyroCalibrationOptions& options,
           AccelParameterization ap, const std::vector<bool>& held,
           const std::vector<GyroRotationData>& rotations,
           const std::vector<Eigen::Matrix3d>& static_information,
           const std::vector<double>& magnitude_sigmas, double gravity, std::vector<double>* x,
           Built* built) {
  built->problem = std::make_unique<ceres::Problem>();
  built->blocks.clear();
  built->rows = 0;
  ceres::Problem& problem = *built->problem;
  double* base = x->data();
  const bool with_g = layout.g >= 0;
  const bool joint = layout.accel_bias >= 0;
  std::vector<int> gyro_offsets = {layout.bias, layout.matrix};
  if (with_g) gyro_offsets.push_back(layout.g);
  auto add = [&](ceres::CostFunction* cost, const std::vector<int>& offsets, bool robust) {
    std::vector<double*> blocks;
    for (int o : offsets) blocks.push_back(base + o);
    problem.AddResidualBlock(cost, robust ? MakeLoss(options.loss, options.loss_scale) : nullptr,
                             blocks);
    built->blocks.push_back({cost, offsets});
    built->rows += cost->num_residuals();
  };
  for (size_t k = 0; k < prep.static_gyro.size(); ++k) {
    add(GyroStaticResidual::Create(prep.static_gyro[k], prep.static_force[k], static_information[k],
                                   with_g),
        gyro_offsets, true);
  }
  std::vector<int> rotation_offsets = gyro_offsets;
  if (joint) {
    rotation_offsets.push_back(layout.accel_bias);
    rotation_offsets.push_back(layout.accel_upper);
  }
  for (const GyroRotationData& d : rotations) {
    add(GyroRotationResidual::Create(d, with_g, joint), rotation_offsets, true);
  }
  if (joint) {
    for (size_t k = 0; k < prep.normalized_positions.size(); ++k) {
      add(GravityMagnitudeResidual::Create(prep.normalized_positions[k].raw_mean, gravity,
                                           magnitude_sigmas[k]),
          {layout.accel_bias, layout.accel_upper}, false);
    }
  }

  // Held entries: fixed by the parameterization, or not determined.
  auto hold = [&](int offset, int size, std::vector<int> fixed, ceres::Manifold* manifold) {
    double* block = base + offset;
    for (int i = 0; i < size; ++i) {
      if (held[offset + i] && std::find(fixed.begin(), fixed.end(), i) == fixed.end()) {
        fixed.push_back(i);
      }
    }
    if (static_cast<int>(fixed.size()) == size) {
      problem.SetParameterBlockConstant(block);
      delete manifold;
      return;
    }
    built->free_blocks.push_back(block);
    if (manifold != nullptr) {
      problem.SetManifold(block, manifold);
    } else if (!fixed.empty()) {
      problem.SetManifold(block, new ceres::SubsetManifold(size, fixed));
    }
  };
  built->free_blocks.clear();
  hold(layout.bias, 3, {}, nullptr);
  const GyroParameterization gp = options.parameterization;
  if (gp == GyroParameterization::kBias) {
    hold(layout.matrix, 9, {}, new IsotropicScaleManifold);
  } else if (gp == GyroParameterization::kScale) {
    hold(layout.matrix, 9, {1, 2, 3, 5, 6, 7}, nullptr);
  } else {
    hold(layout.matrix, 9, {}, nullptr);
  }
  if (with_g) hold(layout.g, 9, {}, nullptr);
  if (joint) {
    hold(layout.accel_bias, 3, {}, nullptr);
    if (ap == AccelParameterization::kScale) {
      hold(layout.accel_upper, kUpperSize, {1, 2, 4}, nullptr);
    } else {
      hold(layout.accel_upper, kUpperSize, {}, nullptr);
    }
  }
}

// The whitened Jacobian of all residuals (no loss) with respect to the
// ambient parameters at x.
Eigen::MatrixXd AmbientJacobian(const Built& built, const Layout& layout, std::vector<double>* x) {
  Eigen::MatrixXd j = Eigen::MatrixXd::Zero(built.rows, layout.size);
  int row = 0;
  for (const Built::Block& b : built.blocks) {
    const int rows = b.cost->num_residuals();
    const std::vector<int32_t>& sizes = b.cost->parameter_block_sizes();
    std::vector<const double*> parameters;
    std::vector<std::vector<double>> storage(sizes.size());
    std::vector<double*> jacobians;
    for (size_t i = 0; i < sizes.size(); ++i) {
      parameters.push_back(x->data() + b.offsets[i]);
      storage[i].resize(rows * sizes[i]);
      jacobians.push_back(storage[i].data());
    }
    std::vector<double> residuals(rows);
    b.cost->Evaluate(parameters.data(), residuals.data(), jacobians.data());
    for (size_t i = 0; i < sizes.size(); ++i) {
      for (int r = 0; r < rows; ++r) {
        for (int c = 0; c < sizes[i]; ++c) {
          j(row + r, b.offsets[i] + c) = storage[i][r * sizes[i] + c];
        }
      }
    }
    row += rows;
  }
  return j;
}

// Free parameters the data does not determine: in a null direction of the
// whitened Jacobian, or with a standard deviation beyond the options' limits
// (normalised units: M' near the identity, G in rad/s per m/s^2).
std::vector<std::string> Undetermined(const Eigen::MatrixXd& jacobian, const FreeColumns& free,
                                      const GyroCalibrationOptions& options) {
  const ObservabilityReport report = AnalyzeObservability(jacobian, free.names);
  std::vector<std::string> out = report.undetermined;
  if (report.full_rank()) {
    const Eigen::VectorXd norms = jacobian.colwise().norm();
    const Eigen::VectorXd inv = norms.cwiseInverse();
    const Eigen::MatrixXd scaled = jacobian * inv.asDiagonal();
    const Eigen::MatrixXd information = scaled.transpose() * scaled;
    const Eigen::MatrixXd cov = inv.asDiagonal() *
                                information.ldlt().solve(Eigen::MatrixXd::Identity(
                                    information.rows(), information.cols())) *
                                inv.asDiagonal();
    for (size_t j = 0; j < free.names.size(); ++j) {
      const std::string& name = free.names[j];
      const double std = std::sqrt(std::max(cov(j, j), 0.0));
      const bool matrix = name == "scale" || name.rfind("m_", 0) == 0;
      const bool g = name.rfind("g_", 0) == 0;
      if ((matrix && !(std <= options.max_matrix_std)) ||
          (g && !(std <= options.max_g_sensitivity_std))) {
        if (std::find(out.begin(), out.end(), name) == out.end()) out.push_back(name);
      }
    }
  }
  return out;
}

// Warnings for undetermined gyroscope parameters, grouped by what is missing.
void WarnUndetermined(const std::vector<std::string>& names, std::vector<std::string>* warnings) {
  for (int c = 0; c < 3; ++c) {
    std::vector<std::string> column;
    for (const std::string& n : names) {
      if (n.size() == 4 && n.rfind("m_", 0) == 0 && n[3] == kAxisNames[c]) column.push_back(n);
    }
    if (column.empty()) continue;
    const std::string axis(1, kAxisNames[c]);
    std::string listed;
    for (const std::string& n : column) listed += (listed.empty() ? "" : ", ") + n;
    const bool scale = std::find(column.begin(), column.end(), "m_" + axis + axis) != column.end();
    warnings->push_back("no rotation about the body " + axis +
                        " axis (away from the vertical) between the static poses: gyro " +
                        (scale ? "scale " + axis + " and " : std::string()) + "matrix entries " +
                        listed +
                        " not determined; they are held at the initial estimate and reported "
                        "without a standard deviation: turn the unit about its " +
                        axis + " axis while that axis is horizontal");
  }
  std::string g;
  for (const std::string& n : names) {
    if (n.rfind("g_", 0) == 0) g += (g.empty() ? "" : ", ") + n;
  }
  if (!g.empty()) {
    warnings->push_back(
        "the gravity directions of the static poses do not span three dimensions: gyro "
        "g-sensitivity " +
        g +
        " not determined (held at 0, reported without a standard deviation): add poses with "
        "other axes up");
  }
}

// The covariance the accelerometer's own uncertainty adds to the free
// parameters when the accelerometer is held (not joint): S C_a S^T, with
// S = -(J_x^T J_x)^-1 J_x^T J_a the first-order change of the estimate
// with the accelerometer's (b_a', free U') (normalised units), J_a from the
// joint form of the rotation residuals; jx is the whitened Jacobian of all
// residuals in the free columns.
Eigen::MatrixXd AccelContribution(const Eigen::MatrixXd& jx, const Layout& layout,
                                  const Prepared& prep,
                                  const std::vector<GyroRotationData>& rotations,
                                  std::vector<double>* x, const AccelModel& accel,
                                  const Normalization& norm,
                                  const Eigen::MatrixXd& accel_covariance) {
  const std::vector<int> free_upper = FreeUpperIndices(accel.parameterization);
  const int na = 3 + static_cast<int>(free_upper.size());
  Eigen::MatrixXd ja = Eigen::MatrixXd::Zero(jx.rows(), na);
  const AccelModel an = norm.Apply(accel);
  double accel_bias[3] = {an.bias(0), an.bias(1), an.bias(2)};
  double accel_upper[kUpperSize];
  an.GetUpper(accel_upper);
  const bool with_g = layout.g >= 0;
  int row = 3 * static_cast<int>(prep.static_gyro.size());
  for (const GyroRotationData& d : rotations) {
    std::unique_ptr<ceres::CostFunction> cost(GyroRotationResidual::Create(d, with_g, true));
    std::vector<const double*> parameters = {x->data() + layout.bias, x->data() + layout.matrix};
    if (with_g) parameters.push_back(x->data() + layout.g);
    parameters.push_back(accel_bias);
    parameters.push_back(accel_upper);
    double residual[2], jb[2 * 3], ju[2 * kUpperSize];
    std::vector<double*> jacobians(parameters.size(), nullptr);
    jacobians[parameters.size() - 2] = jb;
    jacobians[parameters.size() - 1] = ju;
    cost->Evaluate(parameters.data(), residual, jacobians.data());
    for (int r = 0; r < 2; ++r) {
      for (int c = 0; c < 3; ++c) ja(row + r, c) = jb[3 * r + c];
      for (size_t c = 0; c < free_upper.size(); ++c) {
        ja(row + r, 3 + c) = ju[kUpperSize * r + free_upper[c]];
      }
    }
    row += 2;
  }
  // C_a in normalised units: b' = (b - c) / s, U' = s U.
  Eigen::VectorXd to_normalized = Eigen::VectorXd::Constant(na, norm.scale);
  to_normalized.head<3>().setConstant(1.0 / norm.scale);
  const Eigen::MatrixXd ca =
      to_normalized.asDiagonal() * accel_covariance * to_normalized.asDiagonal();
  const Eigen::MatrixXd information = jx.transpose() * jx;
  const Eigen::MatrixXd sensitivity = -information.ldlt().solve(jx.transpose() * ja);
  return sensitivity * ca * sensitivity.transpose();
}

// Consecutive rotations k (pose s -> e) and k + 1 (pose e -> f) share the
// measured direction d_e: r_k = W_k E_k (R_k^T d_s - d_e) and r_{k+1} =
// W_{k+1} E_{k+1} (R_{k+1}^T d_e - d_f), so their whitened residuals are
// correlated, Cov(r_k, r_{k+1}) = -W_k E_k C_e R_{k+1} E_{k+1}^T W_{k+1}^T
// (C_e the covariance of d_e), while the fit weighs them as independent.
// The estimate's covariance is then the sandwich A J^T (I + D) J A, with
// A = (J^T J)^-1 what the fit reports and D these off-diagonal blocks; this
// returns the correction A J^T D J A (free columns, normalised units).
// Generalised least squares with the full covariance would change the
// estimate by far less than its sigma (the shared direction noise is a few
// per cent of the integrated gyroscope noise), so only the reported
// uncertainty is corrected. j is the whitened Jacobian of all residuals in
// the free columns (rows: static poses, then rotations, in Build's order).
Eigen::MatrixXd SharedPoseCorrection(const Eigen::MatrixXd& j, const Prepared& prep,
                                     const std::vector<GyroRotationData>& rotations,
                                     const std::vector<Eigen::Matrix3d>& turns,
                                     const AccelModel& accel, const Eigen::MatrixXd& covariance) {
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(j.rows(), j.rows());
  const int first_row = 3 * static_cast<int>(prep.static_gyro.size());
  const Eigen::Matrix3d am = accel.matrix();
  for (size_t k = 0; k + 1 < prep.segments.size(); ++k) {
    if (prep.segments[k].to != prep.segments[k + 1].from) continue;
    const Position& shared = prep.positions[prep.segments[k].to];
    const Eigen::Matrix3d ce =
        DirectionCovariance(am, accel.Apply(shared.raw_mean), shared.raw_mean_cov);
    const Eigen::Matrix2d block = -rotations[k].sqrt_information * rotations[k].tangent * ce *
                                  turns[k + 1] * rotations[k + 1].tangent.transpose() *
                                  rotations[k + 1].sqrt_information.transpose();
    const int row = first_row + 2 * static_cast<int>(k);
    d.block<2, 2>(row, row + 2) = block;
    d.block<2, 2>(row + 2, row) = block.transpose();
  }
  const Eigen::MatrixXd ja = j * covariance;
  return ja.transpose() * d * ja;
}

}  // namespace

bool CalibrateGyroscope(const ImuLog& log, const std::vector<StaticInterval>& intervals,
                        const AccelModel& accel, const Eigen::MatrixXd& accel_covariance,
                        double gravity, const GyroCalibrationOptions& options,
                        GyroCalibrationResult* result) {
  CHECK(result != nullptr);
  *result = GyroCalibrationResult();
  GyroCalibrationResult& r = *result;
  std::string error;
  if (!options.IsValid(&error)) {
    r.message = error;
    return false;
  }
  if (options.parameterization == GyroParameterization::kNone) {
    r.message = "gyro_model is 'none': there is nothing to calibrate";
    return false;
  }
  const int accel_parameters =
      3 + static_cast<int>(FreeUpperIndices(accel.parameterization).size());
  if (accel_covariance.size() > 0 &&
      (accel_covariance.rows() != accel_parameters || accel_covariance.cols() != accel_parameters ||
       !accel_covariance.allFinite())) {
    r.message = "the accelerometer covariance must be finite and " +
                std::to_string(accel_parameters) + " x " + std::to_string(accel_parameters) +
                " (bias and free entries of U)";
    return false;
  }
  if (options.joint && !(gravity > 0.0 && std::isfinite(gravity))) {
    r.message = "the joint accelerometer and gyroscope fit needs a positive gravity";
    return false;
  }
  Prepared prep;
  Eigen::Matrix3d m0;
  if (!Prepare(log, intervals, accel, options, &prep, &m0, &r.warnings, &error)) {
    r.message = error;
    return false;
  }
  r.initial_matrix = m0;
  r.gyro_noise = prep.gyro_cov.diagonal().cwiseSqrt();

  const Layout layout(options.g_sensitivity, options.joint);
  const AccelParameterization ap = accel.parameterization;
  const Normalization norm = Normalization::For(accel);
  prep.normalized_positions = norm.Apply(prep.positions);
  // Initial values in normalised units: M' = M / k, b' = 0, G = 0.
  std::vector<double> x0(layout.size, 0.0);
  for (int i = 0; i < 9; ++i) x0[layout.matrix + i] = m0(i / 3, i % 3) / prep.scale;
  std::vector<double> magnitude_sigmas;
  if (options.joint) {
    const AccelModel n = norm.Apply(accel);
    for (int i = 0; i < 3; ++i) x0[layout.accel_bias + i] = n.bias(i);
    n.GetUpper(&x0[layout.accel_upper]);
    if (ap == AccelParameterization::kScale) {
      x0[layout.accel_upper + 1] = x0[layout.accel_upper + 2] = x0[layout.accel_upper + 4] = 0.0;
    }
    magnitude_sigmas = MagnitudeSigmas(prep.positions, accel);
    for (double sigma : magnitude_sigmas) {
      if (!(sigma > 0.0) || !std::isfinite(sigma)) {
        r.message = "a static pose has no usable accelerometer noise estimate for the joint fit";
        return false;
      }
    }
  }

  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.function_tolerance = options.function_tolerance;
  solver_options.gradient_tolerance = options.gradient_tolerance;
  solver_options.parameter_tolerance = options.parameter_tolerance;
  solver_options.logging_type = ceres::SILENT;
  solver_options.minimizer_progress_to_stdout = false;
  solver_options.num_threads = 1;

  // Solve; then hold what the data does not determine and solve again, and
  // re-weigh at the estimate while it still moves the weights (the noise of
  // the integrated rate scales with M_g).
  std::vector<double> x = x0;
  std::vector<bool> held(layout.size, false);
  std::vector<GyroRotationData> rotations;
  std::vector<double> sigma_deg;
  std::vector<Eigen::Matrix3d> turns, static_information;
  Built built;
  FreeColumns free;
  ceres::Solver::Summary summary;
  const auto start = std::chrono::steady_clock::now();
  constexpr int kMaxPasses = 4;
  bool pending = false;
  for (int pass = 0; pass < kMaxPasses; ++pass) {
    pending = false;
    const AccelModel accel_now = AccelAt(x, layout, accel, norm);
    if (!Weigh(prep, layout, x, accel_now, norm, &rotations, &sigma_deg, &turns,
               &static_information, &error)) {
      r.message = error;
      return false;
    }
    const std::vector<double> weighed_at = x;
    Build(prep, layout, options, ap, held, rotations, static_information, magnitude_sigmas, gravity,
          &x, &built);
    ceres::Solve(solver_options, built.problem.get(), &summary);
    r.iterations += static_cast<int>(summary.iterations.size()) - 1;
    if (!summary.IsSolutionUsable()) break;

    free = MakeFreeColumns(layout, options.parameterization, ap, held);
    const Eigen::MatrixXd jacobian = AmbientJacobian(built, layout, &x) * free.basis;
    const std::vector<std::string> weak = Undetermined(jacobian, free, options);
    bool changed = false;
    for (const std::string& name : weak) {
      const auto it = std::find(layout.names.begin(), layout.names.end(), name);
      const int a = it == layout.names.end() ? -1 : static_cast<int>(it - layout.names.begin());
      if (name == "scale") {
        r.message =
            "the rotations do not determine the gyroscope scale: the unit never turns "
            "about a horizontal axis between the static poses";
        return false;
      }
      if (a >= layout.matrix && (layout.accel_bias < 0 || a < layout.accel_bias)) {
        held[a] = true;
        x[a] = x0[a];
        changed = true;
        r.undetermined.push_back(name);
      } else if (std::find(r.undetermined.begin(), r.undetermined.end(), name) ==
                 r.undetermined.end()) {
        r.undetermined.push_back(name);
      }
    }
    if (changed) {
      pending = true;
      continue;
    }
    double moved = 0.0;
    for (int i = 0; i < 9; ++i) {
      moved = std::max(moved, std::fabs(x[layout.matrix + i] - weighed_at[layout.matrix + i]));
    }
    if (moved < 1e-3) break;
  }
  r.solve_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.termination = ceres::TerminationTypeToString(summary.termination_type);
  r.converged =
      summary.IsSolutionUsable() && summary.termination_type == ceres::CONVERGENCE && !pending;

  // The estimate in SI / raw units.
  const double k = prep.scale;
  const Eigen::Matrix3d mn =
      Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(&x[layout.matrix]);
  r.model.matrix = k * mn;
  r.model.bias = prep.center + Eigen::Vector3d(x[0], x[1], x[2]) / k;
  if (layout.g >= 0) {
    r.g_sensitivity = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(&x[layout.g]);
  }
  if (!r.model.matrix.allFinite() || !r.model.bias.allFinite() || !r.g_sensitivity.allFinite()) {
    r.converged = false;
  }
  const AccelModel accel_final = AccelAt(x, layout, accel, norm);

  // Residuals and chi-square at the estimate.
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.apply_loss_function = false;
  double cost = 0.0;
  built.problem->Evaluate(evaluate, &cost, nullptr, nullptr, nullptr);
  r.chi2 = 2.0 * cost;
  r.num_residuals = built.rows;
  r.num_parameters = static_cast<int>(free.names.size());
  r.dof = r.num_residuals - r.num_parameters;
  const size_t first_rotation_block = prep.static_gyro.size();
  for (size_t j = 0; j < prep.segments.size(); ++j) {
    const Segment& seg = prep.segments[j];
    const GyroRotationData& d = rotations[j];
    GyroRotationReport report;
    report.from_pose = seg.from;
    report.to_pose = seg.to;
    report.first_sample = seg.first;
    report.last_sample = seg.last;
    report.t_begin = log.t[seg.first];
    report.t_end = log.t[seg.last];
    const Eigen::Vector3d ds = accel_final.Apply(prep.positions[seg.from].raw_mean).normalized();
    const Eigen::Vector3d de = accel_final.Apply(prep.positions[seg.to].raw_mean).normalized();
    report.gravity_angle_deg = std::atan2(ds.cross(de).norm(), ds.dot(de)) * kRadToDeg;
    double dq[4];
    IntegrateGyroRotation<double>(d, &x[layout.bias], &x[layout.matrix],
                                  layout.g >= 0 ? &x[layout.g] : nullptr, dq);
    const Eigen::Vector3d predicted = RotationOf(dq).transpose() * ds;
    report.residual_deg = std::atan2(predicted.cross(de).norm(), predicted.dot(de)) * kRadToDeg;
    report.sigma_deg = sigma_deg[j];
    const Built::Block& block = built.blocks[first_rotation_block + j];
    std::vector<const double*> parameters;
    for (int o : block.offsets) parameters.push_back(x.data() + o);
    double residual[2];
    block.cost->Evaluate(parameters.data(), residual, nullptr);
    report.chi2 = residual[0] * residual[0] + residual[1] * residual[1];
    r.rotations.push_back(report);
  }

  // Covariance of the free parameters (tangent space, normalised), then
  // mapped to SI: b = c + b' / k, M = k M', G = G, accelerometer as in
  // normalization.h.
  Eigen::VectorXd to_si = Eigen::VectorXd::Ones(layout.size);
  to_si.head<3>().setConstant(1.0 / k);
  to_si.segment<9>(layout.matrix).setConstant(k);
  if (layout.accel_bias >= 0) {
    to_si.segment<3>(layout.accel_bias).setConstant(norm.scale);
    to_si.segment<kUpperSize>(layout.accel_upper).setConstant(1.0 / norm.scale);
  }
  if (options.compute_covariance && r.converged) {
    ceres::Covariance::Options covariance_options;
    covariance_options.algorithm_type = ceres::DENSE_SVD;
    covariance_options.num_threads = 1;
    ceres::Covariance covariance(covariance_options);
    const int nf = static_cast<int>(free.names.size());
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> tangent(nf, nf);
    if (covariance.Compute(built.free_blocks, built.problem.get()) &&
        covariance.GetCovarianceMatrixInTangentSpace(built.free_blocks, tangent.data())) {
      const Eigen::MatrixXd jacobian = AmbientJacobian(built, layout, &x) * free.basis;
      tangent += SharedPoseCorrection(jacobian, prep, rotations, turns, accel_final, tangent);
      if (layout.accel_bias < 0 && accel_covariance.size() > 0) {
        tangent +=
            AccelContribution(jacobian, layout, prep, rotations, &x, accel, norm, accel_covariance);
      }
      const Eigen::MatrixXd ambient =
          to_si.asDiagonal() * free.basis * tangent * free.basis.transpose() * to_si.asDiagonal();
      // Free gyroscope columns: all but the accelerometer's.
      std::vector<int> gyro_columns, accel_columns;
      for (int j = 0; j < nf; ++j) {
        (free.names[j].rfind("accel_", 0) == 0 ? accel_columns : gyro_columns).push_back(j);
      }
      Eigen::VectorXd column_si(nf);
      for (int j = 0; j < nf; ++j) {
        int a = 0;
        free.basis.col(j).maxCoeff(&a);
        column_si(j) = to_si(a);
      }
      const Eigen::MatrixXd free_si = column_si.asDiagonal() * tangent * column_si.asDiagonal();
      r.covariance.resize(gyro_columns.size(), gyro_columns.size());
      for (size_t i = 0; i < gyro_columns.size(); ++i) {
        r.parameter_names.push_back(free.names[gyro_columns[i]]);
        for (size_t j = 0; j < gyro_columns.size(); ++j) {
          r.covariance(i, j) = free_si(gyro_columns[i], gyro_columns[j]);
        }
      }
      r.covariance_available = true;
      // An entry has a standard deviation when some free column moves it.
      const Eigen::VectorXd moved = free.basis.rowwise().norm();
      auto std_of = [&](int a) { return moved(a) > 0.0 ? std::sqrt(ambient(a, a)) : NAN; };
      for (int i = 0; i < 3; ++i) r.bias_std(i) = std_of(layout.bias + i);
      for (int i = 0; i < 9; ++i) {
        r.matrix_std(i / 3, i % 3) = std_of(layout.matrix + i);
        if (layout.g >= 0) r.g_sensitivity_std(i / 3, i % 3) = std_of(layout.g + i);
      }
      if (layout.accel_bias >= 0) {
        // (b_a, free U) in the refinement's order, normalised, then mapped back.
        Eigen::MatrixXd accel_cov(accel_columns.size(), accel_columns.size());
        for (size_t i = 0; i < accel_columns.size(); ++i) {
          for (size_t j = 0; j < accel_columns.size(); ++j) {
            accel_cov(i, j) = tangent(accel_columns[i], accel_columns[j]);
          }
        }
        r.accel.covariance = norm.Undo(accel_cov);
        r.accel.covariance_available = true;
      }
    } else {
      r.warnings.push_back(
          "the gyroscope covariance could not be computed (the problem is rank deficient); no "
          "standard deviations are reported");
    }
  }

  if (layout.accel_bias >= 0) {
    r.accel_refined = true;
    RefinementResult& a = r.accel;
    a.model = accel_final;
    a.converged = r.converged;
    a.parameter_names = MagnitudeParameterNames(ap);
    a.num_parameters = static_cast<int>(a.parameter_names.size());
    a.num_residuals = static_cast<int>(prep.positions.size());
    a.sigmas = magnitude_sigmas;
    a.residuals_before = MagnitudeResiduals(prep.positions, accel, gravity);
    a.residuals_after = MagnitudeResiduals(prep.positions, accel_final, gravity);
    a.iterations = r.iterations;
    a.termination = r.termination;
    a.solve_seconds = r.solve_seconds;
    a.message = "refined jointly with the gyroscope";
  }

  WarnUndetermined(r.undetermined, &r.warnings);
  if (r.dof > 0) {
    const double p_value = ChiSquareUpperTail(r.chi2, r.dof);
    if (p_value < 1e-3) {
      std::ostringstream s;
      s.precision(3);
      s << "gyroscope residuals are " << std::sqrt(r.chi2 / r.dof)
        << " times the noise level (chi2 = " << r.chi2 << " on " << r.dof << " dof, p = " << p_value
        << "): the unit moved during a pose, the gyroscope has an effect the model lacks "
           "(g-sensitivity: set gyro_g_sensitivity), or its noise is not white; the standard "
           "deviations are too small by about that factor";
      r.warnings.push_back(s.str());
    }
  }
  if (!r.converged) {
    r.message = "the gyroscope calibration did not converge (" + r.termination + ": " +
                summary.message + ")";
    return false;
  }
  double rms = 0.0;
  for (const GyroRotationReport& rot : r.rotations) rms += rot.residual_deg * rot.residual_deg;
  rms = std::sqrt(rms / static_cast<double>(r.rotations.size()));
  std::ostringstream s;
  s.precision(3);
  s << "calibrated the '" << ToString(options.parameterization) << "' gyroscope model"
    << (options.g_sensitivity ? " with g-sensitivity" : "")
    << (options.joint ? " jointly with the accelerometer" : "") << " from " << r.rotations.size()
    << " rotations between " << prep.positions.size() << " static poses (residual rms " << rms
    << " deg, " << r.iterations << " iterations)";
  r.message = s.str();
  return true;
}

bool AddGyroscopeCalibration(const ImuLog& log, const std::vector<StaticInterval>& intervals,
                             const GyroCalibrationOptions& options, Calibration* calibration) {
  CHECK(calibration != nullptr);
  Calibration& c = *calibration;
  auto fail = [&](const std::string& message) {
    c.success = false;
    c.message = message;
    return false;
  };
  if (!c.success) return fail("the gyroscope needs a calibrated accelerometer first");
  GyroCalibrationResult g;
  const Eigen::MatrixXd accel_covariance =
      c.refinement.covariance_available ? c.refinement.covariance : Eigen::MatrixXd();
  if (!CalibrateGyroscope(log, intervals, c.accel.model, accel_covariance, c.gravity, options,
                          &g)) {
    for (const std::string& w : g.warnings) c.warnings.push_back(w);
    return fail(g.message);
  }
  GyroCalibration& out = c.gyro;
  out = GyroCalibration();
  out.estimated = true;
  out.model = g.model;
  out.bias_std = g.bias_std;
  out.matrix_std = g.matrix_std;
  out.covariance = g.covariance;
  out.covariance_names = g.parameter_names;
  if (options.g_sensitivity) {
    for (int i = 0; i < 9; ++i) {
      out.extra_names.push_back(std::string("g_sensitivity_") + kAxisNames[i / 3] +
                                kAxisNames[i % 3]);
      out.extra_values.push_back(g.g_sensitivity(i / 3, i % 3));
      out.extra_std.push_back(g.g_sensitivity_std(i / 3, i % 3));
    }
  }
  for (const GyroRotationReport& r : g.rotations)
    out.rotation_residual_deg.push_back(r.residual_deg);
  if (g.accel_refined) {
    // The joint fit's accelerometer, with the housing rotation (affine) and
    // its uncertainty kept from the accelerometer step.
    HousingRotation housing;
    const bool affine = c.accel.model.parameterization == AccelParameterization::kAffine &&
                        c.accel.covariance.rows() >= 3 && !c.accel.covariance_names.empty() &&
                        c.accel.covariance_names.back() == "rot_z";
    if (affine) {
      housing.rotation = c.accel.model.rotation;
      housing.angle_covariance = c.accel.covariance.bottomRightCorner<3, 3>();
    }
    const AccelCalibration before = c.accel;
    c.accel.model = g.accel.model;
    if (g.accel.covariance_available) {
      PropagateUncertainty(g.accel, affine ? &housing : nullptr, &c.accel);
      if (c.accel.model.parameterization == AccelParameterization::kAffine && !affine) {
        c.accel.matrix_std.setConstant(NAN);
      }
    }
    c.accel.tilt_rms = before.tilt_rms;
    c.residual_refined = {Rms(g.accel.residuals_after), MaxAbs(g.accel.residuals_after)};
    for (size_t k = 0; k < c.positions.size() && k < g.accel.residuals_after.size(); ++k) {
      c.positions[k].residual_after = g.accel.residuals_after[k];
    }
    c.warnings.push_back(
        "gyro_joint: the accelerometer's bias and U come from the joint fit with the gyroscope "
        "rotations");
  }
  for (const std::string& w : g.warnings) c.warnings.push_back(w);
  c.message += "; " + g.message;
  return true;
}

}  // namespace gravcal
