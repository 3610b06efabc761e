// The multi-IMU calibration (methods/multi_imu.h): shared poses, the joint
// Ceres problem and its covariance, the separate fits, the single-pose case.
#include "gravcal/methods/multi_imu.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <ceres/sphere_manifold.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <exception>
#include <memory>
#include <set>
#include <sstream>

#include "gravcal/core/imu_model.h"
#include "methods/multi_imu_internal.h"

namespace gravcal {
namespace internal {
namespace {

// p = Exp(-delta) c0^T d: the plate direction d in the IMU's frame.
template <typename T>
void ToImuFrame(const Eigen::Matrix3d& c0, const T* delta, const T* d, T* p) {
  T y[3];
  for (int r = 0; r < 3; ++r) y[r] = c0(0, r) * d[0] + c0(1, r) * d[1] + c0(2, r) * d[2];
  const T minus[3] = {-delta[0], -delta[1], -delta[2]};
  ceres::AngleAxisRotatePoint(minus, y, p);
}

// Static pose k of IMU i:
//
//   r = (U (v - b) - g Exp(-delta) c0^T d_k) / sigma          3 values
//
// v the pose's mean raw accelerometer vector, sigma the standard deviation
// of its mean in m/s^2 (isotropic) times the group's variance factor.
// Blocks: b (3), U (6), delta (3), d_k (3, unit).
struct PlateAccelResidual {
  PlateAccelResidual(const Eigen::Vector3d& mean, double sigma, double gravity,
                     const Eigen::Matrix3d& c0)
      : mean_(mean), weight_(1.0 / sigma), gravity_(gravity), c0_(c0) {}

  template <typename T>
  bool operator()(const T* const bias, const T* const upper, const T* const delta,
                  const T* const direction, T* residual) const {
    AccelBlocks<T> blocks;
    blocks.bias = bias;
    blocks.upper = upper;
    T m[3], p[3];
    ImuModel<T>(blocks).SensorFrame(mean_, m);
    ToImuFrame(c0_, delta, direction, p);
    for (int j = 0; j < 3; ++j) residual[j] = (m[j] - gravity_ * p[j]) * weight_;
    return true;
  }

