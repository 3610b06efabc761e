// The effect fit (effect_fit.h): checks, the accelerometer and gyroscope
// parts (effect_fit_accel.cc, effect_fit_gyro.cc, effect_fit_reml.cc) in
// turn, the estimates, and the pieces they share.
#include "gravcal/methods/effect_fit.h"

#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>

#include "estimation/robust_loss.h"
#include "estimation/solver_settings.h"
#include "gravcal/core/imu_model.h"
#include "gravcal/estimation/observability.h"
#include "gravcal/estimation/refinement.h"
#include "methods/between_pose_rotations.h"
#include "methods/effect_fit_parts.h"

namespace gravcal {
namespace internal {

ceres::Solver::Options EffectFitSolverOptions(const EffectFitOptions& o) {
  return SolverOptions(o.solver, ceres::DENSE_NORMAL_CHOLESKY);
}

void CovarianceFromJacobian(const Eigen::MatrixXd& jacobian, int rows_per_position,
                            int leverage_rows, SensorFitSummary* fit) {
  const ObservabilityReport obs =
      AnalyzeObservability(jacobian, fit->parameter_names, kEffectFitRankTolerance);
  fit->undetermined = obs.undetermined;
  fit->rank = obs.rank;
  const int n = static_cast<int>(jacobian.cols());
  // Column scaling keeps the units out of the conditioning.
  Eigen::VectorXd scale = jacobian.colwise().norm().transpose();
  for (int j = 0; j < n; ++j) {
    if (!(scale(j) > 0.0)) scale(j) = 1.0;
  }
  const Eigen::MatrixXd scaled = jacobian * scale.cwiseInverse().asDiagonal();
  Eigen::MatrixXd inverse;
  if (obs.full_rank()) {
    const Eigen::MatrixXd gram = scaled.transpose() * scaled;
    inverse = gram.ldlt().solve(Eigen::MatrixXd::Identity(n, n));
  } else {
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(scaled, Eigen::ComputeThinV);
    const Eigen::VectorXd s = svd.singularValues();
    Eigen::VectorXd inv2 = Eigen::VectorXd::Zero(s.size());
    for (int i = 0; i < s.size(); ++i) {
      if (s(i) > kEffectFitRankTolerance * s(0)) inv2(i) = 1.0 / (s(i) * s(i));
    }
    inverse = svd.matrixV() * inv2.asDiagonal() * svd.matrixV().transpose();
  }
  fit->covariance = scale.cwiseInverse().asDiagonal() * inverse * scale.cwiseInverse().asDiagonal();
  fit->leverage.clear();
  for (int k = 0; k * rows_per_position < leverage_rows; ++k) {
    double h = 0.0;
    for (int r = 0; r < rows_per_position; ++r) {
      const Eigen::RowVectorXd row = scaled.row(k * rows_per_position + r);
      h = std::max(h, (row * inverse * row.transpose())(0, 0));
    }
    fit->leverage.push_back(h);
  }
  for (const std::string& name : obs.undetermined) {
    const auto it = std::find(fit->parameter_names.begin(), fit->parameter_names.end(), name);
    const int i = static_cast<int>(it - fit->parameter_names.begin());
    fit->covariance.row(i).setConstant(NAN);
    fit->covariance.col(i).setConstant(NAN);
  }
}

Eigen::Matrix3d InverseCholesky(const Eigen::Matrix3d& covariance) {
  Eigen::LLT<Eigen::Matrix3d> llt(covariance);
  if (llt.info() != Eigen::Success) return Eigen::Matrix3d::Constant(NAN);
  const Eigen::Matrix3d l = llt.matrixL();
  return l.inverse();
}

void WeightRowsByLoss(const std::vector<int>& block_rows, const EffectFitOptions& options,
                      Eigen::MatrixXd* jacobian, Eigen::VectorXd* residual_rows) {
  const std::unique_ptr<ceres::LossFunction> rho(MakeLoss(options.loss, options.loss_scale));
  int row0 = 0;
  for (int rows : block_rows) {
    const double s = residual_rows->segment(row0, rows).squaredNorm();
    double values[3];
    rho->Evaluate(s, values);
    const double w = std::sqrt(std::max(0.0, values[1]));
    jacobian->middleRows(row0, rows) *= w;
    residual_rows->segment(row0, rows) *= w;
    row0 += rows;
  }
}

ceres::Problem::Options ProblemKeepingOwnership() {
  ceres::Problem::Options keep;
  keep.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  keep.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  return keep;
}

std::unique_ptr<ceres::LossFunctionWrapper> GraduatedLoss(const EffectFitOptions& options,
                                                          double first_scale) {
  if (options.loss == LossType::kNone) return nullptr;
  return std::make_unique<ceres::LossFunctionWrapper>(MakeLoss(options.loss, first_scale),
                                                      ceres::TAKE_OWNERSHIP);
}

ceres::Solver::Summary SolveGraduated(const EffectFitOptions& options,
                                      const std::vector<double>& scales, double* effect_block,
                                      int block_size, const std::vector<int>& effect_free,
                                      const std::vector<int>& effect_held,
                                      ceres::LossFunctionWrapper* loss, ceres::Problem* problem,
                                      SensorFitSummary* fit) {
  if (effect_free.empty()) {
    problem->SetParameterBlockConstant(effect_block);
  } else if (!effect_held.empty()) {
    problem->SetManifold(effect_block, new ceres::SubsetManifold(block_size, effect_held));
  }
  ceres::Solver::Summary summary;
  fit->iterations = 0;
  for (auto it = scales.rbegin(); it != scales.rend(); ++it) {
    if (loss) loss->Reset(MakeLoss(options.loss, *it), ceres::TAKE_OWNERSHIP);
    ceres::Solve(EffectFitSolverOptions(options), problem, &summary);
    fit->iterations += static_cast<int>(summary.iterations.size()) - 1;
    if (!summary.IsSolutionUsable()) break;
  }
  fit->converged = summary.IsSolutionUsable() && summary.termination_type == ceres::CONVERGENCE;
  return summary;
}

}  // namespace internal

namespace {

void FillEstimates(EffectFitResult* result) {
  result->estimates.clear();
  for (Effect e : result->effects) {
    const EffectInfo& info = Info(e);
    EffectEstimate est;
    est.effect = e;
    est.names = info.parameter_names;
    est.unit = info.unit;
    const SensorFitSummary& fit =
        info.sensor == EffectSensor::kAccelerometer ? result->accel_fit : result->gyro_fit;
    if (Info(e).form == EffectForm::kInUpper) {
      const Eigen::Matrix3d& u = result->accel.upper;
      est.values = {u(0, 1), u(0, 2), u(1, 2)};
    } else {
      est.values = result->parameters.Values(e);
    }
    for (const std::string& name : est.names) est.std.push_back(fit.Std(name));
    result->estimates.push_back(est);
  }
}

}  // namespace

double SensorFitSummary::Std(const std::string& name) const {
  const auto it = std::find(parameter_names.begin(), parameter_names.end(), name);
  if (it == parameter_names.end() || covariance.size() == 0) return NAN;
  const int i = static_cast<int>(it - parameter_names.begin());
  const double v = covariance(i, i);
  return v >= 0.0 ? std::sqrt(v) : NAN;
}

bool EffectFitOptions::IsValid(std::string* error) const {
  if (!(pose_disturbance_prior >= 0.0) || !(pose_disturbance_prior_dof >= 0.0) ||
      !(magnitude_extra_variance >= 0.0) || !std::isfinite(magnitude_extra_variance) ||
      !(rotation_gyro_bias_variance >= 0.0) || !std::isfinite(rotation_gyro_bias_variance)) {
    *error =
        "effect fit: magnitude_extra_variance, pose_disturbance_prior and its dof and "
        "rotation_gyro_bias_variance must be >= 0";
    return false;
  }
  if (!(loss_scale > 0.0) || !std::isfinite(loss_scale)) {
    *error = "effect fit: loss_scale must be positive";
    return false;
  }
  std::string solver_error;
  if (!solver.IsValid(&solver_error)) {
    *error = "effect fit: " + solver_error;
    return false;
  }
  return true;
}

bool FitEffects(const std::vector<StaticObservation>& observations, const AccelModel& initial,
                const GyroModel& initial_gyro, const EffectParameters& initial_parameters,
                double gravity, const EffectFitOptions& options, EffectFitResult* result) {
  *result = EffectFitResult();
  std::string error;
  if (!options.IsValid(&error)) {
    result->message = error;
    return false;
  }
  if (!(gravity > 0.0)) {
    result->message = "gravity must be positive";
    return false;
  }
  result->effects = options.effects;
  result->accel = initial;
  result->gyro = initial_gyro;
  result->parameters = initial_parameters;
  const int n = static_cast<int>(observations.size());
  if (options.fit_accel) {
    const int needed = AccelModelParameterCount(options.parameterization, options.effects);
    int trends = 0, trend_rows = 0;
    if (options.use_within_pose_trends) {
      for (const StaticObservation& o : observations) {
        if (!o.has_trend) continue;
        ++trends;
        trend_rows += o.trend_along_gravity ? 1 : 3;
      }
    }
    int rotation_extra = 0;
    if (options.use_between_pose_rotations) {
      const int turns = static_cast<int>(internal::TurnPairs(observations).size());
      if (turns >= internal::kMinRotations)
        rotation_extra = 2 * turns - internal::kRotationGyroColumns;
    }
    if (n + trend_rows + rotation_extra < needed) {
      std::ostringstream s;
      s << "the accelerometer model with " << needed << " parameters needs at least " << needed
        << " static positions, found " << n;
      if (trends > 0) s << " (and " << trends << " within-pose trends)";
      if (rotation_extra > 0)
        s << " (and " << rotation_extra / 2 + 6 << " rotations between poses)";
      result->message = s.str();
      return false;
    }
    Eigen::MatrixXd jacobian;
    Eigen::VectorXd residuals;
    if (!internal::FitAccel(observations, initial, initial_parameters, gravity, options,
                            options.magnitude_extra_variance, &jacobian, &residuals, result)) {
      return false;
    }
    if (options.estimate_pose_variance && options.compute_covariance &&
        !internal::AbsorbMagnitudeVariance(observations, initial, initial_parameters, gravity,
                                           options, &jacobian, &residuals, result)) {
      return false;
    }
  } else {
    result->accel_residuals.resize(n);
    result->forces.resize(n);
    result->accel_sigmas.resize(n);
    for (int k = 0; k < n; ++k) {
      result->accel_residuals[k] =
          AccelResidual(*result, observations[k], gravity, &result->forces[k]);
      result->accel_sigmas[k] = AccelSigma(*result, observations[k]);
    }
  }
  const bool all_gyro = n > 0 && std::all_of(observations.begin(), observations.end(),
                                             [](const StaticObservation& o) { return o.has_gyro; });
  if (options.fit_gyro && all_gyro) {
    if (!internal::FitGyro(observations, initial_gyro, initial_parameters, options, result))
      return false;
  }
  FillEstimates(result);
  std::ostringstream s;
  s << "fitted " << n << " positions";
  if (result->accel_fit.fitted) {
    s << "; accelerometer chi2 " << result->accel_fit.chi2 << " on " << result->accel_fit.dof()
      << " dof";
  }
  if (result->gyro_fit.fitted) {
    s << "; gyroscope chi2 " << result->gyro_fit.chi2 << " on " << result->gyro_fit.dof() << " dof";
  }
  result->message = s.str();
  return true;
}

double AccelResidual(const EffectFitResult& fit, const StaticObservation& observation,
                     double gravity, Eigen::Vector3d* force) {
  const Eigen::Vector3d m = fit.accel.upper * (observation.accel.raw_mean - fit.accel.bias);
  Eigen::Vector3d a;
  if (!CorrectAccel(fit.parameters, fit.effects, m, observation.temperature(), observation.time(),
                    &a)) {
    a = m;
  }
  if (force != nullptr) *force = a;
  return a.norm() - gravity;
}

double AccelSigma(const EffectFitResult& fit, const StaticObservation& observation) {
  return MagnitudeSigmas({observation.accel}, fit.accel)[0];
}

Eigen::Vector3d GyroResidual(const EffectFitResult& fit, const StaticObservation& observation,
                             const Eigen::Vector3d& force, double* whitened_squared) {
  const Eigen::Vector3d e =
      observation.gyro_mean - fit.gyro.bias -
      GyroOffset(fit.parameters, fit.effects, force, observation.temperature(), observation.time());
  if (whitened_squared != nullptr) {
    *whitened_squared = e.dot(observation.gyro_mean_cov.ldlt().solve(e));
  }
  return e;
}

}  // namespace gravcal
