// Private: the set-up shared by the two magnitude fits (Refine, the Ceres
// path, and NewtonRefine, the seed's iteration).
#ifndef GRAVCAL_SRC_ESTIMATION_MAGNITUDE_FIT_H_
#define GRAVCAL_SRC_ESTIMATION_MAGNITUDE_FIT_H_

#include <string>
#include <vector>

#include "estimation/normalization.h"
#include "gravcal/core/accel_model.h"
#include "gravcal/core/position.h"
#include "gravcal/estimation/refinement.h"

namespace gravcal {
namespace internal {

// Sum over positions of (r_k / sigma_k)^2.
double WhitenedSumOfSquares(const std::vector<double>& residuals,
                            const std::vector<double>& sigmas);

// The chi-square verdict both fits give: an exact fit (dof 0), or residuals
// beyond the noise level (p < 1e-3); added to result->warnings.
void WarnOnChiSquare(RefinementResult* result);

// What both fits start from.
struct MagnitudeFitStart {
  // Indices into the 6-vector of U that are free (FreeUpperIndices).
  std::vector<int> free;
  // 3 + free.size().
  int num_parameters = 0;
  int num_positions = 0;
  // The initial model cast to the parameterisation, raw units.
  AccelModel model;
  // The well-conditioned units of the fit (normalization.h), the positions
  // and the initial model in them.
  Normalization norm;
  std::vector<Position> normalized;
  AccelModel normalized_model;
};

// Resets *result; checks gravity and the number of positions for `p`, casts
// `initial` to `p`, and fills result's sigmas, residuals_before,
// initial_cost, num_residuals, num_parameters and parameter_names. On bad
// input returns false with result->message naming `fit` ("refinement",
// "Newton refinement").
bool StartMagnitudeFit(const std::vector<Position>& positions, const AccelModel& initial,
                       double gravity, AccelParameterization p, const std::string& fit,
                       MagnitudeFitStart* start, RefinementResult* result);

// The same, after checking `options` (RefinementOptions or NewtonOptions:
// IsValid and parameterization).
template <typename Options>
bool StartMagnitudeFit(const std::vector<Position>& positions, const AccelModel& initial,
                       double gravity, const Options& options, const std::string& fit,
                       MagnitudeFitStart* start, RefinementResult* result) {
  *result = RefinementResult();
  std::string error;
  if (!options.IsValid(&error)) {
    result->message = error;
    return false;
  }
  return StartMagnitudeFit(positions, initial, gravity, options.parameterization, fit, start,
                           result);
}

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_ESTIMATION_MAGNITUDE_FIT_H_
