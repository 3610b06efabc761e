// The gyroscope part of the effect fit (effect_fit.h): b_g and the
// gyroscope effects from the static mean rates, with the robust loss of the
// accelerometer part.
#include <ceres/ceres.h>

#include <Eigen/Core>
#include <algorithm>
#include <memory>
#include <sstream>

#include "estimation/robust_loss.h"
#include "gravcal/methods/effect_fit.h"
#include "gravcal/residuals/gyro_static_residual.h"
#include "methods/effect_fit_parts.h"

namespace gravcal {
namespace internal {
namespace {

// Per position, L_k^-1 of the covariance of the mean reading; false with
// the message when one is not finite.
bool GyroWhitening(const std::vector<StaticObservation>& observations,
                   std::vector<Eigen::Matrix3d>* whitening, EffectFitResult* result) {
  whitening->resize(observations.size());
  for (size_t k = 0; k < observations.size(); ++k) {
    (*whitening)[k] = InverseCholesky(observations[k].gyro_mean_cov);
    if (!(*whitening)[k].allFinite()) {
      std::ostringstream msg;
      msg << "position " << k << " has no usable gyroscope noise estimate";
      result->message = msg.str();
      return false;
    }
  }
  return true;
}

// fit->chi2, the whitened residuals (3 rows per position) and, with
// `covariance`, the dense Jacobian of b_g and the blocks that are on (G,
// gamma, eta).
void EvaluateGyroFit(const std::vector<std::unique_ptr<ceres::CostFunction>>& owned,
                     const double* const params[4], const bool on[3], bool covariance,
                     Eigen::MatrixXd* jacobian, Eigen::VectorXd* residuals, SensorFitSummary* fit) {
  fit->chi2 = 0.0;
  for (int k = 0; k < static_cast<int>(owned.size()); ++k) {
    double r[3];
    double jb[9], jg[27], jt[9], jd[9];
    double* jacobians[4] = {jb, jg, jt, jd};
    owned[k]->Evaluate(params, r, covariance ? jacobians : nullptr);
    for (int row = 0; row < 3; ++row) {
      fit->chi2 += r[row] * r[row];
      (*residuals)(3 * k + row) = r[row];
      if (!covariance) continue;
      int col = 0;
      for (int i = 0; i < 3; ++i) (*jacobian)(3 * k + row, col++) = jb[3 * row + i];
      if (on[0]) {
        for (int i = 0; i < 9; ++i) (*jacobian)(3 * k + row, col++) = jg[9 * row + i];
      }
      if (on[1]) {
        for (int i = 0; i < 3; ++i) (*jacobian)(3 * k + row, col++) = jt[3 * row + i];
      }
      if (on[2]) {
        for (int i = 0; i < 3; ++i) (*jacobian)(3 * k + row, col++) = jd[3 * row + i];
      }
    }
  }
}

}  // namespace

bool FitGyro(const std::vector<StaticObservation>& observations, const GyroModel& initial_gyro,
             const EffectParameters& initial_parameters, const EffectFitOptions& options,
             EffectFitResult* result) {
  const std::vector<Effect>& effects = options.effects;
  const int n = static_cast<int>(observations.size());
  std::vector<Eigen::Matrix3d> whitening;
  if (!GyroWhitening(observations, &whitening, result)) return false;
  double bias[3] = {initial_gyro.bias(0), initial_gyro.bias(1), initial_gyro.bias(2)};
  double g[9];
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) g[3 * r + c] = initial_parameters.gyro_g_sensitivity(r, c);
  }
  double temperature_bias[3], drift[3];
  for (int i = 0; i < 3; ++i) {
    temperature_bias[i] = initial_parameters.gyro_temperature_bias(i);
    drift[i] = initial_parameters.gyro_bias_drift(i);
  }
  const bool on_g = Contains(effects, Effect::kGyroGSensitivity);
  const bool on_t = Contains(effects, Effect::kGyroTemperatureBias);
  const bool on_d = Contains(effects, Effect::kGyroBiasDrift);
  if (!on_g) std::fill(g, g + 9, 0.0);
  if (!on_t) std::fill(temperature_bias, temperature_bias + 3, 0.0);
  if (!on_d) std::fill(drift, drift + 3, 0.0);