  const Eigen::Vector3d mean_;
  const double weight_;
  const double gravity_;
  const Eigen::Matrix3d c0_;
};

// Static pose k of IMU i, gyroscope: r = (u - b_g) / sigma (raw units; the
// Earth's rate is below the noise of these means and not modelled).
struct PlateGyroPoseResidual {
  PlateGyroPoseResidual(const Eigen::Vector3d& mean, double sigma)
      : mean_(mean), weight_(1.0 / sigma) {}
  template <typename T>
  bool operator()(const T* const gyro_bias, T* residual) const {
    for (int j = 0; j < 3; ++j) residual[j] = (T(mean_[j]) - gyro_bias[j]) * weight_;
    return true;
  }
  const Eigen::Vector3d mean_;
  const double weight_;
};

// Turn k -> k+1 of IMU i (gyro_rotation_residual.h):
//
//   p_s = Exp(-delta) c0^T d_k,  p_e = Exp(-delta) c0^T d_{k+1}
//   r   = W E (R(dq)^T p_s - p_e)                               2 values
//
// dq integrated from w = M_g (u - b_g); W = I / sigma, sigma^2 the white
// noise of the gyroscope integrated over the turn (rad^2 per axis) times
// the group's variance factor. Blocks: b_g (3), M_g (9), delta (3), d_k,
// d_{k+1}.
struct PlateTurnResidual {
  PlateTurnResidual(const GyroRotationData* turn, const Eigen::Matrix3d& c0, double factor)
      : turn_(turn), c0_(c0), weight_(1.0 / std::sqrt(factor)) {}
  template <typename T>
  bool operator()(const T* const gyro_bias, const T* const gyro_matrix, const T* const delta,
                  const T* const start, const T* const end, T* residual) const {
    T ps[3], pe[3], dq[4];
    ToImuFrame(c0_, delta, start, ps);
    ToImuFrame(c0_, delta, end, pe);
    IntegrateGyroTurn(*turn_, gyro_bias, gyro_matrix, static_cast<const T*>(nullptr), dq);
    WhitenedTurnError<T>(dq, ps, pe, turn_->tangent, turn_->sqrt_information, residual);
    residual[0] *= weight_;
    residual[1] *= weight_;
    return true;
  }
  const GyroRotationData* turn_;
  const Eigen::Matrix3d c0_;
  const double weight_;
};

Eigen::Matrix<double, 2, 3> TangentBasis(const Eigen::Vector3d& d) {
  const Eigen::Vector3d n = d.normalized();
  Eigen::Vector3d a = std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d e1 = (a - n * n.dot(a)).normalized();
  const Eigen::Vector3d e2 = n.cross(e1);
  Eigen::Matrix<double, 2, 3> e;
  e.row(0) = e1.transpose();
  e.row(1) = e2.transpose();
  return e;
}

// Variance factors of the three row groups.
struct GroupFactors {
  double accel = 1.0, gyro = 1.0, turn = 1.0;
};

// One solve: the IMUs `members` (indices into data/params), `held` the one
// whose rotation is held (C = c0), poses `dirs` (plate frame, unit).
struct FitOutput {
  bool ok = false;
  std::string message;
  // chi2 and rows per group (unit weights).
  double chi2[3] = {0, 0, 0};
  int rows[3] = {0, 0, 0};
  int parameters = 0;
  // Per member: covariance of [b U b_g M_g delta] (21 or 24; NaN rows and
  // columns where undetermined), and the rms of its pose rows (m/s^2) and
  // turn rows (deg).
  std::vector<Eigen::MatrixXd> covariance;
  std::vector<double> accel_rms, turn_rms_deg;
};

bool Fit(const std::vector<PlateImuData>& data, const std::vector<int>& members, int held,
         double gravity, const GroupFactors& factors, bool covariance, int max_iterations,
         std::vector<PlateImuParameters>* params, std::vector<Eigen::Vector3d>* dirs,
         FitOutput* out) {
  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  ceres::SphereManifold<3> sphere;
  const size_t pose_count = dirs->size();
  for (Eigen::Vector3d& d : *dirs) {
    d.normalize();
    problem.AddParameterBlock(d.data(), 3, &sphere);
  }
  std::vector<std::vector<ceres::ResidualBlockId>> ids(members.size());
  std::vector<std::vector<int>> groups(members.size());
  // The turn of each turn row (for its sigma).
  std::vector<std::vector<const GyroRotationData*>> row_turns(members.size());
  for (size_t m = 0; m < members.size(); ++m) {
    const int i = members[m];
    const PlateImuData& imu = data[i];
    PlateImuParameters& p = (*params)[i];
    problem.AddParameterBlock(p.bias, 3);
    problem.AddParameterBlock(p.upper, 6);
    problem.AddParameterBlock(p.delta, 3);
    if (i == held) problem.SetParameterBlockConstant(p.delta);
    if (p.split >= 0) problem.AddParameterBlock(p.delta_after, 3);
    for (size_t k = 0; k < pose_count; ++k) {
      const PlatePoseData& pose = imu.poses[k];
      const bool after = p.split >= 0 && static_cast<int>(k) >= p.split;
      const double sigma = pose.accel_sigma * std::sqrt(factors.accel);
      ids[m].push_back(problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<PlateAccelResidual, 3, 3, 6, 3, 3>(
              new PlateAccelResidual(pose.accel_mean, sigma, gravity, after ? p.c0_after : p.c0)),
          nullptr, p.bias, p.upper, after ? p.delta_after : p.delta, (*dirs)[k].data()));
      groups[m].push_back(0);
    }
    if (!imu.has_gyro) continue;
    problem.AddParameterBlock(p.gyro_bias, 3);
    problem.AddParameterBlock(p.gyro_matrix, 9);
    for (size_t k = 0; k < pose_count; ++k) {
      const PlatePoseData& pose = imu.poses[k];
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<PlateGyroPoseResidual, 3, 3>(
              new PlateGyroPoseResidual(pose.gyro_mean, pose.gyro_sigma * std::sqrt(factors.gyro))),
          nullptr, p.gyro_bias);
    }
    for (size_t k = 0; k + 1 < pose_count; ++k) {
      const GyroRotationData& turn = imu.turns[k];
      if (turn.t.size() < 2) continue;
      // The turn in which the unit moved has no row.
      if (p.split >= 0 && static_cast<int>(k) + 1 == p.split) continue;
      const bool after = p.split >= 0 && static_cast<int>(k) >= p.split;
      ids[m].push_back(problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<PlateTurnResidual, 2, 3, 9, 3, 3, 3>(
              new PlateTurnResidual(&turn, after ? p.c0_after : p.c0, factors.turn)),
          nullptr, p.gyro_bias, p.gyro_matrix, after ? p.delta_after : p.delta, (*dirs)[k].data(),
          (*dirs)[k + 1].data()));
      groups[m].push_back(2);
      row_turns[m].push_back(&turn);
    }
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = max_iterations;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  if (!summary.IsSolutionUsable()) {
    out->message = "the joint fit failed: " + summary.message;
    return false;
  }
  out->parameters = summary.num_effective_parameters;
  // chi2 per group, with the factors taken out.
  std::vector<ceres::ResidualBlockId> all_ids;
  problem.GetResidualBlocks(&all_ids);
  out->accel_rms.assign(members.size(), NAN);
  out->turn_rms_deg.assign(members.size(), NAN);
  for (size_t m = 0; m < members.size(); ++m) {
    const PlateImuData& imu = data[members[m]];
    double accel_sum = 0.0, turn_sum = 0.0;
    int accel_n = 0, turn_n = 0;
    for (size_t j = 0; j < ids[m].size(); ++j) {
      ceres::Problem::EvaluateOptions e;
      e.residual_blocks = {ids[m][j]};
      e.apply_loss_function = false;
      std::vector<double> r;
      problem.Evaluate(e, nullptr, &r, nullptr, nullptr);
      double s = 0.0;
      for (double x : r) s += x * x;
      if (groups[m][j] == 0) {
        out->chi2[0] += s / 1.0 * factors.accel;
        out->rows[0] += 3;
        const double sigma = imu.poses[j].accel_sigma * std::sqrt(factors.accel);
        accel_sum += s * sigma * sigma;
        accel_n += 3;
      } else {
        out->chi2[2] += s * factors.turn;
        out->rows[2] += 2;
        // Whitened by sqrt_information = I / sigma and the factor.
        const double sigma = 1.0 / row_turns[m][j - imu.poses.size()]->sqrt_information(0, 0);
        turn_sum += s * factors.turn * sigma * sigma;
        turn_n += 2;
      }
    }
    out->accel_rms[m] = accel_n ? std::sqrt(accel_sum / accel_n) : NAN;
    out->turn_rms_deg[m] = turn_n ? std::sqrt(turn_sum / turn_n) * 180.0 / M_PI : NAN;
  }
  // The gyroscope pose rows.
  for (size_t m = 0; m < members.size(); ++m) {
    const int i = members[m];
    if (!data[i].has_gyro) continue;
    const PlateImuParameters& p = (*params)[i];
    for (size_t k = 0; k < pose_count; ++k) {
      const PlatePoseData& pose = data[i].poses[k];
      for (int j = 0; j < 3; ++j) {
        const double r = (pose.gyro_mean[j] - p.gyro_bias[j]) / pose.gyro_sigma;
        out->chi2[1] += r * r;
      }
      out->rows[1] += 3;
    }
  }
  if (covariance) {
    // The Jacobian of the free blocks, columns scaled to unit norm; its
    // null space (singular values below 1e-9 of the largest) marks what the
    // data do not determine.
    std::vector<double*> blocks;
    std::vector<int> sizes;
    std::vector<std::vector<int>> member_columns(members.size());
    int columns = 0;
    for (size_t m = 0; m < members.size(); ++m) {
      const int i = members[m];
      PlateImuParameters& p = (*params)[i];
      std::vector<std::pair<double*, int>> list = {{p.bias, 3}, {p.upper, 6}};
      if (data[i].has_gyro) {
        list.push_back({p.gyro_bias, 3});
        list.push_back({p.gyro_matrix, 9});
      }
      if (i != held) list.push_back({p.delta, 3});
      for (const auto& [b, n] : list) {
        blocks.push_back(b);
        sizes.push_back(n);
        for (int c = 0; c < n; ++c) member_columns[m].push_back(columns + c);
        columns += n;
      }
      if (i == held) {
        // The held rotation: three columns that are not there.
        for (int c = 0; c < 3; ++c) member_columns[m].push_back(-1);
      }
      if (p.split >= 0) {
        blocks.push_back(p.delta_after);
        sizes.push_back(3);
        columns += 3;
      }
    }
    for (Eigen::Vector3d& d : *dirs) {
      blocks.push_back(d.data());
      sizes.push_back(2);
      columns += 2;
    }
    ceres::Problem::EvaluateOptions e;
    e.parameter_blocks = blocks;
    e.apply_loss_function = false;
    ceres::CRSMatrix crs;
    problem.Evaluate(e, nullptr, nullptr, nullptr, &crs);
    if (crs.num_cols != columns) {
      out->message = "the joint fit's Jacobian has an unexpected layout";
      return false;
    }
    Eigen::MatrixXd j = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
    for (int r = 0; r < crs.num_rows; ++r) {
      for (int k = crs.rows[r]; k < crs.rows[r + 1]; ++k) j(r, crs.cols[k]) = crs.values[k];
    }
    // Ceres' Jacobian is whitened with the factors in; the covariance is of
    // the factor-scaled rows, as wanted.
    Eigen::VectorXd norms = j.colwise().norm().transpose();
    for (int c = 0; c < norms.size(); ++c) {
      if (!(norms[c] > 0.0)) norms[c] = 1.0;
    }
    const Eigen::MatrixXd js = j * norms.cwiseInverse().asDiagonal();
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(js.transpose() * js);
    const Eigen::VectorXd lambda = eig.eigenvalues();
    const double tol = 1e-14 * (lambda.size() ? lambda.maxCoeff() : 0.0);
    const Eigen::MatrixXd& v = eig.eigenvectors();
    Eigen::VectorXd inv = Eigen::VectorXd::Zero(lambda.size());
    Eigen::VectorXd null_weight = Eigen::VectorXd::Zero(js.cols());
    for (int k = 0; k < lambda.size(); ++k) {
      if (lambda[k] > tol) {
        inv[k] = 1.0 / lambda[k];
      } else {
        null_weight += v.col(k).cwiseAbs2();
      }
    }
    Eigen::MatrixXd cov = v * inv.asDiagonal() * v.transpose();
    cov = norms.cwiseInverse().asDiagonal() * cov * norms.cwiseInverse().asDiagonal();
    for (int c = 0; c < cov.rows(); ++c) {
      if (null_weight[c] > 1e-6) {
        cov.row(c).setConstant(NAN);
        cov.col(c).setConstant(NAN);
      }
    }
    out->covariance.clear();
    for (size_t m = 0; m < members.size(); ++m) {
      const std::vector<int>& cols = member_columns[m];
      const int n = static_cast<int>(cols.size());
      Eigen::MatrixXd c = Eigen::MatrixXd::Zero(n, n);
      for (int a = 0; a < n; ++a) {
        for (int b = 0; b < n; ++b) {
          c(a, b) = cols[a] < 0 || cols[b] < 0 ? 0.0 : cov(cols[a], cols[b]);
        }
      }
      out->covariance.push_back(c);
    }
  }
  out->ok = true;
  return true;
}

// The three group factors from a solve: chi2 / dof per group, at least 1,
// the dof of each group its share of the total.
GroupFactors FactorsOf(const FitOutput& out) {
  GroupFactors f;
  const int rows = out.rows[0] + out.rows[1] + out.rows[2];
  const double dof = rows - out.parameters;
  if (dof <= 0.0) return f;
  double* targets[3] = {&f.accel, &f.gyro, &f.turn};
  for (int g = 0; g < 3; ++g) {
    if (out.rows[g] == 0) continue;
    const double group_dof = out.rows[g] * dof / rows;
    *targets[g] = std::max(1.0, out.chi2[g] / group_dof);
  }
  return f;
}

// Solve, reweigh the groups, solve again with the covariance.
bool FitWithFactors(const std::vector<PlateImuData>& data, const std::vector<int>& members,
                    int held, double gravity, int max_iterations,
                    std::vector<PlateImuParameters>* params, std::vector<Eigen::Vector3d>* dirs,
                    GroupFactors* factors, FitOutput* out) {
  GroupFactors f;
  FitOutput first;
  if (!Fit(data, members, held, gravity, f, false, max_iterations, params, dirs, &first)) {
    *out = first;
    return false;
  }
  f = FactorsOf(first);
  if (!Fit(data, members, held, gravity, f, true, max_iterations, params, dirs, out)) return false;
  *factors = f;
  return true;
}

// Starting intrinsics of one IMU from its poses: an axis-aligned ellipsoid
// sum_j a_j (v_j - c_j)^2 = 1 through the pose means (a sphere with fewer
// than 6 poses, the nominal scale with fewer than 4), then b = c and
// U = diag(g sqrt(a_j)).
void StartIntrinsics(const PlateImuData& imu, double gravity, PlateImuParameters* p) {
  const size_t n = imu.poses.size();
  const double s = imu.imu->accel_scale;
  for (int j = 0; j < 6; ++j) p->upper[j] = 0.0;
  p->upper[0] = p->upper[3] = p->upper[5] = s;
  for (int j = 0; j < 3; ++j) p->bias[j] = 0.0;
  if (n >= 6) {
    Eigen::MatrixXd a(n, 6);
    Eigen::VectorXd one = Eigen::VectorXd::Ones(n);
    for (size_t k = 0; k < n; ++k) {
      const Eigen::Vector3d v = imu.poses[k].accel_mean * s;
      a.row(k) << v.x() * v.x(), v.y() * v.y(), v.z() * v.z(), v.x(), v.y(), v.z();
    }
    const Eigen::VectorXd x = a.colPivHouseholderQr().solve(one);
    if (x.allFinite() && x[0] > 0 && x[1] > 0 && x[2] > 0) {
      Eigen::Vector3d c;
      double k = 1.0;
      for (int j = 0; j < 3; ++j) {
        c[j] = -x[3 + j] / (2.0 * x[j]);
        k += x[j] * c[j] * c[j];
      }
      if (k > 0.0) {
        for (int j = 0; j < 3; ++j) p->bias[j] = c[j] / s;
        p->upper[0] = s * gravity * std::sqrt(x[0] / k);
        p->upper[3] = s * gravity * std::sqrt(x[1] / k);
        p->upper[5] = s * gravity * std::sqrt(x[2] / k);
        return;
      }
    }
  }
  if (n >= 4) {
    // |v - c|^2 = r^2: 2 v.c + (r^2 - |c|^2) = |v|^2.
    Eigen::MatrixXd a(n, 4);
    Eigen::VectorXd y(n);
    for (size_t k = 0; k < n; ++k) {
      const Eigen::Vector3d v = imu.poses[k].accel_mean * s;
      a.row(k) << 2.0 * v.x(), 2.0 * v.y(), 2.0 * v.z(), 1.0;
      y[k] = v.squaredNorm();
    }
    const Eigen::VectorXd x = a.colPivHouseholderQr().solve(y);
    const double r2 = x[3] + x.head<3>().squaredNorm();
    if (x.allFinite() && r2 > 0.0) {
      for (int j = 0; j < 3; ++j) p->bias[j] = x[j] / s;
      const double u = s * gravity / std::sqrt(r2);
      p->upper[0] = p->upper[3] = p->upper[5] = u;
    }
  }
}

// Starting gyroscope: b_g the mean of the still means, M_g = s I with s
// the stated scale, or the data's when the two differ by more than 30 %:
// the largest ratio over the turns of the tilt between the two poses
// (from the accelerometer) to the integrated raw rate |sum (u - b_g) dt|
// (a turn about a horizontal axis shows its whole angle as tilt).
void StartGyro(const PlateImuData& imu, const std::vector<Eigen::Vector3d>& dirs,
               PlateImuParameters* p, std::vector<std::string>* notes) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const PlatePoseData& pose : imu.poses) mean += pose.gyro_mean;
  mean /= static_cast<double>(std::max<size_t>(1, imu.poses.size()));
  for (int j = 0; j < 3; ++j) p->gyro_bias[j] = mean[j];
  double data_scale = 0.0;
  for (size_t k = 0; k < imu.turns.size(); ++k) {
    const GyroRotationData& turn = imu.turns[k];
    if (turn.t.size() < 2) continue;
    const double tilt = std::acos(std::clamp(dirs[k].dot(dirs[k + 1]), -1.0, 1.0));
    if (tilt < 20.0 * M_PI / 180.0) continue;
    Eigen::Vector3d phi = Eigen::Vector3d::Zero();
    for (size_t j = 1; j < turn.t.size(); ++j) {
      phi += 0.5 * (turn.gyro[j] + turn.gyro[j - 1] - 2.0 * mean) * (turn.t[j] - turn.t[j - 1]);
    }
    if (phi.norm() > 0.0) data_scale = std::max(data_scale, tilt / phi.norm());
  }
  double scale = imu.imu->gyro_scale;
  if (data_scale > 0.0 && std::abs(std::log(data_scale / scale)) > std::log(1.3)) {
    std::ostringstream s;
    s << imu.imu->name << ": the turns show a gyroscope scale of about " << data_scale
      << " rad/s per raw unit, not the stated " << scale << ": started from the data's";
    notes->push_back(s.str());
    scale = data_scale;
  }
  for (int j = 0; j < 9; ++j) p->gyro_matrix[j] = j % 4 == 0 ? scale : 0.0;
}

