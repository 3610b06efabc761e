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
// `covariance`, the dense Jacobian of b_g and the free entries of the
// effects' block (`effect_free`, in block order).
void EvaluateGyroFit(const std::vector<std::unique_ptr<ceres::CostFunction>>& owned,
                     const double* const params[2], const std::vector<int>& effect_free,
                     bool covariance, Eigen::MatrixXd* jacobian, Eigen::VectorXd* residuals,
                     SensorFitSummary* fit) {
  fit->chi2 = 0.0;
  for (int k = 0; k < static_cast<int>(owned.size()); ++k) {
    double r[3];
    double jb[9], je[3 * kGyroEffectParameters];
    double* jacobians[2] = {jb, je};
    owned[k]->Evaluate(params, r, covariance ? jacobians : nullptr);
    for (int row = 0; row < 3; ++row) {
      fit->chi2 += r[row] * r[row];
      (*residuals)(3 * k + row) = r[row];
      if (!covariance) continue;
      int col = 0;
      for (int i = 0; i < 3; ++i) (*jacobian)(3 * k + row, col++) = jb[3 * row + i];
      for (int i : effect_free) {
        (*jacobian)(3 * k + row, col++) = je[kGyroEffectParameters * row + i];
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
  // The effects' block: the effects switched on from their initial values,
  // the others held at zero (effect_free: the entries that are fitted).
  double effect_block[kGyroEffectParameters] = {};
  std::vector<int> effect_free, effect_held;
  std::vector<Effect> fitted;
  for (const EffectInfo& info : EffectCatalogue()) {
    if (info.form != EffectForm::kGyroOffset) continue;
    const int offset = effects::kLayout.offset[static_cast<int>(info.effect)];
    const bool on = Contains(effects, info.effect);
    if (on) fitted.push_back(info.effect);
    const double* initial_values = initial_parameters.Block(info.effect);
    for (int i = 0; i < info.num_parameters; ++i) {
      effect_block[offset + i] = on ? initial_values[i] : 0.0;
      (on ? effect_free : effect_held).push_back(offset + i);
    }
  }

  std::vector<std::unique_ptr<ceres::CostFunction>> owned;
  for (int k = 0; k < n; ++k) {
    const StaticObservation& o = observations[k];
    owned.emplace_back(GyroStaticResidual::CreateWithEffects(
        o.gyro_mean, whitening[k], result->forces[k],
        TemperatureOffset(initial_parameters, o.temperature()),
        o.time() - initial_parameters.reference_time));
  }
  const double* params[2] = {bias, effect_block};
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
    problem.AddResidualBlock(cost.get(), loss.get(), bias, effect_block);
  }
  SensorFitSummary& fit = result->gyro_fit;
  const ceres::Solver::Summary summary =
      SolveGraduated(options, scales, effect_block, kGyroEffectParameters, effect_free, effect_held,
                     loss.get(), &problem, &fit);
  fit.fitted = true;
  fit.information = "static mean rates";
  if (loss) fit.information += std::string(" (") + ToString(options.loss) + " loss)";
  if (!summary.IsSolutionUsable()) {
    result->message = "gyroscope effect fit failed: " + summary.message;
    return false;
  }
  fit.parameter_names = {"gyro_bias_x", "gyro_bias_y", "gyro_bias_z"};
  for (Effect e : fitted) {
    for (const std::string& name : Info(e).parameter_names) fit.parameter_names.push_back(name);
  }
  const int np = static_cast<int>(fit.parameter_names.size());
  Eigen::MatrixXd jacobian(3 * n, np);
  Eigen::VectorXd residual_rows(3 * n);
  EvaluateGyroFit(owned, params, effect_free, options.compute_covariance, &jacobian, &residual_rows,
                  &fit);
  if (loss && options.compute_covariance) {
    WeightRowsByLoss(std::vector<int>(n, 3), options, &jacobian, &residual_rows);
  }
  fit.num_residuals = 3 * n;
  fit.num_parameters = np;
  result->gyro.bias = Eigen::Vector3d(bias[0], bias[1], bias[2]);
  std::copy(effect_block, effect_block + kGyroEffectParameters, result->parameters.gyro.begin());
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
