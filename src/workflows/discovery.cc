#include "gravcal/workflows/discovery.h"

#include <glog/logging.h>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <numeric>
#include <sstream>

#include "util/statistics.h"

namespace gravcal {
namespace {

bool IsAccel(Effect e) { return Info(e).sensor == EffectSensor::kAccelerometer; }

// Leverage above which a position counts as not predictable by the others.
constexpr double kMaxLeverage = 0.99;

// What every fit in one discovery run shares.
struct Context {
  const std::vector<StaticObservation>* observations = nullptr;
  double gravity = kStandardGravity;
  AccelParameterization parameterization = AccelParameterization::kScaleMisalignment;
  bool has_gyro = false;
  bool has_temperature = false;
  double temperature_range = 0.0;
};

std::string Format(const char* format, double v) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, v);
  return buffer;
}

bool Fit(const Context& ctx, const std::vector<StaticObservation>& observations,
         const std::vector<Effect>& effects, const EffectFitResult& start, bool fit_accel,
         bool fit_gyro, bool covariance, EffectFitResult* out) {
  EffectFitOptions o;
  o.parameterization = ctx.parameterization;
  o.effects = effects;
  o.fit_accel = fit_accel;
  o.fit_gyro = fit_gyro && ctx.has_gyro;
  o.compute_covariance = covariance;
  return FitEffects(observations, start.accel, start.gyro, start.parameters, ctx.gravity, o, out);
}

// rms of the residuals in physical units and in sigma, from a full fit.
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