// Intervals of `log` matched to the reference's by time: the shared pose is
// the intersection of one interval of every IMU.
bool SharedPoses(const std::vector<PlateImu>& imus, const std::vector<StaticDetection>& detections,
                 int reference, std::vector<std::pair<double, double>>* windows,
                 std::vector<std::string>* notes) {
  for (const StaticInterval& r : detections[reference].intervals) {
    double begin = r.t_begin, end = r.t_end;
    bool all = true;
    for (size_t i = 0; i < imus.size() && all; ++i) {
      if (static_cast<int>(i) == reference) continue;
      double best = 0.0;
      double b = 0.0, e = 0.0;
      for (const StaticInterval& o : detections[i].intervals) {
        const double overlap = std::min(o.t_end, end) - std::max(o.t_begin, begin);
        if (overlap > best) {
          best = overlap;
          b = o.t_begin;
          e = o.t_end;
        }
      }
      if (best < 0.5 * (r.t_end - r.t_begin)) {
        all = false;
        break;
      }
      begin = std::max(begin, b);
      end = std::min(end, e);
    }
    if (!all) {
      std::ostringstream s;
      s << "the still period at " << r.t_begin << "-" << r.t_end
        << " s is not still in every IMU: left out";
      notes->push_back(s.str());
      continue;
    }
    windows->push_back({begin, end});
  }
  return true;
}

