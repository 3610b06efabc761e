#include "workflows/discovery_cross_validation.h"

#include <cmath>

namespace gravcal {
namespace internal {
namespace {

// Leverage above which a position counts as not predictable by the others.
constexpr double kMaxLeverage = 0.99;

}  // namespace

Gap InSampleGap(const EffectFitResult& fit, bool has_gyro) {
  Gap g;
  const size_t n = fit.accel_residuals.size();
  if (n == 0) return g;
  double s = 0.0, w = 0.0;
  for (size_t k = 0; k < n; ++k) {
    s += fit.accel_residuals[k] * fit.accel_residuals[k];
    const double z = fit.accel_residuals[k] / fit.accel_sigmas[k];
    w += z * z;
  }
  g.accel = std::sqrt(s / n);
  g.accel_sigma = std::sqrt(w / n);
  if (has_gyro && fit.gyro_residuals.size() == n) {
    s = 0.0;
    for (const Eigen::Vector3d& e : fit.gyro_residuals) s += e.squaredNorm();
    g.gyro = std::sqrt(s / (3.0 * n));
    g.gyro_sigma = std::sqrt(fit.gyro_fit.chi2 / (3.0 * n));
  }
  return g;
}

bool CrossValidate(const DiscoveryContext& ctx, const std::vector<Effect>& effects,
                   const EffectFitResult& full, EffectSensor sensor, Gap* cv,
                   std::vector<double>* accel_residuals,
                   std::vector<Eigen::Vector3d>* gyro_residuals) {
  const std::vector<StaticObservation>& obs = *ctx.observations;
  const size_t n = obs.size();
  const bool accel = sensor == EffectSensor::kAccelerometer;
  std::vector<StaticObservation> subset;
  subset.reserve(n);
  double s = 0.0, w = 0.0;
  std::vector<double> ar(n, NAN);
  std::vector<Eigen::Vector3d> gr(n, Eigen::Vector3d::Constant(NAN));
  // A position with leverage near 1 is not predicted by the others: leave
  // it out of the gap rather than let one undetermined fold swamp it.
  const std::vector<double>& leverage = accel ? full.accel_fit.leverage : full.gyro_fit.leverage;
  int unpredictable = 0;
  for (size_t j = 0; j < n; ++j) {
    if (j < leverage.size() && leverage[j] > kMaxLeverage) {
      ++unpredictable;
      continue;
    }
    subset.clear();
    for (size_t k = 0; k < n; ++k) {
      if (k != j) subset.push_back(obs[k]);
    }
    EffectFitResult fold;
    if (!FitDiscoveryModel(ctx, subset, effects, full, accel, !accel, false, &fold)) return false;
    if (accel) {
      ar[j] = AccelResidual(fold, obs[j], ctx.gravity, nullptr);
      s += ar[j] * ar[j];
      const double z = ar[j] / full.accel_sigmas[j];
      w += z * z;
    } else {
      double w2 = 0.0;
      gr[j] = GyroResidual(fold, obs[j], full.forces[j], &w2);
      s += gr[j].squaredNorm();
      w += w2;
    }
  }
  const double used = static_cast<double>(n - unpredictable);
  if (used < 1.0) return false;
  if (accel) {
    cv->accel = std::sqrt(s / used);
    cv->accel_sigma = std::sqrt(w / used);
    cv->accel_unpredictable = unpredictable;
    if (accel_residuals) *accel_residuals = ar;
  } else {
    cv->gyro = std::sqrt(s / (3.0 * used));
    cv->gyro_sigma = std::sqrt(w / (3.0 * used));
    cv->gyro_unpredictable = unpredictable;
    if (gyro_residuals) *gyro_residuals = gr;
  }
  return true;
}

bool Assess(const DiscoveryContext& ctx, const std::vector<Effect>& effects,
            const EffectFitResult& start, const std::vector<EffectSensor>& validate,
            const ModelAssessment* previous, ModelAssessment* out) {
  out->parameterization = ctx.parameterization;
  out->effects = effects;
  if (!FitDiscoveryModel(ctx, *ctx.observations, effects, start, true, true, true, &out->fit))
    return false;
  out->gap = InSampleGap(out->fit, ctx.has_gyro);
  if (previous != nullptr) {
    out->cv_gap = previous->cv_gap;
    out->cv_accel_residuals = previous->cv_accel_residuals;
    out->cv_gyro_residuals = previous->cv_gyro_residuals;
  }
  for (EffectSensor s : validate) {
    if (s == EffectSensor::kGyroscope && !ctx.has_gyro) continue;
    if (!CrossValidate(ctx, effects, out->fit, s, &out->cv_gap, &out->cv_accel_residuals,
                       &out->cv_gyro_residuals)) {
      out->cv_gap.accel = out->cv_gap.accel_sigma = NAN;
    }
  }
  return true;
}

}  // namespace internal
}  // namespace gravcal