// Leave-one-position-out prediction of one sensor under `effects`, starting
// every fold from the full fit. Fills the cross-validated gap of that sensor
// and the left-out residuals; false when a fold cannot be fitted.
bool CrossValidate(const Context& ctx, const std::vector<Effect>& effects,
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
    if (!Fit(ctx, subset, effects, full, accel, !accel, false, &fold)) return false;
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

// Fits `effects` fully (both sensors, covariance) and cross-validates the
// sensors in `validate`; the other sensor's cross-validation is copied from
// `previous` (its model did not change).
bool Assess(const Context& ctx, const std::vector<Effect>& effects, const EffectFitResult& start,
            const std::vector<EffectSensor>& validate, const ModelAssessment* previous,
            ModelAssessment* out) {
  out->parameterization = ctx.parameterization;
  out->effects = effects;
  if (!Fit(ctx, *ctx.observations, effects, start, true, true, true, &out->fit)) return false;
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

// The raw reading the model predicts for position k: the vector along the
// measured direction whose corrected magnitude is g, mapped back through
// the effects and U.
Eigen::Vector3d SimulatedAccel(const EffectFitResult& fit, const StaticObservation& o,
                               const Eigen::Vector3d& force, double gravity) {
  const Eigen::Vector3d s = gravity * force.normalized();
  EffectParameters p;
  p.reference_temperature = fit.parameters.reference_temperature;
  p.reference_time = fit.parameters.reference_time;
  for (Effect e : fit.effects) {
    if (e == Effect::kAccelQuadratic) p.accel_quadratic = fit.parameters.accel_quadratic;
    if (e == Effect::kAccelTemperatureBias) {
      p.accel_temperature_bias = fit.parameters.accel_temperature_bias;
    }
    if (e == Effect::kAccelTemperatureScale) {
      p.accel_temperature_scale = fit.parameters.accel_temperature_scale;
    }
    if (e == Effect::kAccelBiasDrift) p.accel_bias_drift = fit.parameters.accel_bias_drift;
  }
  const Eigen::Vector3d m = ApplyAccelEffects(p, s, o.temperature(), o.time());
  return fit.accel.upper.inverse() * m + fit.accel.bias;
}

// Adds the group of the positions k for which in(k) holds, unless empty.
void AddGroup(const std::string& by, const std::string& name,
              const std::vector<PositionDisagreement>& p, bool has_gyro,
              const std::function<bool(size_t)>& in, std::vector<GroupDisagreement>* groups) {
  GroupDisagreement g;
  g.by = by;
  g.group = name;
  double sa = 0.0, sg = 0.0;
  for (size_t k = 0; k < p.size(); ++k) {
    if (!in(k)) continue;
    ++g.count;
    sa += p[k].accel_z * p[k].accel_z;
    sg += p[k].gyro_z.squaredNorm();
  }
  if (g.count == 0) return;
  g.accel_sigma = std::sqrt(sa / g.count);
  if (has_gyro) g.gyro_sigma = std::sqrt(sg / (3.0 * g.count));
  groups->push_back(g);
}

// Groups positions into `bins` equal stretches of a value.
void AddBinnedGroups(const std::string& by, const std::string& unit, const char* format,
                     const std::vector<double>& value, const std::vector<PositionDisagreement>& p,
                     bool has_gyro, int bins, std::vector<GroupDisagreement>* groups) {
  const double lo = *std::min_element(value.begin(), value.end());
  const double hi = *std::max_element(value.begin(), value.end());
  if (!(hi > lo)) return;
  for (int b = 0; b < bins; ++b) {
    const double from = lo + (hi - lo) * b / bins;
    const double to = lo + (hi - lo) * (b + 1) / bins;
    AddGroup(
        by, Format(format, from) + " to " + Format(format, to) + " " + unit, p, has_gyro,
        [&](size_t k) { return value[k] >= from && (value[k] < to || b == bins - 1); }, groups);
  }
}

Disagreement Locate(const Context& ctx, const EffectFitResult& fit, int where_count) {
  const std::vector<StaticObservation>& obs = *ctx.observations;
  Disagreement d;
  const int n = static_cast<int>(obs.size());
  static const char* kAxis[6] = {"+x", "-x", "+y", "-y", "+z", "-z"};
  for (int k = 0; k < n; ++k) {
    PositionDisagreement p;
    p.index = k;
    p.time = obs[k].time();
    p.temperature = obs[k].temperature();
    const Eigen::Vector3d& a = fit.forces[k];
    int axis = 0;
    a.cwiseAbs().maxCoeff(&axis);
    p.axis = kAxis[2 * axis + (a(axis) < 0.0 ? 1 : 0)];
    p.axis_level = std::fabs(a(axis)) / std::max(a.norm(), 1e-300);
    p.accel_measured = obs[k].accel.raw_mean;
    p.accel_simulated = SimulatedAccel(fit, obs[k], a, ctx.gravity);
    p.accel_residual = fit.accel_residuals[k];
    p.accel_z = p.accel_residual / fit.accel_sigmas[k];
    d.accel_chi2 += p.accel_z * p.accel_z;
    if (ctx.has_gyro && fit.gyro_residuals.size() == obs.size()) {
      p.gyro_measured = obs[k].gyro_mean;
      p.gyro_residual = fit.gyro_residuals[k];
      p.gyro_simulated = p.gyro_measured - p.gyro_residual;
      p.gyro_z = p.gyro_residual.cwiseQuotient(fit.gyro_sigmas[k]);
    }
    d.positions.push_back(p);
  }
  d.accel_dof = fit.accel_fit.dof();
  d.accel_p = ChiSquareUpperTail(d.accel_chi2, d.accel_dof);
  if (ctx.has_gyro && fit.gyro_fit.fitted) {
    d.gyro_chi2 = fit.gyro_fit.chi2;
    d.gyro_dof = fit.gyro_fit.dof();
    d.gyro_p = ChiSquareUpperTail(d.gyro_chi2, d.gyro_dof);
  }

  // Worst positions per sensor.
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return std::fabs(d.positions[a].accel_z) > std::fabs(d.positions[b].accel_z);
  });
  d.worst_accel.assign(order.begin(), order.begin() + std::min(n, where_count));
  if (ctx.has_gyro) {
    std::sort(order.begin(), order.end(), [&](int a, int b) {
      return d.positions[a].gyro_z.squaredNorm() > d.positions[b].gyro_z.squaredNorm();
    });
    d.worst_gyro.assign(order.begin(), order.begin() + std::min(n, where_count));
  }

  // Groups: dominant axis, specific-force level on it, time, temperature.
  for (const char* axis : kAxis) {
    AddGroup(
        "axis", axis, d.positions, ctx.has_gyro,
        [&](size_t k) { return d.positions[k].axis == axis; }, &d.groups);
  }
  AddGroup(
      "force_level", "axis-aligned (over 0.9 g on one axis)", d.positions, ctx.has_gyro,
      [&](size_t k) { return d.positions[k].axis_level > 0.9; }, &d.groups);
  AddGroup(
      "force_level", "between axes (0.9 g or less)", d.positions, ctx.has_gyro,
      [&](size_t k) { return d.positions[k].axis_level <= 0.9; }, &d.groups);
  std::vector<double> times, temperatures;
  for (const PositionDisagreement& p : d.positions) {
    times.push_back(p.time);
    temperatures.push_back(p.temperature);
  }
  AddBinnedGroups("time", "s", "%.0f", times, d.positions, ctx.has_gyro, 3, &d.groups);
  if (ctx.has_temperature) {
    AddBinnedGroups("temperature", "degC", "%.1f", temperatures, d.positions, ctx.has_gyro, 3,
                    &d.groups);
  }

  std::ostringstream s;
  s.precision(3);
  s << "accelerometer |a| - g: " << std::sqrt(d.accel_chi2 / std::max(n, 1)) << " sigma rms (chi2 "
    << d.accel_chi2 << " on " << d.accel_dof << " dof, p = " << d.accel_p << ")";
  if (!d.worst_accel.empty()) {
    const PositionDisagreement& w = d.positions[d.worst_accel[0]];
    s << ", worst position " << w.index << " (" << w.axis << " up, t = " << w.time << " s, "
      << w.accel_z << " sigma)";
  }
  if (ctx.has_gyro && !d.worst_gyro.empty()) {
    const PositionDisagreement& w = d.positions[d.worst_gyro[0]];
    int axis = 0;
    w.gyro_z.cwiseAbs().maxCoeff(&axis);
    s << "; gyroscope: " << std::sqrt(d.gyro_chi2 / std::max(3 * n, 1)) << " sigma rms (chi2 "
      << d.gyro_chi2 << " on " << d.gyro_dof << " dof, p = " << d.gyro_p << "), worst position "
      << w.index << " (gyro "
      << "xyz"[axis] << " " << w.gyro_z(axis) << " sigma, t = " << w.time << " s)";
  }
  d.summary = s.str();
  return d;
}

