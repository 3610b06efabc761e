// gravcal/estimation/refinement.h: the fine step, a Ceres fit of the gravity magnitude.
//
// Minimises sum_k rho( r_k^2 ) over the bias b and the upper-triangular U,
// with r_k the GravityMagnitudeResidual of each static position
// (gravity_magnitude_residual.h) and rho an optional robust loss. The
// rotation R of the initial model is kept: the magnitude cannot see it
// (docs/methods.md section 1; the 12-parameter system of the seed is singular in
// three directions). sigma_k is computed once, at the initial model, from the
// position's covariance of the mean:
//
//   sigma_k^2 = u_k^T U C_k U^T u_k,   u_k = U (v_k - b) / |U (v_k - b)|,
//
// C_k the covariance of the mean raw vector.
//
// The covariance of (b, free entries of U) is (J^T J)^-1 at the optimum
// (ceres::Covariance), valid when the sigmas are right; chi2 / dof tells if
// they are. Parameters in the null space of J are reported as undetermined.
#ifndef GRAVCAL_ESTIMATION_REFINEMENT_H_
#define GRAVCAL_ESTIMATION_REFINEMENT_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "gravcal/core/accel_model.h"
#include "gravcal/core/position.h"
#include "gravcal/core/solver_result.h"
#include "gravcal/estimation/fit_settings.h"
#include "gravcal/estimation/observability.h"
#include "gravcal/estimation/solver_tolerances.h"

namespace gravcal {

// The shared settings (fit_settings.h: parameterization, the robust loss on
// the whitened residuals, compute_covariance, the pose variance) and the
// refinement's own.
struct RefinementOptions : AccelFitSettings {
  // A parameter whose standard deviation exceeds these is reported as not
  // determined by the positions (no number): bias in m/s^2, entries of U
  // relative to the mean scale factor.
  double max_bias_std = 0.1;
  double max_matrix_std = 0.01;
  // Parameters held at their initial value (names as in
  // MagnitudeParameterNames, e.g. "u_xy"). When the solve does not converge
  // because the positions do not determine some parameters, those are added
  // here and the fit is repeated, so a flat direction does not stall the
  // solver; they are reported as undetermined.
  std::vector<std::string> held_parameters;
  // Added to every sigma_k^2 (m/s^2)^2: the per-pose variance the samples
  // cannot show (methods/pose_variance.h sets it; 0 = white noise only).
  double extra_variance = 0.0;
  // estimate_pose_variance (PoseVarianceOptions): estimate that variance by
  // REML and absorb it (twelve_position, ceres), with the prior
  // pose_disturbance_prior on pose_disturbance_prior_dof. Off by default
  // until it is validated on repeated real recordings (see docs/methods.md):
  // on the real sessions it grows the sigmas 5-8 times; warn when its s
  // exceeds max_pose_disturbance (m/s^2), or when a richer model explains
  // the excess at structure_test_level (then not absorbed).
  double max_pose_disturbance = 0.01;
  double structure_test_level = 1e-3;
  // The prior is set aside (REML alone, with a warning) when the residuals
  // scatter more than it allows beyond this level, or less beyond a
  // hundredth of it (methods/pose_variance.h): a prior this recording
  // contradicts must not size its sigmas.
  double prior_conflict_level = 0.01;
  // Stopping rules of the solve (max_iterations 100, tolerances 1e-14, 1e-14,
  // 1e-12).
  SolverTolerances solver;

  bool IsValid(std::string* error) const;
};

// sigma_k of every position at `model` (see above), m/s^2.
std::vector<double> MagnitudeSigmas(const std::vector<Position>& positions,
                                    const AccelModel& model);

// Names of the free magnitude parameters of a parameterisation, in the order
// used by covariances: bias_x, bias_y, bias_z, then u_xx, u_xy, u_xz, u_yy,
// u_yz, u_zz (only u_xx, u_yy, u_zz for kScale).
std::vector<std::string> MagnitudeParameterNames(AccelParameterization p);

// Indices into the 6-vector of U that are free for `p`.
std::vector<int> FreeUpperIndices(AccelParameterization p);

// Whitened Jacobian of r_k with respect to the free parameters (analytic).
Eigen::MatrixXd MagnitudeJacobian(const std::vector<Position>& positions, const AccelModel& model,
                                  const std::vector<double>& sigmas);

// |a_k| - g for every position.
std::vector<double> MagnitudeResiduals(const std::vector<Position>& positions,
                                       const AccelModel& model, double gravity);

// Refines `initial` (from the coarse fit). With a robust loss the solve is
// graduated: it starts with the loss scale wide enough to hold every initial
// residual (nearly least squares) and halves it down to loss_scale, so a
// poor start does not lock the fit into a wrong basin. Returns false on invalid options
// or input; a fit that does not converge returns true with converged = false
// and the message saying so. The result's model keeps initial.rotation.
bool Refine(const std::vector<Position>& positions, const AccelModel& initial, double gravity,
            const RefinementOptions& options, RefinementResult* result);

}  // namespace gravcal

#endif  // GRAVCAL_ESTIMATION_REFINEMENT_H_
