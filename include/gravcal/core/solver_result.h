// gravcal/core/solver_result.h: what the estimation steps return, shared by
// the methods and the calibration result: the observability of the magnitude
// model, the coarse fit's result and the refinement's result, with the robust
// loss they can use.
#ifndef GRAVCAL_CORE_SOLVER_RESULT_H_
#define GRAVCAL_CORE_SOLVER_RESULT_H_

#include <Eigen/Core>
#include <cmath>
#include <string>
#include <vector>

#include "gravcal/core/accel_model.h"
#include "gravcal/core/types.h"

namespace gravcal {

struct ObservabilityReport {
  int rank = 0;
  int columns = 0;
  // Singular values of the column-scaled Jacobian, descending.
  Eigen::VectorXd singular_values;
  // Unit null-space directions in parameter space (columns), unscaled.
  Eigen::MatrixXd null_space;
  // Names of the parameters that take part in a null direction.
  std::vector<std::string> undetermined;
  // One line per null direction, e.g. "bias_z - 0.71 u_zz".
  std::vector<std::string> descriptions;
  bool full_rank() const { return rank == columns; }
};

struct CoarseFitResult {
  AccelModel model;
  CoarseMethod method = CoarseMethod::kSixPosition;
  // Nominal up axis used for each position (-1 = none).
  std::vector<int> nominal_up;
  int axis_positions = 0;
  std::string message = "CoarseFit was not called";
};

// One extra variance s^2 added to every residual's variance, for what the
// samples of a pose cannot show (placement disturbances, tremor between
// poses, mount flex, correlated noise), estimated by restricted maximum
// likelihood from the residuals of a fit (estimation/variance_component.h).
struct VarianceComponent {
  bool estimated = false;
  // s^2 and its standard deviation (from the expected restricted
  // information), in the residual's unit squared (for the accelerometer
  // magnitude fit (m/s^2)^2). s^2 = 0 when the residuals show no excess over
  // their sigmas (then at_boundary).
  double variance = 0.0;
  double variance_std = NAN;
  bool at_boundary = true;
  // Residual degrees of freedom n - rank(J) the estimate rests on.
  int dof = 0;
  // True when s^2 was added to every residual's variance and the fit
  // repeated, so every standard deviation carries it; false when the excess
  // was left unexplained (a structured term explains it, or s^2 = 0).
  bool absorbed = false;
  // True when a prior on s^2 was configured but the residuals conflict with
  // it (methods/pose_variance.h): the estimate is then REML alone.
  bool prior_set_aside = false;
  std::string message = "EstimateVarianceComponent was not called";
};

// What every least-squares solve of the library reports about itself, and
// the covariance of its free parameters. The methods' results extend it.
struct LeastSquaresSummary {
  bool converged = false;
  int iterations = 0;
  // The solver's own word on why it stopped.
  std::string termination;
  double solve_seconds = 0.0;
  int num_residuals = 0;
  int num_parameters = 0;
  // Sum of squared whitened residuals and its degrees of freedom: chi2 / dof
  // near 1 means the sigmas and the model fit the data.
  double chi2 = 0.0;
  int dof = 0;
  // Covariance of the free parameters, in parameter_names order.
  bool covariance_available = false;
  Eigen::MatrixXd covariance;
  std::vector<std::string> parameter_names;
};

// The magnitude fit: num_parameters is 6 or 9.
struct RefinementResult : LeastSquaresSummary {
  AccelModel model;
  // 0.5 * sum of squared whitened residuals (before any loss).
  double initial_cost = 0.0;
  double final_cost = 0.0;
  ObservabilityReport observability;
  // Per position: |a_k| - g before (initial model) and after, m/s^2, and
  // the sigma used.
  std::vector<double> residuals_before;
  std::vector<double> residuals_after;
  std::vector<double> sigmas;
  std::vector<std::string> warnings;
  // The code of each warning (same index).
  std::vector<WarningCode> warning_codes;
  std::string message = "Refine was not called";
};

}  // namespace gravcal

#endif  // GRAVCAL_CORE_SOLVER_RESULT_H_
