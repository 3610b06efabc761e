// The REML of the effect fit (effect_fit.h, estimate_pose_variance):
// one extra variance common to the position magnitudes, what the pose means
// share beyond their samples' noise, and the refit that absorbs it.
#include <Eigen/Core>
#include <cmath>
#include <string>
#include <vector>

#include "estimation/variance_component.h"
#include "gravcal/estimation/observability.h"
#include "gravcal/methods/effect_fit.h"
#include "methods/effect_fit_parts.h"

namespace gravcal {
namespace internal {
namespace {

// REML of one extra variance of the magnitudes (estimate_pose_variance)
// from a finished fit and its whitened Jacobian (magnitude rows first). The
// magnitude rows enter unwhitened (m/s^2, sigma_k), the trend rows whitened
// (sigma 1): s^2, of the order of sigma_k^2 (1e-7 (m/s^2)^2), is then
// immaterial beside the trend rows' unit variance, so it is the magnitudes'
// excess alone. False when the magnitudes leave no degree of freedom.
bool MagnitudeVariance(const EffectFitResult& fit, const Eigen::MatrixXd& whitened_jacobian,
                       const Eigen::VectorXd& whitened_residuals, const EffectFitOptions& options,
                       VarianceComponent* component) {
  const int n = static_cast<int>(fit.accel_sigmas.size());
  const int rows = static_cast<int>(whitened_jacobian.rows());
  // Residual directions of the magnitudes: n minus what the parameters
  // take from them beyond what the trends already determine.
  const std::vector<std::string>& names = fit.accel_fit.parameter_names;
  const int trend_rank = rows > n ? AnalyzeObservability(whitened_jacobian.bottomRows(rows - n),
                                                         names, kEffectFitRankTolerance)
                                        .rank
                                  : 0;
  const int magnitude_dof = n - (fit.accel_fit.rank - trend_rank);
  if (magnitude_dof < 1 && !(options.pose_disturbance_prior_dof > 0.0)) {
    component->message =
        "the position magnitudes leave no residual degree of freedom: their extra variance is "
        "not estimated (give a prior)";
    return false;
  }
  VariancePrior prior;
  prior.variance = options.pose_disturbance_prior * options.pose_disturbance_prior;
  prior.dof = options.pose_disturbance_prior_dof;
  Eigen::VectorXd r = whitened_residuals;
  Eigen::VectorXd sigmas = Eigen::VectorXd::Ones(r.size());
  Eigen::MatrixXd jacobian = whitened_jacobian;
  for (int k = 0; k < n; ++k) {
    r(k) *= fit.accel_sigmas[k];
    sigmas(k) = fit.accel_sigmas[k];
    jacobian.row(k) *= fit.accel_sigmas[k];
  }
  return EstimateVarianceComponent(r, sigmas, jacobian, component, prior);
}

}  // namespace

bool AbsorbMagnitudeVariance(const std::vector<StaticObservation>& observations,
                             const AccelModel& initial, const EffectParameters& initial_parameters,
                             double gravity, const EffectFitOptions& options,
                             Eigen::MatrixXd* jacobian, Eigen::VectorXd* residuals,
                             EffectFitResult* result) {
  const int n = static_cast<int>(observations.size());
  VarianceComponent component;
  if (MagnitudeVariance(*result, *jacobian, *residuals, options, &component) &&
      component.variance > 0.0) {
    double mean_white = 0.0;
    for (double sigma : result->accel_sigmas) mean_white += sigma * sigma / n;
    EffectFitResult refit = *result;
    if (!FitAccel(observations, initial, initial_parameters, gravity, options,
                  options.magnitude_extra_variance + component.variance, jacobian, residuals,
                  &refit)) {
      *result = refit;
      return false;
    }
    *result = refit;
    component.absorbed = true;
    result->magnitude_variance_inflation = StudentInflation(component, mean_white, nullptr);
    result->accel_fit.covariance *= result->magnitude_variance_inflation;
    result->accel_bias_std *= std::sqrt(result->magnitude_variance_inflation);
  }
  result->magnitude_variance = component;
  return true;
}

}  // namespace internal
}  // namespace gravcal
