// gravcal/workflows/discovery.h: the model discrepancy workflow (`gravcal discover`).
//
// 1. Fit the baseline (the configured parameterisation plus any effects the
//    config switches on) to the static positions: accelerometer magnitudes
//    and, where the log has one, mean gyroscope readings (effect_fit.h).
// 2. Simulate the session with it: the reading the model predicts for every
//    position, accelerometer (the raw vector of magnitude g along the
//    measured direction) and gyroscope.
// 3. Locate the disagreement: measured minus simulated, per position and
//    grouped by dominant axis, specific-force level, time and temperature,
//    each in units of the noise that position's own samples show.
// 4. Try every candidate effect of the catalogue (model_effects.h): refit
//    with it (Ceres) and score it from its own sensor's evidence alone:
//    - a likelihood-ratio test on that sensor's chi2 with dof = the effect's
//      parameter count, against the positions' own noise; when neither the
//      model with every candidate of the sensor nor the one with this
//      candidate fits the sensor's data to that noise (noise the samples do
//      not show, e.g. hand tremor), the statistic is divided by phi = chi2 /
//      dof of the extended model and referred to F(p, dof) instead;
//    - delta BIC = (chi2_new - chi2_old) / phi + p ln(n), n the sensor's
//      own residual count;
//    - leave-one-position-out cross-validation: every position predicted by
//      a fit without it; the effect must lower the cross-validated gap.
//    Significant = p below significance / (candidates of its sensor tried),
//    delta BIC below -min_bic_gain and a smaller cross-validated gap. The
//    significant candidate with the lowest delta BIC is named; others of the
//    same sensor within ambiguity_bic of it explain the data almost as well
//    and are reported as ambiguous with advice on the recording that would
//    separate them.
// 5. Add it; the extended model is the new baseline; repeat until nothing
//    is significant.
// 6. Judge each sensor (SensorVerdict): the effects named for it, and, when
//    its final model still leaves far more than its noise, that no catalogue
//    effect explains the excess. No sensor's chi2, noise level, candidates
//    or excess enters the other's decisions (the gyroscope's g-sensitivity
//    takes the accelerometer's fitted specific force as its regressor,
//    nothing more): an AHRS gyroscope whose static means sit 11 sigma from
//    any static model does not hide an accelerometer effect, and the
//    accelerometer's scores are the same with or without a gyroscope
//    column.
//
// Each decision says which information of the session it used
// (SensorFitSummary::information: "position magnitudes" for the
// accelerometer, with "+ within-pose trends" and "+ rotations between
// poses" when those rows are in its fits; "static mean rates" for the
// gyroscope). Issue 21: the trends and rotations are rows of the same
// likelihood as the magnitudes (effect_fit.h), so the chi2 tests, BIC and
// cross-validation see them all; an accelerometer effect that leaves the
// magnitudes fewer than min_dof residual degrees of freedom is named only
// when the trends' or rotations' own rows confirm it, or when they single
// it out: every other candidate of its size then fits the magnitudes as
// well, and the whole fit must prefer it over each of them by a margin
// (CandidateScore::confirmed_by, preference_margin). Without a gyroscope, with poses shorter
// than min_trend_seconds, or with rotations exceeding their noise, the
// accelerometer falls back to what is left (down to the magnitudes alone).
//
// The gap is the rms of measured minus simulated: |a| - g over positions for
// the accelerometer (m/s^2), the gyroscope residual over positions and axes
// (raw units); each also in units of the noise (rms of whitened residuals,
// 1 = at the noise level).
#ifndef GRAVCAL_WORKFLOWS_DISCOVERY_H_
#define GRAVCAL_WORKFLOWS_DISCOVERY_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "gravcal/core/imu_log.h"
#include "gravcal/core/model_effects.h"
#include "gravcal/core/types.h"
#include "gravcal/methods/effect_fit.h"
#include "gravcal/methods/twelve_position.h"
#include "gravcal/workflows/thermal_discovery.h"

namespace gravcal {

struct DiscoveryOptions {
  // Candidates to try; empty = the whole catalogue.
  std::vector<Effect> candidates;
  // Family-wise significance level of one step (divided among the
  // candidates tried).
  double significance = 0.01;
  // A candidate must lower the BIC by at least this much: 10 is "very
  // strong" evidence on the Kass-Raftery scale (6 "strong"). Borderline
  // evidence would make the verdict flip when one position is left out.
  double min_bic_gain = 10.0;
  // Candidates whose delta BIC is within this of the best are ambiguous.
  double ambiguity_bic = 10.0;
  // Most effects added.
  int max_steps = 4;
  // Residual degrees of freedom an extended model must keep (the
  // leave-one-out folds need at least one).
  int min_dof = 2;
  // Temperature effects are only tried when the positions span this many
  // degrees C.
  double min_temperature_range = 0.5;
  // Positions listed in each `where`.
  int where_count = 3;
  // Issue 21: the accelerometer's fits and tests also use the slope of
  // each pose's mean along gravity during the hold (within-pose trends,
  // 5 batch means per pose), for poses held at least min_trend_seconds;
  // shorter poses stay magnitude-only (their few batches would say more
  // about the noise than about a trend).
  bool use_within_pose_trends = true;
  double min_trend_seconds = 10.0;
  // Issue 21: with a gyroscope, the turns between consecutive poses as
  // rows of the accelerometer's fits (effect_fit.h,
  // use_between_pose_rotations), with the gyroscope's matrix and bias
  // estimated jointly. Used only where the magnitudes cannot test every
  // accelerometer candidate (fewer than min_dof residual degrees of freedom
  // under the richest model), and left out, with a warning, when they
  // exceed their noise under that model.
  bool use_between_pose_rotations = true;

