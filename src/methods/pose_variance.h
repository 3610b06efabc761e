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
// A variance component must not hide a missing model term, and a prior
// must not make the sigmas dishonest. In order:
//
// 1. The prior, if any, is checked against the residuals. Both fits below
//    are weighted by the white sigmas alone; if the excess is pose-to-pose
//    scatter s^2, a white-weighted residual has variance c = 1 + s^2 h in
//    chi2's units, h = mean_k 1 / sigma_k^2 (exact for equal sigma_k, a
//    fair mean otherwise), so chi2 / c ~ chi2(dof). The prior s0^2 on nu0
//    degrees of freedom, read as an independent estimate of s^2 (nu0 s0^2 /
//    s^2 ~ chi2(nu0): what a scaled inverse chi-square prior states when it
//    is the truth), gives c0 = 1 + s0^2 h, and when s^2 h >> 1
//
//      R = (chi2 / dof) / c0 ~ F(dof, nu0).
//
//    The check uses the exact form of that, the prior predictive tail of
//    chi2 (PriorPredictiveUpperTail, estimation/variance_component.h), which
//    also counts the white part: a prior far below the white noise cannot
//    make chi2 / dof small, and R alone would miss how far off it is.
//    When chi2 lies in the upper tail beyond prior_conflict_level, or in
//    the lower tail beyond a hundredth of it, this recording contradicts the
//    prior: a kPoseScatter warning says so, and the prior is set aside (REML
//    alone, pose_variance.prior_set_aside). The tails differ because the
//    costs do: setting the prior aside for more scatter widens the sigmas
//    (REML with its Student factor), for less scatter it narrows them, and
//    REML alone on three dof then often finds s^2 = 0. At 0.01 on both
//    tails, 3 of 100 simulated hand-placed sessions whose scatter is the
//    prior's set it aside downwards, enough to take u_zz's rms error /
//    sigma over the 100 to 1.66 (tests/property/hand_placed_test.cc). chi2 is taken from
//    the richer fit below when it has residual degrees of freedom (so a
//    missing term is not read as a conflict), else from the fit itself.
//
// 2. Before absorbing the excess, the next richer parameterisation (scale
//    -> scale_misalignment, q = 3 more parameters) is fitted with the same
//    white sigmas and compared by an F test. (chi2_scale - chi2_rich) / c ~
//    chi2(q) independent of chi2_rich / c ~ chi2(dof_rich), and the prior
//    adds nu0 c0 / c ~ chi2(nu0) to the denominator's pool:
//
//      F = ((chi2_scale - chi2_rich) / q)
//          / ((chi2_rich + nu0 c0) / (dof_rich + nu0))  ~  F(q, dof_rich + nu0).
//
//    c cancels, so the test does not depend on the size of the excess. With
//    nu0 = 0 (no prior, or set aside) it is the classical test on dof_rich;
//    the prior gives it power where the poses leave the richer model few
//    degrees of freedom or none (nine poses). The distribution is exact when
//    the prior is the truth and s^2 h >> 1; otherwise the prior's white part
//    1 is a constant where F assumes it random, which makes the denominator
//    steadier than F(q, .) allows and the test slightly conservative. When
//    its upper tail is below structure_test_level, the excess is the
//    non-orthogonality's: nothing is absorbed, the fit's chi-square warning
//    stays, and a warning names the term and points to `gravcal discover`.
//
// 3. Otherwise s^2 is absorbed. When s exceeds max_pose_disturbance a
//    warning says it is implausible for a sensor at rest; else no warning:
//    the scatter is what hand-placed poses show.
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
