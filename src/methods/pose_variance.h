// Private: the twelve-position method's account of what the samples of each
// pose cannot show (placement disturbances, tremor between poses, mount
// flex, correlated noise): one extra variance s^2 per accelerometer pose,
// estimated by REML from the magnitude residuals of the white-noise fit
// (estimation/variance_component.h), then added to every sigma_k^2 and the
// fit repeated, so every standard deviation carries it, multiplied by the
// Student-t factor nu / (nu - 2) of an estimated variance; with
// pose_disturbance_prior_dof > 0 the estimate leans on the prior s0
// (estimation/variance_component.h). ten_position's step 4 uses it too.
//
// A variance component must not hide a missing model term. Before absorbing
// the excess, the next richer parameterisation (scale -> scale_misalignment)
// is fitted with the same white sigmas and compared by an F test, which does
// not depend on the common scale of the excess:
//
//   F = ((chi2_scale - chi2_rich) / 3) / (chi2_rich / dof_rich) ~ F(3, dof_rich).
//
// When its upper tail is below structure_test_level, the excess is the
// non-orthogonality's: nothing is absorbed, the fit's chi-square warning
// stays, and a warning names the term and points to `gravcal discover`.
// When s exceeds max_pose_disturbance, the excess is absorbed but a warning
// says it is implausible for a sensor at rest. Otherwise no warning: the
// scatter is what hand-placed poses show.
#ifndef GRAVCAL_SRC_METHODS_POSE_VARIANCE_H_
#define GRAVCAL_SRC_METHODS_POSE_VARIANCE_H_

#include <string>
#include <vector>

#include "gravcal/core/position.h"
#include "gravcal/core/solver_result.h"
#include "gravcal/core/types.h"
#include "gravcal/estimation/refinement.h"

namespace gravcal {
namespace internal {

// `refinement` is the converged result of Refine(placed, initial, gravity,
// options); it is replaced by the re-weighted fit when the excess is
// absorbed, and its warnings receive what is said above. `pose_variance`
// receives the estimate (estimated = false when options.estimate_pose_variance
// is off, the fit did not converge or has no degree of freedom).
void AccountForPoseVariance(const std::vector<Position>& placed, const AccelModel& initial,
                            double gravity, const RefinementOptions& options,
                            RefinementResult* refinement, VarianceComponent* pose_variance);

// The warnings on an absorbed s^2 (above): fewer than kMinEffectiveDof
// effective degrees of freedom, and s above options.max_pose_disturbance.
// known_attitude uses them too.
void WarnPoseVariance(const VarianceComponent& vc, double effective_dof,
                      const RefinementOptions& options, std::vector<std::string>* warnings,
                      std::vector<WarningCode>* codes);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_METHODS_POSE_VARIANCE_H_