PlatePoseData PoseOf(const ImuLog& log, double begin, double end) {
  PlatePoseData p;
  p.begin = std::lower_bound(log.t.begin(), log.t.end(), begin) - log.t.begin();
  p.end = std::upper_bound(log.t.begin(), log.t.end(), end) - log.t.begin();
  if (p.end <= p.begin) p.end = std::min(log.size(), p.begin + 1);
  const StaticInterval s = MakeInterval(log, p.begin, p.end);
  const double n = static_cast<double>(std::max<size_t>(1, s.count()));
  p.accel_mean = s.accel_mean;
  // Each axis at least its quantisation: step^2 / 12, the step the smallest
  // nonzero change between samples (and a relative floor for data with
  // none, such as a constant reading).
  const double accel_step2 = s.accel_resolution.squaredNorm() / 3.0;
  const double accel_var = std::max(
      {s.accel_cov.trace() / 3.0, accel_step2 / 12.0, 1e-24 * s.accel_mean.squaredNorm() + 1e-300});
  p.accel_sigma = std::sqrt(accel_var / n);
  p.gyro_mean = s.gyro_mean;
  double gyro_step2 = 0.0;
  if (log.has_gyro()) {
    Eigen::Vector3d step = Eigen::Vector3d::Zero();
    for (size_t k = p.begin + 1; k < std::min(p.end, p.begin + 256); ++k) {
      for (int j = 0; j < 3; ++j) {
        const double d = std::abs(log.gyro[k][j] - log.gyro[k - 1][j]);
        if (d > 0.0 && (step[j] == 0.0 || d < step[j])) step[j] = d;
      }
    }
    gyro_step2 = step.squaredNorm() / 3.0;
  }
  p.gyro_sigma = std::sqrt(std::max({s.gyro_cov.trace() / 3.0, gyro_step2 / 12.0, 1e-30}) / n);
  return p;
}

