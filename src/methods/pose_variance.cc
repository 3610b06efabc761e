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

// REML s^2 from the residuals of `fit`, over its estimated (not held) columns.
bool EstimateFromFit(const std::vector<Position>& placed, const RefinementOptions& options,
                     const RefinementResult& fit, VarianceComponent* vc) {
  const int n = static_cast<int>(placed.size());
  const Eigen::MatrixXd all = MagnitudeJacobian(placed, fit.model, std::vector<double>(n, 1.0));
  std::vector<int> columns;
  for (int i = 0; i < static_cast<int>(fit.parameter_names.size()); ++i) {
    const auto& held = options.held_parameters;
    if (std::find(held.begin(), held.end(), fit.parameter_names[i]) == held.end()) {
      columns.push_back(i);
    }
  }
  Eigen::MatrixXd jacobian(n, columns.size());
  for (size_t i = 0; i < columns.size(); ++i) jacobian.col(i) = all.col(columns[i]);
  const Eigen::VectorXd r = Eigen::Map<const Eigen::VectorXd>(fit.residuals_after.data(), n);
  const Eigen::VectorXd sigmas = Eigen::Map<const Eigen::VectorXd>(fit.sigmas.data(), n);
  VariancePrior prior;
  prior.variance = options.pose_disturbance_prior * options.pose_disturbance_prior;
  prior.dof = options.pose_disturbance_prior_dof;
  return EstimateVarianceComponent(r, sigmas, jacobian, vc, prior);
}

// The F test of the scale model against scale_misalignment (see the
// header). True with `text` naming the term when the richer model explains
// the excess; `tested` false when the richer model cannot be fitted.
bool ExcessIsStructured(const std::vector<Position>& placed, const AccelModel& initial,
                        double gravity, const RefinementOptions& options,
                        const RefinementResult& fit, bool* tested, std::string* text) {
  *tested = false;
  if (options.parameterization != AccelParameterization::kScale) return false;
  RefinementOptions rich = options;
  rich.parameterization = AccelParameterization::kScaleMisalignment;
  rich.estimate_pose_variance = false;
  rich.extra_variance = 0.0;
  RefinementResult r;
  if (!Refine(placed, initial, gravity, rich, &r) || !r.converged || r.dof <= 0 ||
      !r.observability.undetermined.empty() || !(r.chi2 > 0.0)) {
    return false;
  }
  *tested = true;
  const int extra = r.num_parameters - fit.num_parameters;
  const double f = ((fit.chi2 - r.chi2) / extra) / (r.chi2 / r.dof);
  const double p = f > 0.0 ? FUpperTail(f, extra, r.dof) : 1.0;
  if (!(p < options.structure_test_level)) return false;
  std::ostringstream s;
  s.precision(3);
  s << "the excess over the noise is structured, not pose-to-pose scatter: non-orthogonality "
       "(u_xy, u_xz, u_yz, the 'scale_misalignment' model) explains it (chi2 "
    << fit.chi2 << " -> " << r.chi2 << ", F = " << f << " on " << extra << " and " << r.dof
    << " dof, p = " << p
    << "); it is not absorbed as noise and the standard deviations are the white-noise ones: "
       "fit parameterization: scale_misalignment, or run `gravcal discover`";
  *text = s.str();
  return true;
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
  VarianceComponent vc;
  if (!EstimateFromFit(placed, options, *refinement, &vc)) {
    pose_variance->message = "not estimated: " + vc.message;
    return;
  }
  if (vc.at_boundary) {
    *pose_variance = vc;
    return;
  }
  bool tested = false;
  std::string structured;
  if (ExcessIsStructured(placed, initial, gravity, options, *refinement, &tested, &structured)) {
    vc.message += "; not absorbed: a model term explains the excess";
    *pose_variance = vc;
    AddWarning(WarningCode::kResidualsAboveNoise, structured, &refinement->warnings,
               &refinement->warning_codes);
    return;
  }
  RefinementOptions again = options;
  again.extra_variance = vc.variance;
  RefinementResult absorbed;
  if (!Refine(placed, initial, gravity, again, &absorbed) || !absorbed.converged) {
    vc.message += "; not absorbed: the re-weighted fit failed (" + absorbed.message + ")";
    *pose_variance = vc;
    return;
  }
  // s^2 is estimated: error / sigma is Student-t like (variance_component.h).
  double white_variance = 0.0;
  for (double sigma : refinement->sigmas) white_variance += sigma * sigma;
  white_variance /= std::max<size_t>(refinement->sigmas.size(), 1);
  double effective_dof = INFINITY;
  const double inflation = StudentInflation(vc, white_variance, &effective_dof);
  if (absorbed.covariance_available) absorbed.covariance *= inflation;
  absorbed.solve_seconds += refinement->solve_seconds;
  absorbed.iterations += refinement->iterations;
  *refinement = absorbed;
  vc.absorbed = true;
  std::ostringstream t;
  t.precision(3);
  t << "; added to every pose's variance, covariance x " << inflation << " (Student t, "
    << effective_dof << " effective dof)";
  vc.message += t.str() + (tested || options.parameterization != AccelParameterization::kScale
                               ? ""
                               : " (too few poses to test whether non-orthogonality explains it)");
  *pose_variance = vc;
  WarnPoseVariance(vc, effective_dof, options, &refinement->warnings, &refinement->warning_codes);
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
