#include "workflows/discovery_step.h"

#include <algorithm>
#include <string>

#include "workflows/discovery_cross_validation.h"

namespace gravcal {
namespace internal {
namespace {

std::string Advice(Effect a, Effect b) {
  const EffectRegressor ra = Info(a).regressor;
  const EffectRegressor rb = Info(b).regressor;
  auto is = [&](EffectRegressor x, EffectRegressor y) {
    return (ra == x && rb == y) || (ra == y && rb == x);
  };
  if (is(EffectRegressor::kTemperature, EffectRegressor::kTime)) {
    return "temperature and time rose together in this session (a monotonic warm-up), so an "
           "effect of temperature and a drift in time explain the data equally: record a "
           "cool-down after the warm-up (or a warm-up and cool-down in one session), or repeat "
           "the poses while the temperature is held constant";
  }
  if (ra == rb && ra == EffectRegressor::kTemperature) {
    return "with these poses a temperature-dependent bias and scale factor look alike: repeat "
           "each axis up and down at several temperatures";
  }
  if (ra == rb && ra == EffectRegressor::kOrientation) {
    return "the poses do not separate these two orientation patterns: add poses between the "
           "axes (45-degree tilts about each axis) and with each axis up and down";
  }
  return std::string("record a session in which what ") + Info(a).name + " and " + Info(b).name +
         " depend on vary independently";
}

// Residuals per position of one sensor (accelerometer in component 0).
std::vector<Eigen::Vector3d> Residuals(const EffectFitResult& fit, bool accel) {
  std::vector<Eigen::Vector3d> r;
  const size_t n = fit.accel_residuals.size();
  for (size_t k = 0; k < n; ++k) {
    if (accel) {
      r.push_back(Eigen::Vector3d(fit.accel_residuals[k], 0.0, 0.0));
    } else {
      r.push_back(k < fit.gyro_residuals.size() ? fit.gyro_residuals[k]
                                                : Eigen::Vector3d::Constant(NAN));
    }
  }
  return r;
}

// The plots' x values: the effect's regressor (temperature, time) and the
// fitted effect's own contribution to each position's residual (for the
// accelerometer the change of |a| - g it makes, in component 0; for the
// gyroscope its offset per axis). Orientation effects have no scalar
// regressor: their contribution is it (its norm for the gyroscope).
void FillRegressor(const DiscoveryContext& ctx, const EffectFitResult& with, Effect e,
                   DiscoveryStep* step) {
  const std::vector<StaticObservation>& obs = *ctx.observations;
  const EffectInfo& info = Info(e);
  EffectFitResult without = with;
  if (Info(e).form == EffectForm::kInUpper) {
    without.accel.upper(0, 1) = without.accel.upper(0, 2) = without.accel.upper(1, 2) = 0.0;
  }
  without.effects.erase(std::remove(without.effects.begin(), without.effects.end(), e),
                        without.effects.end());
  step->regressor.clear();
  step->contribution.clear();
  for (size_t k = 0; k < obs.size(); ++k) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    if (info.sensor == EffectSensor::kAccelerometer) {
      c(0) = AccelResidual(without, obs[k], ctx.gravity, nullptr) -
             AccelResidual(with, obs[k], ctx.gravity, nullptr);
    } else {
      c = GyroOffset(with.parameters, {e}, with.forces[k], obs[k].temperature(), obs[k].time());
    }
    step->contribution.push_back(c);
    switch (info.regressor) {
      case EffectRegressor::kTemperature:
        step->regressor.push_back(obs[k].temperature());
        break;
      case EffectRegressor::kTime:
        step->regressor.push_back(obs[k].time());
        break;
      case EffectRegressor::kOrientation:
        step->regressor.push_back(info.sensor == EffectSensor::kAccelerometer ? c(0) : c.norm());
        break;
    }
  }
  switch (info.regressor) {
    case EffectRegressor::kTemperature:
      step->regressor_name = "temperature, degC";
      break;
    case EffectRegressor::kTime:
      step->regressor_name = "time, s";
      break;
    case EffectRegressor::kOrientation:
      step->regressor_name = std::string("fitted ") + info.name + " contribution";
      break;
  }
}

// The effects of the same sensor whose delta BIC is within ambiguity_bic of
// the chosen one's: step->ambiguous_with, and an Ambiguity with advice.
void NoteAmbiguity(const DiscoveryOptions& options, const std::vector<CandidateScore>& scores,
                   const CandidateScore& chosen, int step_index, DiscoveryStep* s,
                   std::vector<Ambiguity>* ambiguous) {
  const bool accel = IsAccel(chosen.effect);
  for (const CandidateScore& c : scores) {
    if (&c == &chosen || !c.significant || IsAccel(c.effect) != accel) continue;
    if (c.delta_bic - chosen.delta_bic < options.ambiguity_bic) {
      s->ambiguous_with.push_back(c.effect);
    }
  }
  if (s->ambiguous_with.empty()) return;
  Ambiguity a;
  a.step = step_index;
  a.effects.push_back(chosen.effect);
  a.delta_bic.push_back(chosen.delta_bic);
  for (Effect e : s->ambiguous_with) {
    a.effects.push_back(e);
    for (const CandidateScore& c : scores) {
      if (c.effect == e) a.delta_bic.push_back(c.delta_bic);
    }
  }
  a.advice = Advice(chosen.effect, s->ambiguous_with.front());
  ambiguous->push_back(a);
}

}  // namespace

bool TakeStep(const DiscoveryContext& ctx, const DiscoveryOptions& options,
              const std::vector<CandidateScore>& scores, int best, const EffectFitResult& best_fit,
              const Disagreement& where, ModelAssessment* current, DiscoveryResult* result) {
  const CandidateScore& chosen = scores[best];
  DiscoveryStep s;
  s.effect = chosen.effect;
  s.p_value = chosen.p_value;
  s.delta_bic = chosen.delta_bic;
  s.dof = chosen.dof;
  s.information = chosen.information;
  s.confirmed_by = chosen.confirmed_by;
  s.where = where;
  s.candidates = scores;
  s.gap_before = current->gap;
  s.cv_gap_before = current->cv_gap;
  NoteAmbiguity(options, scores, chosen, static_cast<int>(result->steps.size()), &s,
                &result->ambiguous);
  const bool accel = IsAccel(chosen.effect);
  std::vector<Effect> extended = current->effects;
  extended.push_back(chosen.effect);
  ModelAssessment next;
  if (!Assess(ctx, extended, best_fit, {Info(chosen.effect).sensor}, current, &next)) {
    result->message =
        "refit with " + std::string(ToString(chosen.effect)) + ": " + next.fit.message;
    return false;
  }
  s.gap_after = next.gap;
  s.cv_gap_after = next.cv_gap;
  for (const EffectEstimate& e : next.fit.estimates) {
    if (e.effect == chosen.effect) s.estimate = e;
  }
  FillRegressor(ctx, next.fit, chosen.effect, &s);
  s.residual_before = Residuals(current->fit, accel);
  s.residual_after = Residuals(next.fit, accel);
  *current = next;
  result->steps.push_back(s);
  return true;
}

}  // namespace internal
}  // namespace gravcal