constexpr const char* kIntrinsicNames[21] = {
    "bias_x", "bias_y", "bias_z",      "u_xx",        "u_xy",        "u_xz", "u_yy",
    "u_yz",   "u_zz",   "gyro_bias_x", "gyro_bias_y", "gyro_bias_z", "m_xx", "m_xy",
    "m_xz",   "m_yx",   "m_yy",        "m_yz",        "m_zx",        "m_zy", "m_zz"};

// The per-IMU Calibration in the existing schema.
void FillCalibration(const PlateImuData& imu, const PlateImuParameters& p,
                     const Eigen::MatrixXd& cov, double gravity, Calibration* c) {
  c->success = true;
  c->method = "multi_imu";
  c->gravity = gravity;
  c->gravity_source = "config";
  AccelModel& a = c->accel.model;
  a.parameterization = AccelParameterization::kScaleMisalignment;
  a.bias = Eigen::Vector3d(p.bias[0], p.bias[1], p.bias[2]);
  a.SetUpper(p.upper);
  a.rotation.setIdentity();
  const int accel_n = 9;
  auto sd = [&](int k) { return std::sqrt(cov(k, k)); };
  for (int j = 0; j < 3; ++j) c->accel.bias_std[j] = sd(j);
  c->accel.matrix_std.setConstant(NAN);
  const int rc[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};
  for (int k = 0; k < 6; ++k) c->accel.matrix_std(rc[k][0], rc[k][1]) = sd(3 + k);
  c->accel.covariance = cov.topLeftCorner(accel_n, accel_n);
  c->accel.covariance_names.assign(kIntrinsicNames, kIntrinsicNames + accel_n);
  if (imu.has_gyro) {
    GyroCalibration& g = c->gyro;
    g.estimated = true;
    g.model.bias = Eigen::Vector3d(p.gyro_bias[0], p.gyro_bias[1], p.gyro_bias[2]);
    g.model.matrix = p.GyroMatrix();
    for (int j = 0; j < 3; ++j) g.bias_std[j] = sd(9 + j);
    for (int k = 0; k < 9; ++k) g.matrix_std(k / 3, k % 3) = sd(12 + k);
    g.covariance = cov.block(9, 9, 12, 12);
    g.covariance_names = {"bias_x", "bias_y", "bias_z", "m_xx", "m_xy", "m_xz",
                          "m_yx",   "m_yy",   "m_yz",   "m_zx", "m_zy", "m_zz"};
  }
  std::vector<double> residuals;
  for (const PlatePoseData& pose : imu.poses) {
    Eigen::Vector3d m = a.upper * (pose.accel_mean - a.bias);
    residuals.push_back(m.norm() - gravity);
  }
  c->residual_refined = SummarizeResiduals(residuals);
  c->message = "multi_imu: calibrated on the plate's shared poses";
}

// The standard deviations of [b U b_g M_g] (21; gyro NaN when absent).
std::vector<double> StdsOf(const Eigen::MatrixXd& cov, bool gyro) {
  std::vector<double> s(21, NAN);
  for (int k = 0; k < 9; ++k) s[k] = std::sqrt(cov(k, k));
  if (gyro) {
    for (int k = 9; k < 21; ++k) s[k] = std::sqrt(cov(k, k));
  }
  return s;
}

// Expands a member covariance without gyro (9 + 3) to the 24 layout.
Eigen::MatrixXd FullLayout(const Eigen::MatrixXd& cov, bool gyro) {
  if (gyro) return cov;
  Eigen::MatrixXd full = Eigen::MatrixXd::Constant(24, 24, NAN);
  full.topLeftCorner(9, 9) = cov.topLeftCorner(9, 9);
  full.bottomRightCorner(3, 3) = cov.bottomRightCorner(3, 3);
  full.block(0, 21, 9, 3) = cov.block(0, 9, 9, 3);
  full.block(21, 0, 3, 9) = cov.block(9, 0, 3, 9);
  return full;
}