// Why an effect cannot be tried in this session, or "".
std::string NotApplicable(const Context& ctx, const std::vector<Effect>& current, Effect e,
                          const DiscoveryOptions& options, int sensor_residuals,
                          int sensor_parameters) {
  const EffectInfo& info = Info(e);
  if (Contains(current, e)) return "already in the model";
  if (e == Effect::kAccelMisalignment && ctx.parameterization != AccelParameterization::kScale) {
    return "already in the baseline (parameterization " +
           std::string(ToString(ctx.parameterization)) + ")";
  }
  if (info.sensor == EffectSensor::kGyroscope && !ctx.has_gyro) {
    return "the log has no gyroscope";
  }
  if (info.regressor == EffectRegressor::kTemperature) {
    if (!ctx.has_temperature) return "the log has no temperature";
    if (ctx.temperature_range < options.min_temperature_range) {
      return "the positions span only " + Format("%.2f", ctx.temperature_range) + " degC (needs " +
             Format("%.2f", options.min_temperature_range) +
             "): record while the temperature changes";
    }
  }
  const int per_position = info.sensor == EffectSensor::kGyroscope ? 3 : 1;
  const int dof = sensor_residuals - sensor_parameters - info.num_parameters;
  if (dof < options.min_dof || dof - per_position < 1) {
    std::ostringstream s;
    s << "too few positions: " << sensor_residuals / per_position << " positions give "
      << sensor_residuals << " residuals for " << sensor_parameters << " + " << info.num_parameters
      << " parameters (needs " << options.min_dof
      << " left over, and one in every leave-one-out fold); record more poses"
      << (IsAccel(e) && ctx.parameterization != AccelParameterization::kScale
              ? " or use parameterization: scale"
              : "");
    return s.str();
  }
  return "";
}

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
void FillRegressor(const Context& ctx, const EffectFitResult& with, Effect e, DiscoveryStep* step) {
  const std::vector<StaticObservation>& obs = *ctx.observations;
  const EffectInfo& info = Info(e);
  EffectFitResult without = with;
  if (e == Effect::kAccelMisalignment) {
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

// The likelihood-ratio p-value and delta BIC of every candidate tried.
// The noise scale: when the current model extended by all candidates of a
// sensor at once fits that sensor's data to its own noise (chi2 test, p >=
// 0.01), the per-position sigmas are right and each candidate is tested
// against them (chi-square); otherwise the data show noise (or an effect)
// beyond the catalogue, and each candidate's statistic is divided by the
// dispersion phi = chi2 / dof its extended model leaves, and referred to
// F(p, dof). (Dividing by each candidate's own phi alone would count the
// other missing effects as noise: two effects hidden together could then
// both go unnamed.)
void ScoreCandidates(const Context& ctx, const ModelAssessment& current,
                     const std::vector<EffectFitResult>& fits, double log_n,
                     std::vector<CandidateScore>* scores) {
  for (EffectSensor sensor : {EffectSensor::kAccelerometer, EffectSensor::kGyroscope}) {
    const bool accel = sensor == EffectSensor::kAccelerometer;
    std::vector<Effect> all = current.effects;
    int count = 0;
    int last = -1;
    for (size_t i = 0; i < scores->size(); ++i) {
      if ((*scores)[i].tried && IsAccel((*scores)[i].effect) == accel) {
        all.push_back((*scores)[i].effect);
        ++count;
        last = static_cast<int>(i);
      }
    }
    if (count == 0) continue;
    bool noise_fits = false;
    EffectFitResult joint;
    const EffectFitResult* richest = &fits[last];
    if (count == 1 || Fit(ctx, *ctx.observations, all, current.fit, accel, !accel, true, &joint)) {
      if (count > 1) richest = &joint;
      const SensorFitSummary& f = accel ? richest->accel_fit : richest->gyro_fit;
      const int dof = f.num_residuals - f.rank;
      noise_fits = dof >= 1 && ChiSquareUpperTail(f.chi2, dof) >= 0.01;
    }
    for (size_t i = 0; i < scores->size(); ++i) {
      CandidateScore& c = (*scores)[i];
      if (!c.tried || IsAccel(c.effect) != accel) continue;
      const SensorFitSummary& ext = accel ? fits[i].accel_fit : fits[i].gyro_fit;
      const int dof1 = ext.dof();
      c.dispersion = noise_fits || dof1 <= 0 ? 1.0 : std::max(1.0, ext.chi2 / dof1);
      if (!(c.delta_chi2 > 0.0)) {
        c.p_value = 1.0;
      } else if (c.dispersion > 1.0) {
        c.p_value = FUpperTail(c.delta_chi2 / c.dof / c.dispersion, c.dof, dof1);
      } else {
        c.p_value = ChiSquareUpperTail(c.delta_chi2, c.dof);
      }
      c.delta_bic = -c.delta_chi2 / c.dispersion + c.dof * log_n;
    }
  }
}

// When no candidate is significant on its own but some pass the likelihood
// ratio and BIC and fail only the cross-validation, two effects may be
// masking each other: each alone leaves the other's large residual, which
// dominates the left-out predictions. Tries those candidates in pairs of
// the same sensor: a pair counts when together they lower the
// cross-validated gap and each adds significantly (chi2 test at `alpha`)
// on top of the other. The member of the best such pair (lowest
// cross-validated gap) with the lower delta BIC alone is named; the index
// of its score, or -1.
int PairLookAhead(const Context& ctx, const ModelAssessment& current, double alpha,
                  const DiscoveryOptions& options, std::vector<CandidateScore>* scores) {
  std::vector<int> masked;
  for (size_t i = 0; i < scores->size(); ++i) {
    const CandidateScore& c = (*scores)[i];
    if (c.tried && c.p_value < alpha && c.delta_bic < -options.min_bic_gain) {
      masked.push_back(static_cast<int>(i));
    }
  }
  int best = -1;
  double best_cv = INFINITY;
  std::string partner;
  for (size_t a = 0; a < masked.size(); ++a) {
    for (size_t b = a + 1; b < masked.size(); ++b) {
      CandidateScore& ca = (*scores)[masked[a]];
      CandidateScore& cb = (*scores)[masked[b]];
      const bool accel = IsAccel(ca.effect);
      if (IsAccel(cb.effect) != accel) continue;
      std::vector<Effect> pair = current.effects;
      pair.push_back(ca.effect);
      pair.push_back(cb.effect);
      EffectFitResult fit;
      if (!Fit(ctx, *ctx.observations, pair, current.fit, accel, !accel, true, &fit)) continue;
      const SensorFitSummary& now = accel ? current.fit.accel_fit : current.fit.gyro_fit;
      const double chi2 = accel ? fit.accel_fit.chi2 : fit.gyro_fit.chi2;
      // chi2 with only A = chi2_now - delta_chi2_A; B adds that minus chi2.
      const double adds_b = now.chi2 - ca.delta_chi2 - chi2;
      const double adds_a = now.chi2 - cb.delta_chi2 - chi2;
      if (!(ChiSquareUpperTail(adds_b, cb.dof) < alpha) ||
          !(ChiSquareUpperTail(adds_a, ca.dof) < alpha)) {
        continue;
      }
      Gap cv = current.cv_gap;
      if (!CrossValidate(ctx, pair, fit, Info(ca.effect).sensor, &cv, nullptr, nullptr)) continue;
      const double before = accel ? current.cv_gap.accel_sigma : current.cv_gap.gyro_sigma;
      const double after = accel ? cv.accel_sigma : cv.gyro_sigma;
      if (!(after < before) || !(after < best_cv)) continue;
      best_cv = after;
      const bool a_first = ca.delta_bic <= cb.delta_bic;
      best = a_first ? masked[a] : masked[b];
      partner = ToString(a_first ? cb.effect : ca.effect);
    }
  }
  if (best >= 0) {
    CandidateScore& c = (*scores)[best];
    c.significant = true;
    std::ostringstream why;
    why.precision(3);
    why << "significant together with " << partner << " (cross-validated gap " << best_cv
        << " sigma with both); alone: " << c.reason;
    c.reason = why.str();
  }
  return best;
}

}  // namespace

bool DiscoveryOptions::IsValid(std::string* error) const {
  if (!(significance > 0.0 && significance < 1.0)) {
    *error = "discovery_significance: must be between 0 and 1";
    return false;
  }
  if (!(min_bic_gain >= 0.0)) {
    *error = "discovery_min_bic_gain: must be zero or positive";
    return false;
  }
  if (!(ambiguity_bic >= 0.0)) {
    *error = "discovery_ambiguity_bic: must be zero or positive";
    return false;
  }
  if (max_steps < 0) {
    *error = "discovery_max_steps: must be zero or positive";
    return false;
  }
  if (min_dof < 1) {
    *error = "discovery_min_dof: must be at least 1";
    return false;
  }
  if (!(min_temperature_range >= 0.0)) {
    *error = "discovery_min_temperature_range: must be zero or positive";
    return false;
  }
  if (where_count < 1) {
    *error = "discovery where_count: must be at least 1";
    return false;
  }
  return true;
}

std::vector<Effect> DiscoveryResult::named() const {
  std::vector<Effect> out;
  for (const DiscoveryStep& s : steps) out.push_back(s.effect);
  return out;
}

bool DiscoverFromObservations(const std::vector<StaticObservation>& observations,
                              const CalibrationOptions& calibration,
                              const std::vector<Effect>& baseline_effects,
                              const DiscoveryOptions& options, DiscoveryResult* result) {
  CHECK(result != nullptr);
  const auto start_time = std::chrono::steady_clock::now();
  const std::string source = result->source;
  *result = DiscoveryResult();
  result->source = source;
  DiscoveryResult& r = *result;
  std::string error;
  if (!options.IsValid(&error) || !calibration.IsValid(&error)) {
    r.message = error;
    return false;
  }
  r.observations = observations;
  const int n = static_cast<int>(observations.size());

  // Starting model: the configured calibration (coarse fit and refinement).
  std::vector<Position> positions;
  for (const StaticObservation& o : observations) positions.push_back(o.accel);
  CalibrationOptions start_options = calibration;
  start_options.allow_undetermined = true;
  start_options.refinement.compute_covariance = false;
  Calibration start;
  if (!CalibrateFromPositions(positions, start_options, &start) && !start.not_converged) {
    r.message = start.message;
    return false;
  }
  r.gravity = start.gravity;
  r.gravity_source = start.gravity_source;
  for (const std::string& w : start.warnings) {
    if (w.find("standard gravity") != std::string::npos) r.warnings.push_back(w);
  }

  Context ctx;
  ctx.observations = &r.observations;
  ctx.gravity = r.gravity;
  ctx.parameterization = calibration.refinement.parameterization == AccelParameterization::kScale
                             ? AccelParameterization::kScale
                             : AccelParameterization::kScaleMisalignment;
  ctx.has_gyro = n > 0 && std::all_of(observations.begin(), observations.end(),
                                      [](const StaticObservation& o) { return o.has_gyro; });
  ctx.has_temperature = n > 0 && std::all_of(observations.begin(), observations.end(),
                                             [](const StaticObservation& o) {
                                               return std::isfinite(o.temperature());
                                             });
  EffectFitResult seed;
  seed.accel = start.accel.model;
  double t_sum = 0.0, temperature_sum = 0.0;
  double t_lo = INFINITY, t_hi = -INFINITY;
  Eigen::Vector3d gyro_sum = Eigen::Vector3d::Zero();
  for (const StaticObservation& o : observations) {
    t_sum += o.time();
    if (ctx.has_temperature) {
      temperature_sum += o.temperature();
      t_lo = std::min(t_lo, o.temperature());
      t_hi = std::max(t_hi, o.temperature());
    }
    gyro_sum += o.gyro_mean;
  }
  seed.parameters.reference_time = n > 0 ? t_sum / n : 0.0;
  seed.parameters.reference_temperature = ctx.has_temperature ? temperature_sum / n : 0.0;
  ctx.temperature_range = ctx.has_temperature ? t_hi - t_lo : 0.0;
  seed.gyro.bias = n > 0 ? Eigen::Vector3d(gyro_sum / n) : Eigen::Vector3d::Zero();

  const std::vector<EffectSensor> both = {EffectSensor::kAccelerometer, EffectSensor::kGyroscope};
  if (!Assess(ctx, baseline_effects, seed, both, nullptr, &r.baseline)) {
    r.message = "baseline fit: " + r.baseline.fit.message;
    return false;
  }
  for (const std::string& w : r.baseline.fit.warnings) r.warnings.push_back(w);
  if (!r.baseline.fit.accel_fit.undetermined.empty()) {
    std::string names;
    for (const std::string& u : r.baseline.fit.accel_fit.undetermined) {
      names += (names.empty() ? "" : ", ") + u;
    }
    r.warnings.push_back("the positions do not determine " + names +
                         " of the baseline: its gaps are still meaningful, its parameters not");
  }
  r.baseline_where = Locate(ctx, r.baseline.fit, options.where_count);

  std::vector<Effect> candidates = options.candidates;
  if (candidates.empty()) {
    for (const EffectInfo& info : EffectCatalogue()) candidates.push_back(info.effect);
  }
  const double log_n = std::log(static_cast<double>(r.baseline.fit.accel_fit.num_residuals +
                                                    r.baseline.fit.gyro_fit.num_residuals));

  ModelAssessment current = r.baseline;
  Disagreement where = r.baseline_where;
  bool stopped_by_limit = false;
  std::vector<std::string> untestable_warned;
  for (int step = 0;; ++step) {
    if (step >= options.max_steps) {
      stopped_by_limit = true;
      break;
    }
    std::vector<CandidateScore> scores;
    std::vector<EffectFitResult> fits;
    for (Effect e : candidates) {
      CandidateScore c;
      c.effect = e;
      const bool accel = IsAccel(e);
      const SensorFitSummary& now = accel ? current.fit.accel_fit : current.fit.gyro_fit;
      c.reason =
          NotApplicable(ctx, current.effects, e, options, now.num_residuals, now.num_parameters);
      if (!c.reason.empty()) {
        // Warn once per effect; "already in the model / baseline" is no news.
        if (c.reason.rfind("already", 0) != 0 &&
            std::find(untestable_warned.begin(), untestable_warned.end(), Info(e).name) ==
                untestable_warned.end()) {
          untestable_warned.push_back(Info(e).name);
          r.warnings.push_back(std::string(Info(e).name) +
                               " cannot be tested in this session: " + c.reason);
        }
        scores.push_back(c);
        fits.emplace_back();
        continue;
      }
      std::vector<Effect> extended = current.effects;
      extended.push_back(e);
      EffectFitResult fit;
      if (!Fit(ctx, *ctx.observations, extended, current.fit, accel, !accel, true, &fit)) {
        c.reason = "the extended fit failed: " + fit.message;
        scores.push_back(c);
        fits.emplace_back();
        continue;
      }
      const SensorFitSummary& ext = accel ? fit.accel_fit : fit.gyro_fit;
      std::string undetermined;
      for (const std::string& name : Info(e).parameter_names) {
        if (std::find(ext.undetermined.begin(), ext.undetermined.end(), name) !=
            ext.undetermined.end()) {
          undetermined += (undetermined.empty() ? "" : ", ") + name;
        }
      }
      if (!undetermined.empty()) {
        c.reason = "cannot be identified in this session (" + undetermined +
                   " not determined by the positions)";
        if (std::find(untestable_warned.begin(), untestable_warned.end(), Info(e).name) ==
            untestable_warned.end()) {
          untestable_warned.push_back(Info(e).name);
          r.warnings.push_back(std::string(Info(e).name) + ": " + c.reason);
        }
        scores.push_back(c);
        fits.emplace_back();
        continue;
      }
      c.tried = true;
      c.dof = Info(e).num_parameters;
      c.delta_chi2 = now.chi2 - ext.chi2;
      c.gap = InSampleGap(fit, ctx.has_gyro);
      // The other sensor's part was not refitted: its gap is the current one.
      if (accel) {
        c.gap.gyro = current.gap.gyro;
        c.gap.gyro_sigma = current.gap.gyro_sigma;
      } else {
        c.gap.accel = current.gap.accel;
        c.gap.accel_sigma = current.gap.accel_sigma;
      }
      c.cv_gap = current.cv_gap;
      if (!CrossValidate(ctx, extended, fit, Info(e).sensor, &c.cv_gap, nullptr, nullptr)) {
        c.reason = "cross-validation failed (a fold could not be fitted)";
        c.tried = false;
      }
      scores.push_back(c);
      fits.push_back(fit);
    }
    ScoreCandidates(ctx, current, fits, log_n, &scores);
    int tried = 0;
    for (const CandidateScore& c : scores) tried += c.tried ? 1 : 0;
    const double alpha = options.significance / std::max(1, tried);
    int best = -1;
    for (size_t i = 0; i < scores.size(); ++i) {
      CandidateScore& c = scores[i];
      if (!c.tried) continue;
      const bool accel = IsAccel(c.effect);
      const double before = accel ? current.cv_gap.accel_sigma : current.cv_gap.gyro_sigma;
      const double after = accel ? c.cv_gap.accel_sigma : c.cv_gap.gyro_sigma;
      std::ostringstream why;
      why.precision(3);
      if (!(c.p_value < alpha)) why << "p = " << c.p_value << " not below " << alpha << "; ";
      if (!(c.delta_bic < -options.min_bic_gain)) {
        why << "delta BIC = " << c.delta_bic << " not below " << -options.min_bic_gain << "; ";
      }
      if (!(after < before)) {
        why << "cross-validated gap " << after << " sigma not below " << before << "; ";
      }
      c.reason = why.str();
      if (!c.reason.empty()) c.reason.resize(c.reason.size() - 2);
      c.significant = c.reason.empty();
      if (c.significant && (best < 0 || c.delta_bic < scores[best].delta_bic)) {
        best = static_cast<int>(i);
      }
    }
    if (best < 0) best = PairLookAhead(ctx, current, alpha, options, &scores);
    if (best < 0) {
      r.final_candidates = scores;
      break;
    }

    const CandidateScore& chosen = scores[best];
    DiscoveryStep s;
    s.effect = chosen.effect;
    s.p_value = chosen.p_value;
    s.delta_bic = chosen.delta_bic;
    s.dof = chosen.dof;
    s.where = where;
    s.candidates = scores;
    s.gap_before = current.gap;
    s.cv_gap_before = current.cv_gap;
    const bool accel = IsAccel(chosen.effect);
    for (const CandidateScore& c : scores) {
      if (&c == &chosen || !c.significant || IsAccel(c.effect) != accel) continue;
      if (c.delta_bic - chosen.delta_bic < options.ambiguity_bic) {
        s.ambiguous_with.push_back(c.effect);
      }
    }
    if (!s.ambiguous_with.empty()) {
      Ambiguity a;
      a.step = static_cast<int>(r.steps.size());
      a.effects.push_back(chosen.effect);
      a.delta_bic.push_back(chosen.delta_bic);
      for (Effect e : s.ambiguous_with) {
        a.effects.push_back(e);
        for (const CandidateScore& c : scores) {
          if (c.effect == e) a.delta_bic.push_back(c.delta_bic);
        }
      }
      a.advice = Advice(chosen.effect, s.ambiguous_with.front());
      r.ambiguous.push_back(a);
    }

    std::vector<Effect> extended = current.effects;
    extended.push_back(chosen.effect);
    ModelAssessment next;
    if (!Assess(ctx, extended, fits[best], {Info(chosen.effect).sensor}, &current, &next)) {
      r.message = "refit with " + std::string(ToString(chosen.effect)) + ": " + next.fit.message;
      return false;
    }
    s.gap_after = next.gap;
    s.cv_gap_after = next.cv_gap;
    for (const EffectEstimate& e : next.fit.estimates) {
      if (e.effect == chosen.effect) s.estimate = e;
    }
    FillRegressor(ctx, next.fit, chosen.effect, &s);
    s.residual_before = Residuals(current.fit, accel);
    s.residual_after = Residuals(next.fit, accel);
    current = next;
    where = Locate(ctx, current.fit, options.where_count);
    r.steps.push_back(s);
  }
  r.final_model = current;
  r.final_where = where;

  // Verdict.
  std::ostringstream v;
  if (r.steps.empty()) {
    v << "no significant missing effect";
  } else {
    v << "missing effect" << (r.steps.size() > 1 ? "s" : "") << " found: ";
    for (size_t i = 0; i < r.steps.size(); ++i) {
      v << (i ? ", " : "") << ToString(r.steps[i].effect);
      if (!r.steps[i].ambiguous_with.empty()) {
        v << " (or " << ToString(r.steps[i].ambiguous_with.front())
          << ": this session cannot tell them apart)";
      }
    }
    v << (stopped_by_limit ? "; stopped at discovery_max_steps"
                           : "; no further candidate is significant");
  }
  r.verdict = v.str();
  const double phi_a = r.final_model.fit.accel_fit.dof() > 0
                           ? r.final_model.fit.accel_fit.chi2 / r.final_model.fit.accel_fit.dof()
                           : 1.0;
  if (r.final_where.accel_p < 1e-3) {
    r.warnings.push_back(
        "the final model still leaves accelerometer residuals " + Format("%.3g", std::sqrt(phi_a)) +
        " times the noise the positions show: an effect outside the catalogue, disturbed "
        "positions, or noise the samples do not show (tremor, correlated noise)");
  }
  if (ctx.has_gyro && r.final_where.gyro_p < 1e-3) {
    r.warnings.push_back(
        "the final model still leaves gyroscope residuals " +
        Format("%.3g", std::sqrt(r.final_where.gyro_chi2 / std::max(1, r.final_where.gyro_dof))) +
        " times the noise the positions show: an effect outside the catalogue (earth rotation, "
        "bias instability) or correlated noise");
  }
  r.success = true;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  std::ostringstream m;
  m << "discovery on " << n << " positions: " << r.verdict;
  r.message = m.str();
  return true;
}

bool DiscoverEffects(const ImuLog& log, const CalibrationOptions& calibration,
                     const std::vector<Effect>& baseline_effects, const DiscoveryOptions& options,
                     DiscoveryResult* result) {
  CHECK(result != nullptr);
  *result = DiscoveryResult();
  std::string error;
  if (!calibration.IsValid(&error) || !options.IsValid(&error)) {
    result->message = error;
    return false;
  }
  if (!log.Validate(&error)) {
    result->message = error;
    return false;
  }
  StaticDetection detection;
  if (!DetectStaticIntervals(log, calibration.detector, &detection)) {
    result->message = log.source + ": " + detection.message;
    return false;
  }
  result->source = log.source;
  const bool ok =
      DiscoverFromObservations(ObservationsFromIntervals(detection.intervals, log.has_gyro()),
                               calibration, baseline_effects, options, result);
  if (!ok && !log.source.empty()) result->message = log.source + ": " + result->message;
  return ok;
}

}  // namespace gravcal
