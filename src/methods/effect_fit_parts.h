// methods/effect_fit_parts.h: the parts of the effect fit (effect_fit.h)
// that live in their own files: the accelerometer fit
// (effect_fit_accel.cc), the gyroscope fit (effect_fit_gyro.cc) and the REML
// of the magnitudes' extra variance (effect_fit_reml.cc); effect_fit.cc
// joins them. The observations are made in effect_fit_observations.cc.
#ifndef GRAVCAL_SRC_METHODS_EFFECT_FIT_PARTS_H_
#define GRAVCAL_SRC_METHODS_EFFECT_FIT_PARTS_H_

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "gravcal/methods/effect_fit.h"

namespace gravcal {
namespace internal {

// Relative tolerance of the rank test on the scaled whitened Jacobian: a
// direction this weak (condition number 1e7) is not determined in practice.
constexpr double kEffectFitRankTolerance = 1e-7;

// Columns of the gyroscope's nuisance parameters (b_g' 3, M_g' 9) with the
// rotations between poses.
constexpr int kRotationGyroColumns = 12;

ceres::Solver::Options EffectFitSolverOptions(const EffectFitOptions& o);

// (J^T J)^-1 of a whitened Jacobian, with the undetermined parameters (null
// space) named and their rows and columns NaN; the rest from the
// pseudo-inverse. Also the leverage of each position (rows_per_position
// consecutive rows among the first leverage_rows).
void CovarianceFromJacobian(const Eigen::MatrixXd& jacobian, int rows_per_position,
                            int leverage_rows, SensorFitSummary* fit);

// Inverse of the lower Cholesky factor of a covariance (NaN when it has
// none).
Eigen::Matrix3d InverseCholesky(const Eigen::Matrix3d& covariance);

// With a robust loss rho (options.loss at options.loss_scale): the rows of
// each residual block (block_rows[i] consecutive rows of `jacobian` and
// `residual_rows`, in block order) times sqrt(rho'(|r|^2)), the weight
// iteratively reweighted least squares gives the block at the optimum, so
// the covariance counts a block the loss set aside as the solve did.
void WeightRowsByLoss(const std::vector<int>& block_rows, const EffectFitOptions& options,
                      Eigen::MatrixXd* jacobian, Eigen::VectorXd* residual_rows);

// A problem that owns neither its cost functions nor its loss (the fit keeps
// them to evaluate again), and the loss of a graduated solve at its first
// scale: options.loss at first_scale behind a wrapper whose scale the
// later steps of the solve lower; nullptr with no loss.
ceres::Problem::Options ProblemKeepingOwnership();
std::unique_ptr<ceres::LossFunctionWrapper> GraduatedLoss(const EffectFitOptions& options,
                                                          double first_scale);

// Solves `problem` once per loss scale of `scales`, widest first (one solve
// without a loss), `loss` (may be null) set to each in turn, with the
// effects' block (block_size values) held as effect_free / effect_held say:
// constant when none is free, else its held entries fixed. Fills
// fit->iterations and fit->converged; the summary of the last solve.
ceres::Solver::Summary SolveGraduated(const EffectFitOptions& options,
                                      const std::vector<double>& scales, double* effect_block,
                                      int block_size, const std::vector<int>& effect_free,
                                      const std::vector<int>& effect_held,
                                      ceres::LossFunctionWrapper* loss, ceres::Problem* problem,
                                      SensorFitSummary* fit);

// The accelerometer part, in normalised raw units (normalization.h), with
// `extra_variance` added to every magnitude's sigma_k^2; the whitened
// Jacobian and residuals at the optimum (magnitude rows first) for the REML.
bool FitAccel(const std::vector<StaticObservation>& observations, const AccelModel& initial,
              const EffectParameters& initial_parameters, double gravity,
              const EffectFitOptions& options, double extra_variance,
              Eigen::MatrixXd* whitened_jacobian, Eigen::VectorXd* whitened_residuals,
              EffectFitResult* result);

// estimate_pose_variance: the REML of one extra variance of the
// magnitudes from the fit in *result (its whitened Jacobian and
// residuals), and, when it is positive, the refit with it and the Student
// inflation of the covariance. False (with result->message) when the refit
// fails.
bool AbsorbMagnitudeVariance(const std::vector<StaticObservation>& observations,
                             const AccelModel& initial, const EffectParameters& initial_parameters,
                             double gravity, const EffectFitOptions& options,
                             Eigen::MatrixXd* jacobian, Eigen::VectorXd* residuals,
                             EffectFitResult* result);

// The gyroscope part: b_g and the gyroscope effects from the static mean
// rates and the fitted forces (result->forces).
bool FitGyro(const std::vector<StaticObservation>& observations, const GyroModel& initial_gyro,
             const EffectParameters& initial_parameters, const EffectFitOptions& options,
             EffectFitResult* result);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_METHODS_EFFECT_FIT_PARTS_H_
