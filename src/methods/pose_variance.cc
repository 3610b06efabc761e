#include "methods/pose_variance.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/warnings.h"
#include "estimation/variance_component.h"
#include "util/statistics.h"

namespace gravcal {
namespace internal {

namespace {

// The configured prior on s^2 (estimation/variance_component.h).
VariancePrior ConfiguredPrior(const RefinementOptions& options) {
  VariancePrior prior;
  prior.variance = options.pose_disturbance_prior * options.pose_disturbance_prior;
  prior.dof = options.pose_disturbance_prior_dof;
  return prior;
}

// The lower tail's level is this times prior_conflict_level (header).
constexpr double kLessScatterLevelFactor = 0.01;

// h = mean_k 1 / sigma_k^2: s^2 in a white-weighted chi2's units (header).
double MeanInverseVariance(const std::vector<double>& sigmas) {
  double h = 0.0;
  for (double sigma : sigmas) h += 1.0 / (sigma * sigma);
  return h / std::max<size_t>(sigmas.size(), 1);
}

// REML s^2 from the residuals of `fit`, over its estimated columns (not
// those held by the options, nor the undetermined ones the fit held).
bool EstimateFromFit(const std::vector<Position>& placed, const RefinementOptions& options,
                     const RefinementResult& fit, const VariancePrior& prior,
                     VarianceComponent* vc) {
  const int n = static_cast<int>(placed.size());
  const Eigen::MatrixXd all = MagnitudeJacobian(placed, fit.model, std::vector<double>(n, 1.0));
  std::vector<int> columns;
  auto listed = [](const std::vector<std::string>& list, const std::string& name) {
    return std::find(list.begin(), list.end(), name) != list.end();
  };
  for (int i = 0; i < static_cast<int>(fit.parameter_names.size()); ++i) {
    const std::string& name = fit.parameter_names[i];
    // The terms the fit held as undetermined (held at a value: no variance).
    const bool held_weak = listed(fit.observability.undetermined, name) &&
                           fit.covariance_available && i < fit.covariance.rows() &&
                           fit.covariance(i, i) == 0.0;
    if (!listed(options.held_parameters, name) && !held_weak) {
      columns.push_back(i);
    }
  }
  Eigen::MatrixXd jacobian(n, columns.size());
  for (size_t i = 0; i < columns.size(); ++i) jacobian.col(i) = all.col(columns[i]);
  const Eigen::VectorXd r = Eigen::Map<const Eigen::VectorXd>(fit.residuals_after.data(), n);
  const Eigen::VectorXd sigmas = Eigen::Map<const Eigen::VectorXd>(fit.sigmas.data(), n);
  return EstimateVarianceComponent(r, sigmas, jacobian, vc, prior);
}

// The next richer parameterisation (scale -> scale_misalignment) fitted
// with the white sigmas; false when there is none or it cannot be fitted
// (it may be exact: dof 0).
bool FitRicherModel(const std::vector<Position>& placed, const AccelModel& initial, double gravity,
                    const RefinementOptions& options, RefinementResult* rich) {
  if (options.parameterization != AccelParameterization::kScale) return false;
  RefinementOptions o = options;
  o.parameterization = AccelParameterization::kScaleMisalignment;
  o.estimate_pose_variance = false;
  o.extra_variance = 0.0;
  return Refine(placed, initial, gravity, o, rich) && rich->converged && rich->dof >= 0 &&
         rich->observability.undetermined.empty() && rich->chi2 >= 0.0 &&
         rich->sigmas.size() == placed.size();
}

// Step 1 of the header: true (with `text`) when `judged`'s residuals
// contradict the prior, so it must be set aside.
bool PriorConflicts(const RefinementResult& judged, bool richer, const VariancePrior& prior,
                    double level, std::string* text) {
  if (!(prior.dof > 0.0) || judged.dof < 1) return false;
  const double h = MeanInverseVariance(judged.sigmas);
  const double above = PriorPredictiveUpperTail(judged.chi2, judged.dof, prior, h);
  const double below = 1.0 - above;
  // Less scatter than the prior needs stronger evidence (header).
  if (!(above < level) && !(below < kLessScatterLevelFactor * level)) return false;
  std::ostringstream s;
  s.precision(3);
  s << "the poses scatter " << (above < below ? "far more" : "far less")
    << " than the pose-disturbance prior allows (chi2 / dof = " << judged.chi2 / judged.dof
    << " on " << judged.dof << " dof" << (richer ? " with non-orthogonality" : "")
    << " against about " << 1.0 + prior.variance * h << " for s0 = " << std::sqrt(prior.variance)
    << " m/s^2 on " << prior.dof << " dof, p = " << std::min(above, below) << " < "
    << (above < below ? level : kLessScatterLevelFactor * level)
    << "): the prior is set aside and the standard deviations rest on this recording's own "
       "scatter; set pose_disturbance_prior to what this setup scatters by";
  *text = s.str();
  return true;
}

// Step 2 of the header: true with `text` naming the term when the richer
// model explains the excess; *tested false when the test has no degrees of
// freedom.
bool ExcessIsStructured(const RefinementResult& fit, const RefinementResult& rich,
                        const VariancePrior& prior, double level, bool* tested, std::string* text) {
  const double pooled_dof = rich.dof + prior.dof;
  *tested = pooled_dof > 0.0;
  if (!*tested) return false;
  const double pooled = prior.dof * (1.0 + prior.variance * MeanInverseVariance(rich.sigmas));
  const int extra = rich.num_parameters - fit.num_parameters;
  const double f = ((fit.chi2 - rich.chi2) / extra) / ((rich.chi2 + pooled) / pooled_dof);
  const double p = f > 0.0 ? FUpperTail(f, extra, pooled_dof) : 1.0;
  if (!(p < level)) return false;
  std::ostringstream s;
  s.precision(3);
  s << "the excess over the noise is structured, not pose-to-pose scatter: non-orthogonality "
       "(u_xy, u_xz, u_yz, the 'scale_misalignment' model) explains it (chi2 "
    << fit.chi2 << " -> " << rich.chi2 << ", F = " << f << " on " << extra << " and " << pooled_dof
    << " dof";
  if (prior.dof > 0.0) s << " (" << rich.dof << " + the prior's " << prior.dof << ")";
  s << ", p = " << p
    << "); it is not absorbed as noise and the standard deviations are the white-noise ones: "
       "fit parameterization: scale_misalignment, or run `gravcal discover`";
  *text = s.str();
  return true;
}

// Re-solves with s^2 added to every variance and the Student factor on the
// covariance; false (vc->message says why) when the re-weighted fit fails.
bool Absorb(const std::vector<Position>& placed, const AccelModel& initial, double gravity,
            const RefinementOptions& options, RefinementResult* refinement, VarianceComponent* vc,
            double* effective_dof) {
  RefinementOptions again = options;
  again.extra_variance = vc->variance;
  RefinementResult absorbed;
  if (!Refine(placed, initial, gravity, again, &absorbed) || !absorbed.converged) {
    vc->message += "; not absorbed: the re-weighted fit failed (" + absorbed.message + ")";
    return false;
  }
  // s^2 is estimated: error / sigma is Student-t like (variance_component.h).
  double white_variance = 0.0;
  for (double sigma : refinement->sigmas) white_variance += sigma * sigma;
  white_variance /= std::max<size_t>(refinement->sigmas.size(), 1);
  const double inflation = StudentInflation(*vc, white_variance, effective_dof);
  if (absorbed.covariance_available) absorbed.covariance *= inflation;
  absorbed.solve_seconds += refinement->solve_seconds;
  absorbed.iterations += refinement->iterations;
  *refinement = absorbed;
  vc->absorbed = true;
  std::ostringstream t;
  t.precision(3);
  t << "; added to every pose's variance, covariance x " << inflation << " (Student t, "
    << *effective_dof << " effective dof)";
  vc->message += t.str();
  return true;
}

// Steps 2 and 3 of the header for an estimated s^2 > 0 (`prior` as used).
void ExplainOrAbsorb(const std::vector<Position>& placed, const AccelModel& initial, double gravity,
                     const RefinementOptions& options, const RefinementResult* rich,
                     const VariancePrior& prior, RefinementResult* refinement,
                     VarianceComponent* vc) {
  bool tested = false;
  std::string structured;
  if (rich != nullptr && ExcessIsStructured(*refinement, *rich, prior, options.structure_test_level,
                                            &tested, &structured)) {
    vc->message += "; not absorbed: a model term explains the excess";
    AddWarning(WarningCode::kResidualsAboveNoise, structured, &refinement->warnings,
               &refinement->warning_codes);
    return;
  }
  double effective_dof = INFINITY;
  if (!Absorb(placed, initial, gravity, options, refinement, vc, &effective_dof)) return;
  if (!tested && options.parameterization == AccelParameterization::kScale) {
    vc->message += " (too few poses to test whether non-orthogonality explains it)";
  }
  WarnPoseVariance(*vc, effective_dof, options, &refinement->warnings, &refinement->warning_codes);
}

}  // namespace

void AccountForPoseVariance(const std::vector<Position>& placed, const AccelModel& initial,
                            double gravity, const RefinementOptions& options,
                            RefinementResult* refinement, VarianceComponent* pose_variance) {
  CHECK(refinement != nullptr && pose_variance != nullptr);
  *pose_variance = VarianceComponent();
  if (!options.estimate_pose_variance) {
    pose_variance->message = "not estimated (pose_variance: false)";
    return;
  }
  if (!refinement->converged || refinement->residuals_after.size() != placed.size()) {
    pose_variance->message = "not estimated: the fit did not converge";
    return;
  }
  RefinementResult rich;
  const bool has_rich = FitRicherModel(placed, initial, gravity, options, &rich);
  const bool judge_rich = has_rich && rich.dof >= 1;
  VariancePrior prior = ConfiguredPrior(options);
  std::string conflict;
  const bool set_aside = PriorConflicts(judge_rich ? rich : *refinement, judge_rich, prior,
                                        options.prior_conflict_level, &conflict);
  if (set_aside) prior = VariancePrior();
  VarianceComponent vc;
  if (!EstimateFromFit(placed, options, *refinement, prior, &vc)) {
    pose_variance->message = "not estimated: " + vc.message;
    return;
  }
  if (!vc.at_boundary) {
    ExplainOrAbsorb(placed, initial, gravity, options, has_rich ? &rich : nullptr, prior,
                    refinement, &vc);
  }
  if (set_aside) {
    vc.prior_set_aside = true;
    vc.message += "; the prior is set aside (it conflicts with these residuals)";
    AddWarning(WarningCode::kPoseScatter, conflict, &refinement->warnings,
               &refinement->warning_codes);
  }
  *pose_variance = vc;
}

void WarnPoseVariance(const VarianceComponent& vc, double effective_dof,
                      const RefinementOptions& options, std::vector<std::string>* warnings,
                      std::vector<WarningCode>* codes) {
  if (effective_dof < kMinEffectiveDof) {
    std::ostringstream w;
    w.precision(3);
    w << "the pose-to-pose scatter rests on " << effective_dof
      << " effective degrees of freedom (fewer than " << kMinEffectiveDof
      << "): the standard deviations are themselves uncertain by a large factor; more poses "
         "would tell";
    AddWarning(WarningCode::kPoseScatter, w.str(), warnings, codes);
  }
  const double s = std::sqrt(vc.variance);
  if (s > options.max_pose_disturbance) {
    std::ostringstream w;
    w.precision(3);
    w << "the poses scatter by s = " << s
      << " m/s^2 beyond what their samples show, more than max_pose_disturbance = "
      << options.max_pose_disturbance
      << " m/s^2 for a sensor at rest: a pose was disturbed or the model misses an effect (run "
         "`gravcal discover`); the standard deviations include the scatter";
    AddWarning(WarningCode::kPoseScatter, w.str(), warnings, codes);
  }
}

}  // namespace internal
}  // namespace gravcal