void SinglePose(const std::vector<PlateImuData>& data, const MultiImuOptions& options,
                MultiImuResult* result) {
  const int ref = options.reference;
  // The reference's up direction and each unit's, nominal scale.
  std::vector<Eigen::Vector3d> up(data.size());
  for (size_t i = 0; i < data.size(); ++i) {
    const PlatePoseData& pose = data[i].poses[0];
    const double s = data[i].imu->accel_scale;
    const Eigen::Vector3d a = pose.accel_mean * s;
    up[i] = a.normalized();
    PlateImuResult& r = result->imus[i];
    r.up_offset = a.norm() - options.gravity;
    r.up_offset_std = pose.accel_sigma;
    Calibration& c = r.calibration;
    c.success = true;
    c.method = "multi_imu";
    c.gravity = options.gravity;
    c.accel.model.bias.setZero();
    c.accel.model.upper = Eigen::Matrix3d::Identity() * s;
    c.message =
        "multi_imu: one pose: only the offset along gravity (bias plus scale error along the "
        "up axis) is determined; bias, scale and non-orthogonality are not";
    c.warnings.push_back(c.message);
    r.joint_std.assign(21, NAN);
  }
  for (size_t i = 0; i < data.size(); ++i) {
    // The tilt between the units: the shortest rotation; the heading about
    // gravity is not determined.
    result->imus[i].rotation =
        Eigen::Quaterniond::FromTwoVectors(up[i], up[ref]).toRotationMatrix();
  }
  result->undetermined.push_back(
      "one pose: each unit's bias, scale, non-orthogonality and gyroscope model are not "
      "determined; only each unit's offset along gravity is (its up_offset)");
  result->undetermined.push_back(
      "one pose: the rotation between the units is determined only up to a turn about gravity "
      "(the tilt between them is known, the heading not)");
  result->undetermined.push_back("one pose: no turns, so no time offsets");
  result->success = true;
  result->message = "multi_imu: one shared pose; offsets along gravity only";
}

// sum |x_k - R S y_k|^2 at the best rotation R, S the sign change of axis
// `flip` (-1: none).
double DirectionMisfit(const std::vector<Eigen::Vector3d>& x, std::vector<Eigen::Vector3d> y,
                       int flip) {
  if (flip >= 0) {
    for (Eigen::Vector3d& v : y) v[flip] = -v[flip];
  }
  const Eigen::Matrix3d r = Wahba(x, y);
  double c = 0.0;
  for (size_t k = 0; k < x.size(); ++k) c += (x[k] - r * y[k]).squaredNorm();
  return c;
}

}  // namespace

Eigen::Matrix3d PlateImuParameters::Rotation() const {
  const Eigen::Vector3d d(delta[0], delta[1], delta[2]);
  if (d.norm() == 0.0) return c0;
  return c0 * Eigen::AngleAxisd(d.norm(), d.normalized()).toRotationMatrix();
}

Eigen::Matrix3d PlateImuParameters::RotationAfter() const {
  const Eigen::Vector3d d(delta_after[0], delta_after[1], delta_after[2]);
  if (d.norm() == 0.0) return c0_after;
  return c0_after * Eigen::AngleAxisd(d.norm(), d.normalized()).toRotationMatrix();
}

Eigen::Matrix3d PlateImuParameters::UpperMatrix() const {
  Eigen::Matrix3d u = Eigen::Matrix3d::Zero();
  u(0, 0) = upper[0];
  u(0, 1) = upper[1];
  u(0, 2) = upper[2];
  u(1, 1) = upper[3];
  u(1, 2) = upper[4];
  u(2, 2) = upper[5];
  return u;
}

Eigen::Matrix3d PlateImuParameters::GyroMatrix() const {
  Eigen::Matrix3d m;
  for (int k = 0; k < 9; ++k) m(k / 3, k % 3) = gyro_matrix[k];
  return m;
}

Eigen::Vector3d PlateImuParameters::Direction(const PlatePoseData& pose) const {
  return (UpperMatrix() * (pose.accel_mean - Eigen::Vector3d(bias[0], bias[1], bias[2])))
      .normalized();
}

Eigen::Matrix3d Wahba(const std::vector<Eigen::Vector3d>& x,
                      const std::vector<Eigen::Vector3d>& y) {
  Eigen::Matrix3d b = Eigen::Matrix3d::Zero();
  for (size_t k = 0; k < x.size(); ++k) b += x[k] * y[k].transpose();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(b, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixU() * d * svd.matrixV().transpose();
}

}  // namespace internal

bool MultiImuOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& what) {
    if (error) *error = "multi_imu: " + what;
    return false;
  };
  if (!(gravity > 0.0) || !std::isfinite(gravity)) return fail("gravity must be > 0");
  if (reference < 0) return fail("reference must be >= 0");
  if (!(timing_margin >= 0.0) || !(max_time_offset > 0.0))
    return fail("timing_margin must be >= 0 and max_time_offset > 0");
  if (!(permutation_tolerance_deg > 0.0) || !(mounting_warning_deg > 0.0) ||
      !(slip_min_deg > 0.0) || !(slip_factor > 0.0) || !(drift_factor > 0.0) || !(drift_min >= 0.0))
    return fail("the check thresholds must be > 0");
  if (max_iterations < 1) return fail("max_iterations must be >= 1");
  return detector.IsValid(error);
}

