// estimation/newton_solver.h (private): the seed's hand-written Newton iteration (Chen et
// al. 2012, section 3.1), no Ceres. The baseline the Ceres refinement is
// benchmarked against.
//
// Seed form: f_k = |U (v_k - b)|^2 - g^2 = 0 for every position. Each step
// linearises every f_k at the current estimate (first-order Taylor
// expansion), J dx = -f, and solves for dx by linear least squares (normal
// equations, LDLT); it repeats until |dx| is below tolerance relative to |x|.
// f_k is weighted by 1 / (2 g sigma_k), which to first order is the whitened
// magnitude residual, so both forms have nearly the same optimum; with
// kMagnitude the iteration minimises exactly the Ceres cost
// ((|U (v_k - b)| - g) / sigma_k)^2 and reaches the same optimum.
//
// Same parameterisation as the refinement: b and the free entries of U; the
// rotation of the initial model is kept (the magnitude cannot see it).
#ifndef GRAVCAL_SRC_ESTIMATION_NEWTON_SOLVER_H_
#define GRAVCAL_SRC_ESTIMATION_NEWTON_SOLVER_H_

#include <string>
#include <vector>

#include "gravcal/core/accel_model.h"
#include "gravcal/core/position.h"
#include "gravcal/core/types.h"
#include "gravcal/estimation/refinement.h"

namespace gravcal {
namespace internal {

struct NewtonOptions {
  AccelParameterization parameterization = AccelParameterization::kScaleMisalignment;
  NewtonResidual residual = NewtonResidual::kSquaredMagnitude;
  int max_iterations = 50;
  // Stop when |dx_i| <= tolerance * (|x_i| + tolerance) for every parameter.
  double step_tolerance = 1e-12;
  // Covariance (J^T J)^-1 of the whitened magnitude residuals at the end.
  bool compute_covariance = true;

  bool IsValid(std::string* error) const;
};

// Fills the same result as Refine. Returns false on invalid options or input.
bool NewtonRefine(const std::vector<Position>& positions, const AccelModel& initial, double gravity,
                  const NewtonOptions& options, RefinementResult* result);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_ESTIMATION_NEWTON_SOLVER_H_
