// Private: the set-up shared by the two magnitude fits (Refine, the Ceres
// path, and NewtonRefine, the seed's iteration).
#ifndef GRAVCAL_SRC_ESTIMATION_MAGNITUDE_FIT_H_
#define GRAVCAL_SRC_ESTIMATION_MAGNITUDE_FIT_H_

#include <string>
#include <vector>

#include "gravcal/core/accel_model.h"
#include "gravcal/core/position.h"
#include "gravcal/estimation/refinement.h"

namespace gravcal {

// Sum over positions of (r_k / sigma_k)^2.
double WhitenedSumOfSquares(const std::vector<double>& residuals,
                            const std::vector<double>& sigmas);

// Checks gravity and the number of positions for `p`, casts `initial` to
// `p` into *model, and fills result's sigmas, residuals_before,
// initial_cost, num_residuals, num_parameters and parameter_names. On bad
// input returns false with result->message naming `fit` ("refinement",
// "Newton refinement").
bool StartMagnitudeFit(const std::vector<Position>& positions, const AccelModel& initial,
                       double gravity, AccelParameterization p, const std::string& fit,
                       AccelModel* model, RefinementResult* result);

}  // namespace gravcal

#endif  // GRAVCAL_SRC_ESTIMATION_MAGNITUDE_FIT_H_
