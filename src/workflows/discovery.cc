#include "gravcal/workflows/discovery.h"

#include <glog/logging.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "core/warnings.h"
#include "gravcal/core/imu_model.h"
#include "methods/between_pose_rotations.h"
#include "methods/static_positions.h"
#include "util/source_prefix.h"
#include "util/statistics.h"
#include "workflows/discovery_candidates.h"
#include "workflows/discovery_context.h"
#include "workflows/discovery_cross_validation.h"
#include "workflows/discovery_localisation.h"
#include "workflows/discovery_step.h"

namespace gravcal {
namespace internal {
namespace {

// The starting model: the configured calibration (coarse fit and
// refinement) of the positions, and the discovery context and seed fit
// from it. False with r->message when it cannot be fitted.
bool StartingModel(const std::vector<StaticObservation>& observations,
                   const CalibrationOptions& calibration, const DiscoveryOptions& options,
                   DiscoveryResult* result, DiscoveryContext* context, EffectFitResult* start_fit) {
  DiscoveryResult& r = *result;
  const int n = static_cast<int>(observations.size());
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
  for (size_t i = 0; i < start.warnings.size(); ++i) {
    if (i < start.warning_codes.size() && start.warning_codes[i] == WarningCode::kStandardGravity) {
      AddWarning(WarningCode::kStandardGravity, start.warnings[i], &r.warnings, &r.warning_codes);
    }
  }

  DiscoveryContext& ctx = *context;
  ctx.observations = &r.observations;
  ctx.gravity = r.gravity;
  ctx.parameterization = calibration.refinement.parameterization == AccelParameterization::kScale
                             ? AccelParameterization::kScale
                             : AccelParameterization::kScaleMisalignment;
  ctx.has_gyro = n > 0 && std::all_of(observations.begin(), observations.end(),
                                      [](const StaticObservation& o) { return o.has_gyro; });
  ctx.use_rotations = options.use_between_pose_rotations && ctx.has_gyro &&
                      static_cast<int>(TurnPairs(observations).size()) >= kMinRotations;
  ctx.has_temperature = n > 0 && std::all_of(observations.begin(), observations.end(),
                                             [](const StaticObservation& o) {
                                               return std::isfinite(o.temperature());
                                             });
  EffectFitResult& seed = *start_fit;
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
  return true;
}

// "gyroscope static means exceed their noise by 11.8 x".
std::string ExcessPhrase(EffectSensor sensor, double excess) {
  return std::string(sensor == EffectSensor::kAccelerometer ? "accelerometer |a| - g residuals"
                                                            : "gyroscope static means") +
         " exceed their noise by " + FormatNumber("%.3g", excess) + " x";
}

// The conclusion on one sensor, from its own final fit and the last round
// of candidates (which none of its candidates passed).
SensorVerdict JudgeSensor(EffectSensor sensor, bool stopped_by_limit, const DiscoveryResult& r) {
  const bool accel = sensor == EffectSensor::kAccelerometer;
  const SensorFitSummary& f = accel ? r.final_model.fit.accel_fit : r.final_model.fit.gyro_fit;
  SensorVerdict v;
  v.sensor = sensor;
  v.information = f.information;
  std::vector<const DiscoveryStep*> own;
  for (const DiscoveryStep& s : r.steps) {
    if (IsAccel(s.effect) != accel) continue;
    v.named.push_back(s.effect);
    own.push_back(&s);
  }
  v.excess = f.dof() > 0 ? std::sqrt(f.chi2 / f.dof()) : NAN;
  v.p_value = accel ? r.final_where.accel_p : r.final_where.gyro_p;
  int tried = 0;
  for (const CandidateScore& c : r.final_candidates) {
    tried += c.tried && IsAccel(c.effect) == accel ? 1 : 0;
  }
  const char* name = accel ? "accelerometer" : "gyroscope";
  std::ostringstream line;
  line << name << ": ";
  if (v.named.empty()) {
    line << "no significant missing effect";
  } else {
    line << "missing effect" << (v.named.size() > 1 ? "s" : "") << " found: ";
    for (size_t i = 0; i < own.size(); ++i) {
      line << (i ? ", " : "") << ToString(own[i]->effect);
      if (!own[i]->ambiguous_with.empty()) {
        line << " (or " << ToString(own[i]->ambiguous_with.front())
             << ": this session cannot tell them apart)";
      }
    }
  }
  if (v.p_value < 1e-3 && std::isfinite(v.excess)) {
    line << "; " << ExcessPhrase(sensor, v.excess);
    if (stopped_by_limit) {
      line << " (stopped at discovery_max_steps)";
    } else if (tried == 0) {
      line << "; no catalogue effect can be tested on it in this session (see the warnings)";
    } else {
      v.unexplained = true;
      line << "; no catalogue effect explains it";
    }
  }
  v.verdict = line.str();
  return v;
}

// The verdict line of the run, each sensor's own verdict, and the warnings
// on what the final model still leaves.
void Verdict(const DiscoveryContext& ctx, bool stopped_by_limit, DiscoveryResult* result) {
  DiscoveryResult& r = *result;
  r.sensors.push_back(JudgeSensor(EffectSensor::kAccelerometer, stopped_by_limit, r));
  if (ctx.has_gyro) r.sensors.push_back(JudgeSensor(EffectSensor::kGyroscope, stopped_by_limit, r));
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
  for (const SensorVerdict& s : r.sensors) {
    if (!s.unexplained) continue;
    v << "; " << ExcessPhrase(s.sensor, s.excess) << "; no catalogue effect explains it";
  }
  r.verdict = v.str();
  const double phi_a = r.final_model.fit.accel_fit.dof() > 0
                           ? r.final_model.fit.accel_fit.chi2 / r.final_model.fit.accel_fit.dof()
                           : 1.0;
  if (r.final_where.accel_p < 1e-3) {
    AddWarning(
        WarningCode::kResidualsAboveNoise,
        "the final model still leaves accelerometer residuals " +
            FormatNumber("%.3g", std::sqrt(phi_a)) +
            " times the noise the positions show: an effect outside the catalogue, disturbed "
            "positions, or noise the samples do not show (tremor, correlated noise)",
        &r.warnings, &r.warning_codes);
  }
  if (ctx.has_gyro && r.final_where.gyro_p < 1e-3) {
    AddWarning(
        WarningCode::kResidualsAboveNoise,
        "the final model still leaves gyroscope residuals " +
            FormatNumber("%.3g",
                         std::sqrt(r.final_where.gyro_chi2 / std::max(1, r.final_where.gyro_dof))) +
            " times the noise the positions show: an effect outside the catalogue (earth rotation, "
            "bias instability, an AHRS's own processing of its gyroscope) or correlated noise; the "
            "accelerometer's tests do not depend on it",
        &r.warnings, &r.warning_codes);
  }
}

// The candidate effects: the options' list, or the whole catalogue.
std::vector<Effect> CandidateEffects(const DiscoveryOptions& options) {
  std::vector<Effect> candidates = options.candidates;
  if (candidates.empty()) {
    for (const EffectInfo& info : EffectCatalogue()) candidates.push_back(info.effect);
  }
  return candidates;
}

// "the position magnitudes" (and "the within-pose trends" when a pose has
// one): what the accelerometer's decisions use without the rotations.
std::string WhatIsLeft(const std::vector<StaticObservation>& observations) {
  const bool trends = std::any_of(observations.begin(), observations.end(),
                                  [](const StaticObservation& o) { return o.has_trend; });
  return trends ? "the position magnitudes and within-pose trends only"
                : "the position magnitudes only";
}

// Whether the rotations between poses stay in the accelerometer's fits:
// they must fit their noise (chi2 p >= 1e-3 on their rows less the
// gyroscope's 12 parameters) under the richest accelerometer model this
// session can test, the baseline with every accelerometer candidate that
// applies, so that a missing accelerometer effect is not taken for a
// fault of the turns. What exceeds them then is outside the accelerometer
// catalogue (a gyroscope g-sensitivity during the turn, a turn the
// gyroscope does not integrate): the rows are left out with a warning, and
// the accelerometer's decisions use the magnitudes and trends alone.
void CheckRotations(const std::vector<Effect>& baseline_effects,
                    const std::vector<Effect>& candidates, const DiscoveryOptions& options,
                    const EffectFitResult& seed, DiscoveryContext* context,
                    DiscoveryResult* result) {
  DiscoveryContext& ctx = *context;
  if (!ctx.use_rotations) return;
  std::vector<Effect> richest = baseline_effects;
  for (Effect e : candidates) {
    if (!IsAccel(e) || Contains(richest, e)) continue;
    if (Info(e).form == EffectForm::kInUpper &&
        ctx.parameterization != AccelParameterization::kScale) {
      continue;
    }
    if (Info(e).regressor == EffectRegressor::kTemperature &&
        (!ctx.has_temperature || ctx.temperature_range < options.min_temperature_range)) {
      continue;
    }
    richest.push_back(e);
  }
  // Only where needed: when the magnitudes keep min_dof residual degrees
  // of freedom even under the richest model, they test every candidate on
  // their own, and the rotations (about a hundred times the CPU of the
  // magnitudes: every fit integrates every turn) are left out. The choice
  // follows from the design (poses and parameters), not from the data, so
  // the tests stay honest.
  const int parameters = AccelModelParameterCount(ctx.parameterization, richest);
  if (static_cast<int>(ctx.observations->size()) - parameters >= options.min_dof) {
    ctx.use_rotations = false;
    return;
  }
  EffectFitResult fit;
  if (!FitDiscoveryModel(ctx, *ctx.observations, richest, seed, true, false, false, &fit) &&
      !FitDiscoveryModel(ctx, *ctx.observations, baseline_effects, seed, true, false, false,
                         &fit)) {
    return;
  }
  const SensorFitSummary& f = fit.accel_fit;
  const int dof = f.rotation_residuals - 12;
  if (f.rotation_residuals > 0 && dof > 0 && ChiSquareUpperTail(f.rotation_chi2, dof) >= 1e-3) {
    return;
  }
  ctx.use_rotations = false;
  std::ostringstream w;
  w.precision(3);
  if (f.rotation_residuals == 0) {
    w << "the rotations between poses could not be used";
    for (const std::string& m : fit.warnings) w << ": " << m;
    w << "; the accelerometer's decisions use " << WhatIsLeft(*ctx.observations);
    AddWarning(WarningCode::kRotationSkipped, w.str(), &result->warnings, &result->warning_codes);
    return;
  }
  w << "the rotations between poses exceed their noise even with every accelerometer effect "
       "(chi2 "
    << f.rotation_chi2 << " on about " << dof
    << " dof): a gyroscope g-sensitivity or a turn the gyroscope does not integrate; they are "
       "left out, and the accelerometer's decisions use "
    << WhatIsLeft(*ctx.observations);
  AddWarning(WarningCode::kRotationsAboveNoise, w.str(), &result->warnings, &result->warning_codes);
}

// Assesses the baseline with both sensors cross-validated; false with
// r->message when it cannot be fitted.
bool AssessBaseline(const DiscoveryContext& ctx, const std::vector<Effect>& baseline_effects,
                    const EffectFitResult& seed, int where_count, DiscoveryResult* result) {
  DiscoveryResult& r = *result;
  const std::vector<EffectSensor> both = {EffectSensor::kAccelerometer, EffectSensor::kGyroscope};
  if (!Assess(ctx, baseline_effects, seed, both, nullptr, &r.baseline)) {
    r.message = "baseline fit: " + r.baseline.fit.message;
    return false;
  }
  for (const std::string& w : r.baseline.fit.warnings) {
    AddWarning(w.find("exceed their noise") != std::string::npos ? WarningCode::kRotationsAboveNoise
                                                                 : WarningCode::kRotationSkipped,
               w, &r.warnings, &r.warning_codes);
  }
  if (!r.baseline.fit.accel_fit.undetermined.empty()) {
    std::string names;
    for (const std::string& u : r.baseline.fit.accel_fit.undetermined) {
      names += (names.empty() ? "" : ", ") + u;
    }
    AddWarning(WarningCode::kUndetermined,
               "the positions do not determine " + names +
                   " of the baseline: its gaps are still meaningful, its parameters not",
               &r.warnings, &r.warning_codes);
  }
  r.baseline_where = Locate(ctx, r.baseline.fit, where_count);
  return true;
}

}  // namespace
}  // namespace internal

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
  if (!(min_trend_seconds > 0.0) || !std::isfinite(min_trend_seconds)) {
    *error = "discovery_min_trend_seconds: must be positive";
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
  internal::DiscoveryContext ctx;
  EffectFitResult seed;
  const std::vector<Effect> candidates = internal::CandidateEffects(options);
  if (!internal::StartingModel(observations, calibration, options, &r, &ctx, &seed)) return false;
  internal::CheckRotations(baseline_effects, candidates, options, seed, &ctx, &r);
  if (!internal::AssessBaseline(ctx, baseline_effects, seed, options.where_count, &r)) {
    return false;
  }
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
    internal::TryCandidates(ctx, current, candidates, options, &untestable_warned, &r.warnings,
                            &scores, &fits);
    internal::CodeNewWarnings(WarningCode::kEffectUntestable, r.warnings, &r.warning_codes);
    internal::ScoreCandidates(ctx, current, fits, &scores);
    const int best = internal::ChooseCandidate(ctx, current, options, fits, &scores);
    if (best < 0) {
      r.final_candidates = scores;
      break;
    }
    if (!internal::TakeStep(ctx, options, scores, best, fits[best], where, &current, &r)) {
      return false;
    }
    where = internal::Locate(ctx, current.fit, options.where_count);
  }
  r.final_model = current;
  r.final_where = where;
  internal::Verdict(ctx, stopped_by_limit, &r);
  r.success = true;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  std::ostringstream m;
  m << "discovery on " << observations.size() << " positions: " << r.verdict;
  r.message = m.str();
  return true;
}