  std::vector<std::unique_ptr<ceres::CostFunction>> owned;
  for (int k = 0; k < n; ++k) {
    const StaticObservation& o = observations[k];
    owned.emplace_back(GyroStaticResidual::CreateWithEffects(
        o.gyro_mean, whitening[k], result->forces[k],
        TemperatureOffset(initial_parameters, o.temperature()),
        o.time() - initial_parameters.reference_time));
  }
  const double* params[4] = {bias, g, temperature_bias, drift};
  // The robust loss of the accelerometer part, graduated the same way: from
  // a scale that holds every initial residual down to loss_scale.
  double largest = 0.0;
  if (options.loss != LossType::kNone) {
    for (const auto& cost : owned) {
      Eigen::Vector3d r;
      if (cost->Evaluate(params, r.data(), nullptr)) largest = std::max(largest, r.norm());
    }
  }
  const std::vector<double> scales = GraduatedLossScales(options.loss, options.loss_scale, largest);
  ceres::Problem problem(ProblemKeepingOwnership());
  std::unique_ptr<ceres::LossFunctionWrapper> loss = GraduatedLoss(options, scales.back());
  for (const auto& cost : owned) {
    problem.AddResidualBlock(cost.get(), loss.get(), bias, g, temperature_bias, drift);
  }
  if (!on_g) problem.SetParameterBlockConstant(g);
  if (!on_t) problem.SetParameterBlockConstant(temperature_bias);
  if (!on_d) problem.SetParameterBlockConstant(drift);
  // Once per loss scale, widest first (one solve without a loss).
  ceres::Solver::Summary summary;
  SensorFitSummary& fit = result->gyro_fit;
  fit.iterations = 0;
  for (auto it = scales.rbegin(); it != scales.rend(); ++it) {
    if (loss) loss->Reset(MakeLoss(options.loss, *it), ceres::TAKE_OWNERSHIP);
    ceres::Solve(EffectFitSolverOptions(options), &problem, &summary);
    fit.iterations += static_cast<int>(summary.iterations.size()) - 1;
    if (!summary.IsSolutionUsable()) break;
  }
  fit.fitted = true;
  fit.information = "static mean rates";
  if (loss) fit.information += std::string(" (") + ToString(options.loss) + " loss)";
  fit.converged = summary.IsSolutionUsable() && summary.termination_type == ceres::CONVERGENCE;
  if (!summary.IsSolutionUsable()) {
    result->message = "gyroscope effect fit failed: " + summary.message;
    return false;
  }
  fit.parameter_names = {"gyro_bias_x", "gyro_bias_y", "gyro_bias_z"};
  const Effect kGyroEffects[3] = {Effect::kGyroGSensitivity, Effect::kGyroTemperatureBias,
                                  Effect::kGyroBiasDrift};
  const bool on[3] = {on_g, on_t, on_d};
  for (int b = 0; b < 3; ++b) {
    if (!on[b]) continue;
    for (const std::string& name : Info(kGyroEffects[b]).parameter_names) {
      fit.parameter_names.push_back(name);
    }
  }
  const int np = static_cast<int>(fit.parameter_names.size());
  Eigen::MatrixXd jacobian(3 * n, np);
  Eigen::VectorXd residual_rows(3 * n);
  EvaluateGyroFit(owned, params, on, options.compute_covariance, &jacobian, &residual_rows, &fit);
  if (loss && options.compute_covariance) {
    WeightRowsByLoss(std::vector<int>(n, 3), options, &jacobian, &residual_rows);
  }
  fit.num_residuals = 3 * n;
  fit.num_parameters = np;
  result->gyro.bias = Eigen::Vector3d(bias[0], bias[1], bias[2]);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) result->parameters.gyro_g_sensitivity(r, c) = g[3 * r + c];
  }
  result->parameters.gyro_temperature_bias = Eigen::Vector3d(temperature_bias);
  result->parameters.gyro_bias_drift = Eigen::Vector3d(drift);
  if (options.compute_covariance) {
    CovarianceFromJacobian(jacobian, 3, 3 * n, &fit);
    for (int i = 0; i < 3; ++i) result->gyro_bias_std(i) = fit.Std(fit.parameter_names[i]);
  }
  result->gyro_residuals.resize(n);
  result->gyro_sigmas.resize(n);
  for (int k = 0; k < n; ++k) {
    double w2 = 0.0;
    result->gyro_residuals[k] = GyroResidual(*result, observations[k], result->forces[k], &w2);
    result->gyro_sigmas[k] = observations[k].gyro_mean_cov.diagonal().cwiseSqrt();
  }
  return true;
}

}  // namespace internal
}  // namespace gravcal