namespace {

bool CalibrateImpl(const std::vector<PlateImu>& imus, const MultiImuOptions& options,
                   MultiImuResult* result) {
  using namespace internal;
  *result = MultiImuResult();
  std::string error;
  if (!options.IsValid(&error)) {
    result->message = error;
    return false;
  }
  if (imus.empty()) {
    result->message = "multi_imu: no IMUs";
    return false;
  }
  if (options.reference >= static_cast<int>(imus.size())) {
    result->message = "multi_imu: the reference index is past the IMUs";
    return false;
  }
  std::set<std::string> names;
  for (const PlateImu& imu : imus) {
    if (!names.insert(imu.name).second) {
      result->message = "multi_imu: IMU name '" + imu.name + "' is given twice";
      return false;
    }
    if (!(imu.accel_scale > 0.0) || !(imu.gyro_scale > 0.0)) {
      result->message = "multi_imu: " + imu.name + ": accel and gyro scales must be > 0";
      return false;
    }
  }
  const int ref = options.reference;
  result->reference = ref;
  // Detection per IMU, then the shared poses.
  std::vector<StaticDetection> detections(imus.size());
  for (size_t i = 0; i < imus.size(); ++i) {
    if (!imus[i].log.Validate(&error)) {
      result->message = imus[i].name + ": " + error;
      return false;
    }
    if (!DetectStaticIntervals(imus[i].log, options.detector, &detections[i])) {
      result->message = imus[i].name + ": " + detections[i].message;
      return false;
    }
  }
  std::vector<std::pair<double, double>> windows;
  SharedPoses(imus, detections, ref, &windows, &result->warnings);
  if (windows.empty()) {
    result->message = "multi_imu: no still period is shared by every IMU";
    return false;
  }
  const size_t pose_count = windows.size();
  result->poses = static_cast<int>(pose_count);
  std::vector<PlateImuData> data(imus.size());
  for (size_t i = 0; i < imus.size(); ++i) {
    PlateImuData& d = data[i];
    d.imu = &imus[i];
    d.has_gyro = imus[i].log.has_gyro();
    double gyro_var = 0.0, accel_var = 0.0;
    for (const auto& [b, e] : windows) {
      d.poses.push_back(PoseOf(imus[i].log, b, e));
      const PlatePoseData& p = d.poses.back();
      const double n = static_cast<double>(p.end - p.begin);
      accel_var += p.accel_sigma * p.accel_sigma * n;
      gyro_var += p.gyro_sigma * p.gyro_sigma * n;
    }
    d.accel_noise = std::sqrt(accel_var / pose_count) * imus[i].accel_scale;
    d.gyro_noise = std::sqrt(gyro_var / pose_count) * imus[i].gyro_scale;
    // Convert the accelerometer sigmas to m/s^2.
    for (PlatePoseData& p : d.poses) p.accel_sigma *= imus[i].accel_scale;
  }
  result->imus.resize(imus.size());
  for (size_t i = 0; i < imus.size(); ++i) result->imus[i].name = imus[i].name;
  if (pose_count == 1) {
    SinglePose(data, options, result);
    return true;
  }
  // Turns.
  for (PlateImuData& d : data) {
    d.turns.resize(pose_count - 1);
    if (!d.has_gyro) continue;
    const ImuLog& log = d.imu->log;
    for (size_t k = 0; k + 1 < pose_count; ++k) {
      const size_t first = d.poses[k].end - 1, last = d.poses[k + 1].begin;
      if (last <= first + 1 || log.t[last] - log.t[first] > 120.0) continue;
      GyroRotationData& turn = d.turns[k];
      turn.t.assign(log.t.begin() + first, log.t.begin() + last + 1);
      turn.gyro.assign(log.gyro.begin() + first, log.gyro.begin() + last + 1);
      double h2 = 0.0;
      for (size_t j = 1; j < turn.t.size(); ++j) {
        h2 += std::pow(turn.t[j] - turn.t[j - 1], 2);
      }
      const double sigma = std::sqrt(d.gyro_noise * d.gyro_noise * h2 + 1e-12);
      turn.sqrt_information = Eigen::Matrix2d::Identity() / sigma;
    }
  }
  // Separate fits: each IMU alone, its own poses.
  std::vector<PlateImuParameters> separate(imus.size());
  std::vector<std::vector<Eigen::Vector3d>> own_dirs(imus.size());
  std::vector<FitOutput> separate_out(imus.size());
  for (size_t i = 0; i < imus.size(); ++i) {
    PlateImuParameters& p = separate[i];
    StartIntrinsics(data[i], options.gravity, &p);
    for (const PlatePoseData& pose : data[i].poses) own_dirs[i].push_back(p.Direction(pose));
    if (data[i].has_gyro) StartGyro(data[i], own_dirs[i], &p, &result->warnings);
    for (size_t k = 0; k < data[i].turns.size(); ++k) {
      data[i].turns[k].tangent = TangentBasis(own_dirs[i][k + 1]);
    }
    GroupFactors f;
    if (!FitWithFactors(data, {static_cast<int>(i)}, static_cast<int>(i), options.gravity,
                        options.max_iterations, &separate, &own_dirs[i], &f, &separate_out[i])) {
      result->message = imus[i].name + ": " + separate_out[i].message;
      return false;
    }
  }
  // The joint start: intrinsics from the separate fits, rotations by Wahba
  // between each IMU's directions and the reference's.
  std::vector<PlateImuParameters> joint = separate;
  std::vector<Eigen::Vector3d> dirs = own_dirs[ref];
  for (size_t i = 0; i < imus.size(); ++i) {
    PlateImuParameters& p = joint[i];
    for (int j = 0; j < 3; ++j) p.delta[j] = 0.0;
    if (static_cast<int>(i) != ref) {
      // Left-handed axes: one axis read with the wrong sign shows as a
      // reflection between the two sets of directions; the axis whose sign
      // change fits best is flipped in U (row j of U negated) and named.
      // A sign change of one axis equals that of another times a half turn:
      // the axis is the one that leaves the rotation nearest the stated.
      int flip = -1;
      const double none = DirectionMisfit(dirs, own_dirs[i], -1);
      const Eigen::Matrix3d stated =
          imus[ref].stated_mounting.transpose() * imus[i].stated_mounting;
      double nearest = 1e300;
      for (int j = 0; j < 3; ++j) {
        std::vector<Eigen::Vector3d> y = own_dirs[i];
        for (Eigen::Vector3d& v : y) v[j] = -v[j];
        if (DirectionMisfit(dirs, y, -1) >= 0.25 * none) continue;
        const Eigen::Matrix3d r = stated.transpose() * Wahba(dirs, y);
        const double angle = std::acos(std::clamp((r.trace() - 1.0) / 2.0, -1.0, 1.0));
        if (angle < nearest) {
          nearest = angle;
          flip = j;
        }
      }
      if (flip >= 0) {
        const int row[3][3] = {{0, 1, 2}, {-1, 3, 4}, {-1, -1, 5}};
        for (int c = 0; c < 3; ++c) {
          if (row[flip][c] >= 0) p.upper[row[flip][c]] = -p.upper[row[flip][c]];
        }
        for (Eigen::Vector3d& d : own_dirs[i]) d[flip] = -d[flip];
        // The gyroscope's axis reads with the same wrong sign: M_g = s S.
        const double scale =
            (std::abs(p.gyro_matrix[0]) + std::abs(p.gyro_matrix[4]) + std::abs(p.gyro_matrix[8])) /
            3.0;
        for (int k = 0; k < 9; ++k) p.gyro_matrix[k] = k % 4 == 0 ? scale : 0.0;
        p.gyro_matrix[4 * flip] = -scale;
        result->warnings.push_back(imus[i].name + "'s " + std::string(1, "xyz"[flip]) +
                                   " accelerometer axis reads with the wrong sign (its axes are "
                                   "left-handed): flipped or miswired axis?");
      }
    }
    p.c0 = static_cast<int>(i) == ref ? Eigen::Matrix3d::Identity() : Wahba(dirs, own_dirs[i]);
    for (size_t k = 0; k < data[i].turns.size(); ++k) {
      data[i].turns[k].tangent = TangentBasis(p.c0.transpose() * dirs[k + 1]);
    }
  }
  std::vector<int> members;
  for (size_t i = 0; i < imus.size(); ++i) members.push_back(static_cast<int>(i));
  GroupFactors factors;
  FitOutput out;
  if (!FitWithFactors(data, members, ref, options.gravity, options.max_iterations, &joint, &dirs,
                      &factors, &out)) {
    result->message = out.message;
    return false;
  }
  // A unit that moved: its own rotation after the move, and fit again.
  int split = -1;
  const int moved = FindMovedUnit(data, joint, options, &split, result);
  if (moved >= 0) {
    PlateImuParameters& p = joint[moved];
    p.split = split;
    std::vector<Eigen::Vector3d> x, y;
    for (size_t k = split; k < pose_count; ++k) {
      x.push_back(dirs[k]);
      y.push_back(p.Direction(data[moved].poses[k]));
    }
    p.c0_after = Wahba(x, y);
    for (int j = 0; j < 3; ++j) p.delta_after[j] = 0.0;
    for (size_t k = split; k < data[moved].turns.size(); ++k) {
      data[moved].turns[k].tangent = TangentBasis(p.c0_after.transpose() * dirs[k + 1]);
    }
    if (!FitWithFactors(data, members, ref, options.gravity, options.max_iterations, &joint, &dirs,
                        &factors, &out)) {
      result->message = out.message;
      return false;
    }
  }
  // The separate calibrations' sigmas with the joint fit's weights (the
  // same variance factors), so that the comparison shows what sharing the
  // poses gains.
  if (options.separate) {
    for (size_t i = 0; i < imus.size(); ++i) {
      FitOutput sep;
      if (Fit(data, {static_cast<int>(i)}, static_cast<int>(i), options.gravity, factors, true,
              options.max_iterations, &separate, &own_dirs[i], &sep)) {
        result->imus[i].separate_std = StdsOf(sep.covariance[0], data[i].has_gyro);
      }
    }
  }
  result->accel_factor = factors.accel;
  result->gyro_factor = factors.gyro;
  result->turn_factor = factors.turn;
  for (size_t i = 0; i < imus.size(); ++i) {
    PlateImuResult& r = result->imus[i];
    const Eigen::MatrixXd cov = FullLayout(out.covariance[i], data[i].has_gyro);
    FillCalibration(data[i], joint[i], cov, options.gravity, &r.calibration);
    r.joint_std = StdsOf(cov, data[i].has_gyro);
    r.rotation = joint[i].Rotation();
    r.rotation_covariance = cov.bottomRightCorner(3, 3);
    for (int j = 0; j < 3; ++j) r.rotation_std[j] = std::sqrt(r.rotation_covariance(j, j));
    if (static_cast<int>(i) == ref) {
      r.rotation_std.setZero();
      r.rotation_covariance.setZero();
    }
    r.accel_residual_rms = out.accel_rms[i];
    r.turn_residual_deg = out.turn_rms_deg[i];
    bool any_nan = false;
    for (double s : r.joint_std) any_nan = any_nan || !std::isfinite(s);
    if (any_nan && data[i].has_gyro) {
      r.calibration.warnings.push_back("the session does not determine every parameter of " +
                                       imus[i].name + " (those with no standard deviation)");
    }
  }
  result->turns = 0;
  for (const GyroRotationData& t : data[ref].turns) result->turns += t.t.size() >= 2;
  CheckMountings(data, joint, ref, options, result);
  EstimateTimeOffsets(data, joint, ref, options, result);
  result->undetermined.push_back(
      "the lever arm between the IMUs is not observable from gravity and slow turns: not "
      "estimated (the rotations and time offsets do not depend on it)");
  if (result->turns == 0) {
    result->undetermined.push_back(
        "static poses alone give no time offset: the session has no turns between its poses");
  }
  result->success = true;
  std::ostringstream s;
  s << "multi_imu: " << imus.size() << " IMUs on " << pose_count << " shared poses and "
    << result->turns << " turns";
  result->message = s.str();
  return true;
}

}  // namespace

bool CalibrateMultiImu(const std::vector<PlateImu>& imus, const MultiImuOptions& options,
                       MultiImuResult* result) {
  if (result == nullptr) return false;
  try {
    return CalibrateImpl(imus, options, result);
  } catch (const std::exception& e) {
    result->success = false;
    result->message = std::string("multi_imu failed: ") + e.what();
    return false;
  }
}

}  // namespace gravcal
