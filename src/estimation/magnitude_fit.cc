#include "estimation/magnitude_fit.h"

#include <cmath>
#include <sstream>

#include "core/warnings.h"
#include "util/statistics.h"

namespace gravcal {
namespace internal {

double WhitenedSumOfSquares(const std::vector<double>& residuals,
                            const std::vector<double>& sigmas) {
  double s = 0.0;
  for (size_t k = 0; k < residuals.size(); ++k) {
    const double w = residuals[k] / sigmas[k];
    s += w * w;
  }
  return s;
}

bool StartMagnitudeFit(const std::vector<Position>& positions, const AccelModel& initial,
                       double gravity, AccelParameterization p, const std::string& fit,
                       MagnitudeFitStart* start, RefinementResult* result) {
  *result = RefinementResult();
  if (!(gravity > 0.0)) {
    result->message = "gravity must be positive";
    return false;
  }
  const std::vector<int> free = FreeUpperIndices(p);
  const int num_parameters = 3 + static_cast<int>(free.size());
  const int n = static_cast<int>(positions.size());
  if (n < num_parameters) {
    std::ostringstream s;
    s << fit << " of '" << ToString(p) << "' needs at least " << num_parameters
      << " static positions, found " << n;
    result->message = s.str();
    return false;
  }
  AccelModel* model = &start->model;
  *model = initial;
  model->parameterization = p;
  if (p == AccelParameterization::kScale) {
    model->upper(0, 1) = model->upper(0, 2) = model->upper(1, 2) = 0.0;
  }
  result->sigmas = MagnitudeSigmas(positions, *model);
  for (int k = 0; k < n; ++k) {
    if (!(result->sigmas[k] > 0.0) || !std::isfinite(result->sigmas[k])) {
      std::ostringstream s;
      s << "position " << k << " has no usable noise estimate (sigma = " << result->sigmas[k]
        << "); it needs more than one sample";
      result->message = s.str();
      return false;
    }
  }
  result->residuals_before = MagnitudeResiduals(positions, *model, gravity);
  result->initial_cost = 0.5 * WhitenedSumOfSquares(result->residuals_before, result->sigmas);
  result->num_residuals = n;
  result->num_parameters = num_parameters;
  result->parameter_names = MagnitudeParameterNames(p);
  start->free = free;
  start->num_parameters = num_parameters;
  start->num_positions = n;
  start->norm = Normalization::For(*model);
  start->normalized = start->norm.Apply(positions);
  start->normalized_model = start->norm.Apply(*model);
  return true;
}

// The chi-square verdict: an exact fit, or residuals beyond the noise level.
void WarnOnChiSquare(RefinementResult* result) {
  if (result->dof <= 0) {
    internal::AddWarning(WarningCode::kExactFit,
                         "as many positions as parameters: the fit is exact and cannot show "
                         "whether the model or the noise estimate is right; record more positions",
                         &result->warnings, &result->warning_codes);
    return;
  }
  const double p_value = ChiSquareUpperTail(result->chi2, result->dof);
  if (p_value < 1e-3) {
    std::ostringstream s;
    s.precision(3);
    s << "residuals are " << std::sqrt(result->chi2 / result->dof)
      << " times the noise level (chi2 = " << result->chi2 << " on " << result->dof
      << " dof, p = " << p_value
      << "): the model misses an effect, a position was disturbed, or the noise is correlated; "
         "the standard deviations are too small by about that factor";
    internal::AddWarning(WarningCode::kResidualsAboveNoise, s.str(), &result->warnings,
                         &result->warning_codes);
  }
}

}  // namespace internal
}  // namespace gravcal