  bool IsValid(std::string* error) const;
};

// rms of measured minus simulated; NaN where the sensor is absent.
struct Gap {
  // m/s^2 (|a| - g) and raw gyroscope units.
  double accel = NAN;
  double gyro = NAN;
  // In units of the noise: rms of the whitened residuals.
  double accel_sigma = NAN;
  double gyro_sigma = NAN;
  // Cross-validated gaps only: positions left out of them because the
  // others do not determine the model without them (leverage near 1).
  int accel_unpredictable = 0;
  int gyro_unpredictable = 0;
};

// One position: measured minus simulated.
struct PositionDisagreement {
  int index = 0;
  double time = 0.0;
  double temperature = NAN;
  // The calibrated specific-force axis nearest vertical ("+z") and the
  // fraction of g on it.
  std::string axis;
  double axis_level = 0.0;
  // Raw accelerometer reading measured and simulated (the model's reading
  // for this position), and |a| - g in m/s^2 and in sigma.
  Eigen::Vector3d accel_measured = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_simulated = Eigen::Vector3d::Zero();
  double accel_residual = 0.0;
  double accel_z = 0.0;
  // Gyroscope measured, simulated, residual (raw units) and per axis in
  // sigma; zero when absent.
  Eigen::Vector3d gyro_measured = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_simulated = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_residual = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_z = Eigen::Vector3d::Zero();
};

// The disagreement over one group of positions (rms in sigma).
struct GroupDisagreement {
  // "axis", "force_level", "time", "temperature".
  std::string by;
  std::string group;
  int count = 0;
  double accel_sigma = NAN;
  double gyro_sigma = NAN;
};

struct Disagreement {
  std::vector<PositionDisagreement> positions;
  std::vector<GroupDisagreement> groups;
  // Positions that disagree most (indices), per sensor.
  std::vector<int> worst_accel;
  std::vector<int> worst_gyro;
  // Whitened sum of squares, its dof and its chi-square p-value.
  double accel_chi2 = 0.0;
  int accel_dof = 0;
  double accel_p = 1.0;
  double gyro_chi2 = 0.0;
  int gyro_dof = 0;
  double gyro_p = 1.0;
  // One line for people.
  std::string summary;
};

// One model: its fit and gaps.
struct ModelAssessment {
  AccelParameterization parameterization = AccelParameterization::kScaleMisalignment;
  std::vector<Effect> effects;
  EffectFitResult fit;
  Gap gap;
  Gap cv_gap;
  // Left-out prediction residuals (|a| - g, and gyroscope e) per position.
  std::vector<double> cv_accel_residuals;
  std::vector<Eigen::Vector3d> cv_gyro_residuals;
};

struct CandidateScore {
  Effect effect = Effect::kAccelQuadratic;
  bool tried = false;
  bool significant = false;
  // Why not tried, or why not significant; empty when named.
  std::string reason;
  int dof = 0;
  double delta_chi2 = NAN;
  // chi2 / dof of the extended model, at least 1.
  double dispersion = 1.0;
  double p_value = NAN;
  double delta_bic = NAN;
  Gap gap;
  Gap cv_gap;
  // Which information of the session its fit and tests used
  // (SensorFitSummary::information of its sensor), e.g. "position
  // magnitudes".
  std::string information;
  // Accelerometer effects: the residual degrees of freedom the extended
  // model leaves the position magnitudes (positions minus accelerometer
  // parameters). Below DiscoveryOptions::min_dof the magnitudes cannot
  // test the effect on their own (every candidate of its size then fits
  // them exactly), and it is named only when the rows beside them confirm
  // it: the part of delta chi2 from the within-pose trend rows and from
  // the rotation rows (0 when not used), and the p-value of their sum on
  // the effect's dof: below the candidate's level, they confirm it on
  // their own. Otherwise they may still single it out among the
  // candidates that fit the magnitudes equally (preference_margin).
  int magnitude_dof = 0;
  double trend_delta_chi2 = 0.0;
  double rotation_delta_chi2 = 0.0;
  double confirmation_p_value = NAN;
  // How much better the whole fit (magnitudes, trends and rotations) is
  // with this candidate than with its closest rival of the same size
  // (runner_up): the rival's delta BIC minus this one's, the chi2 gap
  // of the two fits over the dispersion. NaN when no rival of its size
  // was tried. Checked against preference_threshold, the squared normal
  // quantile at the candidate's level.
  double preference_margin = NAN;
  Effect runner_up = Effect::kAccelQuadratic;
  double preference_threshold = NAN;
  // "" when the magnitudes suffice; else what confirmed it, e.g.
  // "within-pose trends + rotations between poses (delta chi2 3.1 + 41.2,
  // p = 2e-08)".
  std::string confirmed_by;
};

struct DiscoveryStep {
  Effect effect = Effect::kAccelQuadratic;
  EffectEstimate estimate;
  double p_value = NAN;
  double delta_bic = NAN;
  int dof = 0;
  // Which information the decision used (its candidate's `information`),
  // and what confirmed it when the magnitudes alone could not
  // (CandidateScore::confirmed_by).
  std::string information;
  std::string confirmed_by;
  // Of the sensor the effect belongs to (and the other, unchanged).
  Gap gap_before;
  Gap gap_after;
  Gap cv_gap_before;
  Gap cv_gap_after;
  // Where the model before this step disagreed.
  Disagreement where;
  std::vector<CandidateScore> candidates;
  std::vector<Effect> ambiguous_with;
  // For the plot: the effect's regressor per position (temperature, time,
  // or the fitted effect's own contribution for orientation effects), and
  // the residuals before and after (|a| - g in m/s^2; for gyroscope
  // effects the three axes, raw units).
  std::string regressor_name;
  std::vector<double> regressor;
  std::vector<Eigen::Vector3d> residual_before;
  std::vector<Eigen::Vector3d> residual_after;
  // The fitted effect's own contribution to each position's residual (the
  // accelerometer's in component 0): the residual before lies along it,
  // the residual after does not.
  std::vector<Eigen::Vector3d> contribution;
};

struct Ambiguity {
  std::vector<Effect> effects;
  std::vector<double> delta_bic;
  int step = 0;
  std::string advice;
};

// What the run concluded about one sensor, from that sensor's evidence
// alone: its fits, tests, BIC and cross-validation never see the other
// sensor's residuals, so a sensor whose excess no catalogue effect explains
// (an AHRS gyroscope with its own processing) does not mask an effect of
// the other.
struct SensorVerdict {
  EffectSensor sensor = EffectSensor::kAccelerometer;
  // SensorFitSummary::information of the final model's fit of this sensor.
  std::string information;
  // The effects named for this sensor, in order.
  std::vector<Effect> named;
  // How far the final model is from this sensor's data: sqrt(chi2 / dof)
  // (1 = at the noise the positions' samples show), and the chi-square
  // p-value.
  double excess = NAN;
  double p_value = NAN;
  // The final model still leaves more than the noise (p below 1e-3) and no
  // catalogue effect of this sensor was significant in the last round.
  bool unexplained = false;
  // One line, e.g. "gyroscope static means exceed their noise by 11 x; no
  // catalogue effect explains it".
  std::string verdict;
};

struct DiscoveryResult {
  bool success = false;
  std::string source;
  double gravity = kStandardGravity;
  std::string gravity_source;
  std::vector<StaticObservation> observations;
  ModelAssessment baseline;
  Disagreement baseline_where;
  std::vector<DiscoveryStep> steps;
  std::vector<Ambiguity> ambiguous;
  ModelAssessment final_model;
  Disagreement final_where;
  // The scores of the last round, the one in which nothing was significant
  // (empty when stopped by max_steps).
  std::vector<CandidateScore> final_candidates;
  // One per sensor the log has (accelerometer first).
  std::vector<SensorVerdict> sensors;
  // "no significant missing effect" when nothing was named; followed by the
  // sensors' unexplained excess, if any.
  std::string verdict;
  std::vector<std::string> warnings;
  // The code of each warning (core/types.h), same index.
  std::vector<WarningCode> warning_codes;
  // Issue 35: temperature beyond the catalogue's linear terms (higher order,
  // hysteresis), from a raw log with a temperature column (DiscoverEffects).
  ThermalDiscovery thermal;
  double seconds = 0.0;
  std::string message = "Discover was not called";

  // The named effects, in order.
  std::vector<Effect> named() const;
};

// From a raw log: static detection, then DiscoverFromObservations.
// `calibration` gives the detector, gravity, baseline parameterisation and
// nominal axes; `baseline_effects` effects already in the model.
bool DiscoverEffects(const ImuLog& log, const CalibrationOptions& calibration,
                     const std::vector<Effect>& baseline_effects, const DiscoveryOptions& options,
                     DiscoveryResult* result);

// Returns false with a one-line message on invalid options, too few
// positions for the baseline, or a baseline fit that fails; finding
// nothing is a success with verdict "no significant missing effect".
bool DiscoverFromObservations(const std::vector<StaticObservation>& observations,
                              const CalibrationOptions& calibration,
                              const std::vector<Effect>& baseline_effects,
                              const DiscoveryOptions& options, DiscoveryResult* result);

}  // namespace gravcal

#endif  // GRAVCAL_WORKFLOWS_DISCOVERY_H_