bool DiscoverEffects(const ImuLog& log, const CalibrationOptions& calibration,
                     const std::vector<Effect>& baseline_effects, const DiscoveryOptions& options,
                     DiscoveryResult* result) {
  CHECK(result != nullptr);
  *result = DiscoveryResult();
  std::vector<StaticInterval> intervals;
  if (!calibration.IsValid(&result->message) || !options.IsValid(&result->message) ||
      !internal::DetectLogIntervals(log, calibration.detector, &intervals, &result->message)) {
    return false;
  }
  result->source = log.source;
  // Issue 21: the within-pose trends along gravity of the poses held
  // min_trend_seconds or longer (the real recordings' poses of 3-9 s stay
  // magnitude-only: a trend from their few batches is mostly noise and made
  // the Ferraris verdict unstable under leave-one-out), and the turns
  // between the poses.
  std::vector<StaticObservation> observations;
  if (options.use_within_pose_trends) {
    observations =
        ObservationsFromIntervals(log, intervals, GravityTrendOptions(options.min_trend_seconds));
  } else {
    observations = ObservationsFromIntervals(intervals, log.has_gyro());
  }
  if (options.use_between_pose_rotations) AddBetweenPoseTurns(log, intervals, &observations);
  const bool ok =
      DiscoverFromObservations(observations, calibration, baseline_effects, options, result);
  if (!ok) result->message = internal::PrefixSource(log.source, result->message);
  // Issue 35: higher-order temperature terms and hysteresis, beside the
  // catalogue.
  if (ok && log.has_temperature()) {
    ThermalCalibrationOptions thermal;
    thermal.detector = calibration.detector;
    thermal.detector.trend_factor = 0.0;
    thermal.detector.spread_factor = 0.0;
    thermal.accel_nominal_scale = calibration.nominal_scale;
    thermal.gravity = result->gravity;
    result->thermal = DiscoverThermal(log, thermal);
    for (const std::string& f : result->thermal.findings) result->verdict += "; " + f;
  }
  return ok;
}

}  // namespace gravcal
