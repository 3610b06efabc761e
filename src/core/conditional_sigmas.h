// Private: which undetermined parameters a fit's other standard deviations
// are conditional on (issue 33). When the poses do not determine some terms
// (a null direction, or a standard deviation beyond max_bias_std /
// max_matrix_std), the refinement holds them at the coarse fit's value and
// reports them without a number; every finite standard deviation it reports
// beside them is then conditional on holding them, and each output (the
// calibration JSON, the report, check) labels it so, naming the held terms.
#ifndef GRAVCAL_SRC_CORE_CONDITIONAL_SIGMAS_H_
#define GRAVCAL_SRC_CORE_CONDITIONAL_SIGMAS_H_

#include <string>
#include <vector>

#include "gravcal/core/solver_result.h"

namespace gravcal {
namespace internal {

// The undetermined parameters of `r` when it reports standard deviations for
// the others (then conditional on holding these); empty otherwise.
inline std::vector<std::string> ConditionalOn(const RefinementResult& r) {
  if (!r.covariance_available) return {};
  return r.observability.undetermined;
}

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_CORE_CONDITIONAL_SIGMAS_H_
