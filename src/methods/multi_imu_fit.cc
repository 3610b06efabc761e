// The multi-IMU calibration's joint Ceres problem (methods/multi_imu.h):
// its residuals, one solve with its covariance and null space, and the
// variance factors of the row groups.
#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <ceres/sphere_manifold.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>

#include "estimation/solver_settings.h"
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

}  // namespace

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

bool Fit(const std::vector<PlateImuData>& data, const std::vector<int>& members, int held,
         double gravity, const std::vector<GroupFactors>& member_factors, bool covariance,
         int max_iterations, std::vector<PlateImuParameters>* params,
         std::vector<Eigen::Vector3d>* dirs, FitOutput* out) {
  auto factors_of = [&](size_t m) {
    return m < member_factors.size() ? member_factors[m] : GroupFactors();
  };
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
    const GroupFactors factors = factors_of(m);
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
  const ceres::Solver::Options options =
      internal::SolverOptions(internal::CeresDefaultTolerances(max_iterations), ceres::DENSE_QR);
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
  out->chi2.assign(members.size(), {0.0, 0.0, 0.0});
  out->rows.assign(members.size(), {0, 0, 0});
  for (size_t m = 0; m < members.size(); ++m) {
    const PlateImuData& imu = data[members[m]];
    const GroupFactors factors = factors_of(m);
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
        out->chi2[m][0] += s * factors.accel;
        out->rows[m][0] += 3;
        const double sigma = imu.poses[j].accel_sigma * std::sqrt(factors.accel);
        accel_sum += s * sigma * sigma;
        accel_n += 3;
      } else {
        out->chi2[m][2] += s * factors.turn;
        out->rows[m][2] += 2;
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
        out->chi2[m][1] += r * r;
      }
      out->rows[m][1] += 3;
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

// The group factors of each member from a solve: chi2 / dof per member and
// group, at least 1, the dof of each its share of the total by rows.
std::vector<GroupFactors> FactorsOf(const FitOutput& out,
                                    std::vector<std::array<double, 3>>* group_dofs) {
  std::vector<GroupFactors> f(out.rows.size());
  if (group_dofs != nullptr) group_dofs->assign(out.rows.size(), {0.0, 0.0, 0.0});
  int rows = 0;
  for (const std::array<int, 3>& r : out.rows) rows += r[0] + r[1] + r[2];
  const double dof = rows - out.parameters;
  if (dof <= 0.0) return f;
  for (size_t m = 0; m < f.size(); ++m) {
    double* targets[3] = {&f[m].accel, &f[m].gyro, &f[m].turn};
    for (int g = 0; g < 3; ++g) {
      if (out.rows[m][g] == 0) continue;
      const double group_dof = out.rows[m][g] * dof / rows;
      *targets[g] = std::max(1.0, out.chi2[m][g] / group_dof);
      if (group_dofs != nullptr) (*group_dofs)[m][g] = group_dof;
    }
  }
  return f;
}

bool FitWithFactors(const std::vector<PlateImuData>& data, const std::vector<int>& members,
                    int held, double gravity, int max_iterations,
                    const std::vector<GroupFactors>& prior, std::vector<PlateImuParameters>* params,
                    std::vector<Eigen::Vector3d>* dirs, std::vector<GroupFactors>* factors,
                    FitOutput* out) {
  FitOutput first;
  if (!Fit(data, members, held, gravity, prior, false, max_iterations, params, dirs, &first)) {
    *out = first;
    return false;
  }
  std::vector<std::array<double, 3>> dofs;
  std::vector<GroupFactors> f = FactorsOf(first, &dofs);
  if (prior.size() == f.size()) {
    // A member's own factor stands unless this fit's rows of it show more
    // misfit than its noise explains: beyond 2 standard deviations of
    // chi2 / dof (sqrt(2 / dof)) above it.
    for (size_t m = 0; m < f.size(); ++m) {
      const double own[3] = {prior[m].accel, prior[m].gyro, prior[m].turn};
      double* now[3] = {&f[m].accel, &f[m].gyro, &f[m].turn};
      for (int g = 0; g < 3; ++g) {
        const double limit = own[g] * (1.0 + 2.0 * std::sqrt(2.0 / std::max(1.0, dofs[m][g])));
        if (*now[g] <= limit) *now[g] = own[g];
      }
    }
  }
  if (!Fit(data, members, held, gravity, f, true, max_iterations, params, dirs, out)) return false;
  *factors = f;
  return true;
}

}  // namespace internal
}  // namespace gravcal
