#include "workflows/discovery_candidates.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "util/statistics.h"
#include "workflows/discovery_cross_validation.h"

namespace gravcal {
namespace internal {
namespace {

// Whether a fit leaves the sensor's data at the noise its positions show:
// chi2 on dof degrees of freedom with p >= 0.01.
bool FitsNoise(double chi2, int dof) { return dof >= 1 && ChiSquareUpperTail(chi2, dof) >= 0.01; }

// Columns of the gyroscope's nuisance parameters in an accelerometer fit
// with the rotations between poses (effect_fit.h).
constexpr int kRotationGyroParameters = 12;

// The residual degrees of freedom the position magnitudes keep when e is
// added to the accelerometer fit `now`: positions minus accelerometer
// parameters (the gyroscope's nuisance parameters of the rotations are
// not the magnitudes' to determine).
int MagnitudeDof(const SensorFitSummary& now, int positions, Effect e) {
  const int nuisance = now.rotation_residuals > 0 ? kRotationGyroParameters : 0;
  return positions - (now.num_parameters - nuisance + Info(e).num_parameters);
}

// Why an effect cannot be tried in this session, or "".
std::string NotApplicable(const DiscoveryContext& ctx, const std::vector<Effect>& current, Effect e,
                          const DiscoveryOptions& options, const SensorFitSummary& now) {
  const int sensor_residuals = now.num_residuals;
  const int sensor_parameters = now.num_parameters;
  const EffectInfo& info = Info(e);
  if (Contains(current, e)) return "already in the model";
  if (Info(e).form == EffectForm::kInUpper &&
      ctx.parameterization != AccelParameterization::kScale) {
    return "already in the baseline (parameterization " +
           std::string(ToString(ctx.parameterization)) + ")";
  }
  if (info.sensor == EffectSensor::kGyroscope && !ctx.has_gyro) {
    return "the log has no gyroscope";
  }
  if (info.regressor == EffectRegressor::kTemperature) {
    if (!ctx.has_temperature) return "the log has no temperature";
    if (ctx.temperature_range < options.min_temperature_range) {
      return "the positions span only " + FormatNumber("%.2f", ctx.temperature_range) +
             " degC (needs " + FormatNumber("%.2f", options.min_temperature_range) +
             "): record while the temperature changes";
    }
  }
  const int per_position = info.sensor == EffectSensor::kGyroscope ? 3 : 1;
  const int dof = sensor_residuals - sensor_parameters - info.num_parameters;
  // Accelerometer: the magnitudes alone must keep min_dof unless trend or
  // rotation rows can confirm the effect (ChooseCandidate).
  const bool confirmable =
      info.sensor == EffectSensor::kAccelerometer &&
      (now.rotation_residuals > 0 ||
       (now.trend_residuals > 0 && info.regressor != EffectRegressor::kOrientation));
  const int positions = static_cast<int>(ctx.observations->size());
  const bool magnitudes_short = info.sensor == EffectSensor::kAccelerometer &&
                                MagnitudeDof(now, positions, e) < options.min_dof && !confirmable;
  if (dof < options.min_dof || dof - per_position < 1 || magnitudes_short) {
    std::ostringstream s;
    const int shown = magnitudes_short ? positions : sensor_residuals;
    s << "too few positions: " << shown / per_position << " positions give " << shown
      << " residuals for " << sensor_parameters << " + " << info.num_parameters
      << " parameters (needs " << options.min_dof
      << " left over, and one in every leave-one-out fold); record more poses"
      << (IsAccel(e) && ctx.parameterization != AccelParameterization::kScale
              ? " or use parameterization: scale"
              : "")
      << (IsAccel(e) ? ", hold them 10 s or longer (within-pose trends), or record the "
                       "gyroscope (rotations between poses)"
                     : "");
    return s.str();
  }
  return "";
}

// Warns once per effect that it cannot be tested in this session.
void WarnUntestable(Effect e, const std::string& why, std::vector<std::string>* warned,
                    std::vector<std::string>* warnings) {
  if (std::find(warned->begin(), warned->end(), Info(e).name) != warned->end()) return;
  warned->push_back(Info(e).name);
  warnings->push_back(why);
}

// The names of e's parameters that the extended fit does not determine.
std::string UndeterminedOf(Effect e, const SensorFitSummary& ext) {
  std::string undetermined;
  for (const std::string& name : Info(e).parameter_names) {
    if (std::find(ext.undetermined.begin(), ext.undetermined.end(), name) !=
        ext.undetermined.end()) {
      undetermined += (undetermined.empty() ? "" : ", ") + name;
    }
  }
  return undetermined;
}

// Tries e on top of `current`: fills *c (tried, or the reason not) and *fit.
void TryCandidate(const DiscoveryContext& ctx, const ModelAssessment& current, Effect e,
                  const DiscoveryOptions& options, std::vector<std::string>* warned,
                  std::vector<std::string>* warnings, CandidateScore* c, EffectFitResult* fit) {
  c->effect = e;
  const bool accel = IsAccel(e);
  const SensorFitSummary& now = accel ? current.fit.accel_fit : current.fit.gyro_fit;
  c->reason = NotApplicable(ctx, current.effects, e, options, now);
  if (!c->reason.empty()) {
    // Warn once per effect; "already in the model / baseline" is no news.
    if (c->reason.rfind("already", 0) != 0) {
      WarnUntestable(e,
                     std::string(Info(e).name) + " cannot be tested in this session: " + c->reason,
                     warned, warnings);
    }
    return;
  }
  std::vector<Effect> extended = current.effects;
  extended.push_back(e);
  EffectFitResult extended_fit;
  if (!FitDiscoveryModel(ctx, *ctx.observations, extended, current.fit, accel, !accel, true,
                         &extended_fit)) {
    c->reason = "the extended fit failed: " + extended_fit.message;
    return;
  }
  const SensorFitSummary& ext = accel ? extended_fit.accel_fit : extended_fit.gyro_fit;
  const std::string undetermined = UndeterminedOf(e, ext);
  if (!undetermined.empty()) {
    c->reason = "cannot be identified in this session (" + undetermined +
                " not determined by the positions)";
    WarnUntestable(e, std::string(Info(e).name) + ": " + c->reason, warned, warnings);
    return;
  }
  c->tried = true;
  c->information = ext.information;
  c->dof = Info(e).num_parameters;
  c->delta_chi2 = now.chi2 - ext.chi2;
  if (accel) {
    c->magnitude_dof = MagnitudeDof(now, static_cast<int>(ctx.observations->size()), e);
    // The trend and rotation rows' own share of delta chi2: together, on
    // the effect's dof, they confirm an effect the magnitudes cannot test
    // (one test, so that two sources do not each get the level).
    c->trend_delta_chi2 = now.trend_chi2 - ext.trend_chi2;
    c->rotation_delta_chi2 = now.rotation_chi2 - ext.rotation_chi2;
    if (ext.trend_residuals + ext.rotation_residuals > 0) {
      const double beside = c->trend_delta_chi2 + c->rotation_delta_chi2;
      c->confirmation_p_value = beside > 0.0 ? ChiSquareUpperTail(beside, c->dof) : 1.0;
    }
  }
  c->gap = InSampleGap(extended_fit, ctx.has_gyro);
  // The other sensor's part was not refitted: its gap is the current one.
  if (accel) {
    c->gap.gyro = current.gap.gyro;
    c->gap.gyro_sigma = current.gap.gyro_sigma;
  } else {
    c->gap.accel = current.gap.accel;
    c->gap.accel_sigma = current.gap.accel_sigma;
  }
  // Cross-validated only when its tests pass (ChooseCandidate): until then
  // its sensor's cross-validated gap is unknown.
  c->cv_gap = current.cv_gap;
  if (accel) {
    c->cv_gap.accel = c->cv_gap.accel_sigma = NAN;
  } else {
    c->cv_gap.gyro = c->cv_gap.gyro_sigma = NAN;
  }
  *fit = extended_fit;
}

// The significance level of one candidate test of a sensor: each sensor is
// its own family, `significance` divided among that sensor's candidates
// tried, so candidates of the other sensor (an AHRS gyroscope's, which
// cannot explain its excess) do not raise the bar for this one's.
double SensorAlpha(const std::vector<CandidateScore>& scores, bool accel,
                   const DiscoveryOptions& options) {
  int tried = 0;
  for (const CandidateScore& c : scores) tried += c.tried && IsAccel(c.effect) == accel ? 1 : 0;
  return options.significance / std::max(1, tried);
}

// Whether the rows beside the magnitudes single candidate i out. An
// accelerometer effect that leaves the magnitudes fewer than min_dof
// residual dof fits them about as well as any other candidate of its size:
// what tells the candidates apart is how each predicts the trends within
// the poses (a temperature bias's slope along gravity flips sign between a
// pose and its opposite, a scale factor's does not; a drift follows time,
// not temperature; a nonlinearity has none) and the turns between poses.
// Fills c's margin over its closest rival of the same size, the rival's
// delta BIC minus its own (the chi2 gap of the two fits over the
// dispersion), and the margin needed at level alpha: z^2 with z the normal
// quantile 1 - alpha. The reason: when the rival B is the true effect, the
// gap chi2_B - chi2_c is lambda + 2 mu' e to first order, lambda the
// rival's misfit of the truth, so it exceeds m with probability
// Phi(-(m + lambda) / (2 sqrt(lambda))), largest at lambda = m: Phi(-sqrt m).
// (The second-order term, a difference of two fitted chi2 on the same
// dof, has mean zero and is left out; the twelve-pose tests measure what
// it leaves.)
void Prefer(const std::vector<CandidateScore>& scores, int i, double alpha, CandidateScore* c) {
  c->preference_margin = NAN;
  c->preference_threshold = std::pow(NormalQuantile(1.0 - alpha), 2);
  for (size_t j = 0; j < scores.size(); ++j) {
    const CandidateScore& rival = scores[j];
    if (static_cast<int>(j) == i || !rival.tried || !IsAccel(rival.effect) || rival.dof != c->dof) {
      continue;
    }
    const double margin = rival.delta_bic - c->delta_bic;
    if (std::isnan(c->preference_margin) || margin < c->preference_margin) {
      c->preference_margin = margin;
      c->runner_up = rival.effect;
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
int PairLookAhead(const DiscoveryContext& ctx, const ModelAssessment& current,
                  const DiscoveryOptions& options, std::vector<CandidateScore>* scores) {
  std::vector<int> masked;
  for (size_t i = 0; i < scores->size(); ++i) {
    const CandidateScore& c = (*scores)[i];
    const bool testable =
        !IsAccel(c.effect) || c.magnitude_dof >= options.min_dof || !c.confirmed_by.empty();
    if (c.tried && testable && c.p_value < SensorAlpha(*scores, IsAccel(c.effect), options) &&
        c.delta_bic < -options.min_bic_gain) {
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
      const double alpha = SensorAlpha(*scores, accel, options);
      std::vector<Effect> pair = current.effects;
      pair.push_back(ca.effect);
      pair.push_back(cb.effect);
      EffectFitResult fit;
      if (!FitDiscoveryModel(ctx, *ctx.observations, pair, current.fit, accel, !accel, true, &fit))
        continue;
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

void TryCandidates(const DiscoveryContext& ctx, const ModelAssessment& current,
                   const std::vector<Effect>& candidates, const DiscoveryOptions& options,
                   std::vector<std::string>* warned, std::vector<std::string>* warnings,
                   std::vector<CandidateScore>* scores, std::vector<EffectFitResult>* fits) {
  for (Effect e : candidates) {
    CandidateScore c;
    EffectFitResult fit;
    TryCandidate(ctx, current, e, options, warned, warnings, &c, &fit);
    scores->push_back(c);
    fits->push_back(fit);
  }
}

// The noise scale, per sensor and from that sensor's residuals only: a
// candidate is tested against the positions' own sigmas (chi-square) when
// they are right for it, that is when the current model extended by all
// candidates of the sensor at once, or by this candidate alone, fits the
// sensor's data to that noise (chi2 test, p >= 0.01). Otherwise the data
// show noise (or an effect) beyond the catalogue, and the candidate's
// statistic is divided by the dispersion phi = chi2 / dof its extended
// model leaves, and referred to F(p, dof). (Dividing by each candidate's
// own phi alone would count the other missing effects as noise: two
// effects hidden together could then both go unnamed. And when every
// candidate together leaves no degree of freedom, as on 14 hand-placed
// poses with the scale baseline, the joint model cannot tell noise from
// effect: a candidate that brings the sensor down to its noise is then
// judged by that noise, not by its own leftover scatter.)
// The BIC penalty is p ln(n) with n the sensor's own residual count, so an
// accelerometer decision is the same with or without a gyroscope column.
void ScoreCandidates(const DiscoveryContext& ctx, const ModelAssessment& current,
                     const std::vector<EffectFitResult>& fits,
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
    if (count == 1 ||
        FitDiscoveryModel(ctx, *ctx.observations, all, current.fit, accel, !accel, true, &joint)) {
      if (count > 1) richest = &joint;
      const SensorFitSummary& f = accel ? richest->accel_fit : richest->gyro_fit;
      noise_fits = FitsNoise(f.chi2, f.num_residuals - f.rank);
    }
    const SensorFitSummary& now = accel ? current.fit.accel_fit : current.fit.gyro_fit;
    const double log_n = std::log(static_cast<double>(std::max(1, now.num_residuals)));
    for (size_t i = 0; i < scores->size(); ++i) {
      CandidateScore& c = (*scores)[i];
      if (!c.tried || IsAccel(c.effect) != accel) continue;
      const SensorFitSummary& ext = accel ? fits[i].accel_fit : fits[i].gyro_fit;
      const int dof1 = ext.dof();
      const bool sigmas_right = noise_fits || FitsNoise(ext.chi2, dof1);
      c.dispersion = sigmas_right || dof1 <= 0 ? 1.0 : std::max(1.0, ext.chi2 / dof1);
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

int ChooseCandidate(const DiscoveryContext& ctx, const ModelAssessment& current,
                    const DiscoveryOptions& options, const std::vector<EffectFitResult>& fits,
                    std::vector<CandidateScore>* scores_out) {
  std::vector<CandidateScore>& scores = *scores_out;
  int best = -1;
  for (size_t i = 0; i < scores.size(); ++i) {
    CandidateScore& c = scores[i];
    if (!c.tried) continue;
    const bool accel = IsAccel(c.effect);
    const double alpha = SensorAlpha(scores, accel, options);
    std::ostringstream why;
    why.precision(3);
    if (!(c.p_value < alpha)) why << "p = " << c.p_value << " not below " << alpha << "; ";
    if (!(c.delta_bic < -options.min_bic_gain)) {
      why << "delta BIC = " << c.delta_bic << " not below " << -options.min_bic_gain << "; ";
    }
    c.confirmed_by.clear();
    if (accel && c.magnitude_dof < options.min_dof) {
      const std::string beside = "within-pose trends + rotations between poses (delta chi2 " +
                                 FormatNumber("%.3g", c.trend_delta_chi2) + " + " +
                                 FormatNumber("%.3g", c.rotation_delta_chi2) +
                                 ", p = " + FormatNumber("%.2g", c.confirmation_p_value) + ")";
      Prefer(scores, static_cast<int>(i), alpha, &c);
      // "delta BIC 22.2 to accel_bias_drift, needs 7.88".
      const std::string margin = "delta BIC " + FormatNumber("%.3g", c.preference_margin) + " to " +
                                 ToString(c.runner_up) + ", needs " +
                                 FormatNumber("%.3g", c.preference_threshold);
      if (c.confirmation_p_value < alpha) {
        c.confirmed_by = beside;
      } else if (c.preference_margin >= c.preference_threshold) {
        c.confirmed_by =
            "within-pose trends + rotations between poses, which prefer it to every other "
            "candidate its size (" +
            margin + ")";
      } else {
        why << "the magnitudes keep " << c.magnitude_dof << " residual dof (needs "
            << options.min_dof << "), the " << beside << " do not confirm it"
            << (std::isfinite(c.preference_margin) ? " and do not single it out (" + margin + ")"
                                                   : "")
            << "; ";
      }
    }
    // Leave-one-position-out cross-validation (a dozen refits) only for a
    // candidate that passed the tests above.
    if (why.str().empty()) {
      std::vector<Effect> extended = current.effects;
      extended.push_back(c.effect);
      const double before = accel ? current.cv_gap.accel_sigma : current.cv_gap.gyro_sigma;
      if (!CrossValidate(ctx, extended, fits[i], Info(c.effect).sensor, &c.cv_gap, nullptr,
                         nullptr)) {
        why << "cross-validation failed (a fold could not be fitted); ";
      } else {
        const double after = accel ? c.cv_gap.accel_sigma : c.cv_gap.gyro_sigma;
        if (!(after < before)) {
          why << "cross-validated gap " << after << " sigma not below " << before << "; ";
        }
      }
    }
    c.reason = why.str();
    if (!c.reason.empty()) c.reason.resize(c.reason.size() - 2);
    c.significant = c.reason.empty();
    if (c.significant && (best < 0 || c.delta_bic < scores[best].delta_bic)) {
      best = static_cast<int>(i);
    }
  }
  if (best < 0) best = PairLookAhead(ctx, current, options, &scores);
  return best;
}

}  // namespace internal
}  // namespace gravcal
