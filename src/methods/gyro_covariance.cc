#include "methods/gyro_covariance.h"

#include <ceres/ceres.h>
#include <ceres/covariance.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <memory>

#include "core/warnings.h"
#include "estimation/accel_uncertainty.h"
#include "methods/direction_noise.h"

namespace gravcal {
namespace internal {
namespace {

using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// The covariance the accelerometer's own uncertainty adds to the free
// parameters when the accelerometer is held (not joint): S C_a S^T, with
// S = -(J_x^T J_x)^-1 J_x^T J_a the first-order change of the estimate
// with the accelerometer's (b_a', free U') (normalised units), J_a from the
// joint form of the rotation residuals; jx is the whitened Jacobian of all
// residuals in the free columns.
Eigen::MatrixXd AccelContribution(const Eigen::MatrixXd& jx, const GyroLayout& layout,
                                  const GyroPrepared& prep,
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
Eigen::MatrixXd SharedPoseCorrection(const Eigen::MatrixXd& j, const GyroPrepared& prep,
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

// The scale from normalised to SI units of every ambient entry: b = c + b' / k,
// M = k M', G = G, accelerometer as in normalization.h.
Eigen::VectorXd AmbientToSi(const GyroLayout& layout, double k, const Normalization& norm) {
  Eigen::VectorXd to_si = Eigen::VectorXd::Ones(layout.size);
  to_si.head<3>().setConstant(1.0 / k);
  to_si.segment<9>(layout.matrix).setConstant(k);
  if (layout.accel_bias >= 0) {
    to_si.segment<3>(layout.accel_bias).setConstant(norm.scale);
    to_si.segment<kUpperSize>(layout.accel_upper).setConstant(1.0 / norm.scale);
  }
  return to_si;
}

// Splits the free tangent covariance (normalised units) into the
// gyroscope's (SI, with its standard deviations) and, joint, the
// accelerometer's (b_a, free U in the refinement's order, SI).
void StoreCovariance(const GyroLayout& layout, const GyroFreeColumns& free,
                     const Eigen::VectorXd& to_si, const Normalization& norm,
                     const RowMajorMatrix& tangent, GyroCalibrationResult* result) {
  GyroCalibrationResult& r = *result;
  const int nf = static_cast<int>(free.names.size());
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
}

}  // namespace

void ComputeGyroCovariance(const GyroPrepared& prep, const GyroLayout& layout,
                           const GyroProblem& built, const GyroFreeColumns& free,
                           const GyroWeights& weights, const AccelModel& accel,
                           const AccelModel& accel_final, const Normalization& norm,
                           const Eigen::MatrixXd& accel_covariance, std::vector<double>* x,
                           GyroCalibrationResult* result) {
  // Covariance of the free parameters (tangent space, normalised), then
  // mapped to SI.
  const Eigen::VectorXd to_si = AmbientToSi(layout, prep.scale, norm);
  ceres::Covariance::Options covariance_options;
  covariance_options.algorithm_type = ceres::DENSE_SVD;
  covariance_options.num_threads = 1;
  ceres::Covariance covariance(covariance_options);
  const int nf = static_cast<int>(free.names.size());
  RowMajorMatrix tangent(nf, nf);
  if (covariance.Compute(built.free_blocks, built.problem.get()) &&
      covariance.GetCovarianceMatrixInTangentSpace(built.free_blocks, tangent.data())) {
    const Eigen::MatrixXd jacobian = GyroAmbientJacobian(built, layout, x) * free.basis;
    tangent += SharedPoseCorrection(jacobian, prep, weights.rotations, weights.turns, accel_final,
                                    tangent);
    if (layout.accel_bias < 0 && accel_covariance.size() > 0) {
      tangent += AccelContribution(jacobian, layout, prep, weights.rotations, x, accel, norm,
                                   accel_covariance);
    }
    StoreCovariance(layout, free, to_si, norm, tangent, result);
  } else {
    AddWarning(WarningCode::kNoCovariance,
               "the gyroscope covariance could not be computed (the problem is rank deficient); "
               "no standard deviations are reported",
               &result->warnings, &result->warning_codes);
  }
}

}  // namespace internal
}  // namespace gravcal
