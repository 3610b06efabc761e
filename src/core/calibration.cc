#include "gravcal/core/calibration.h"

#include "util/statistics.h"

namespace gravcal {

using internal::MaxAbs;
using internal::Rms;

ResidualSummary SummarizeResiduals(const std::vector<double>& residuals) {
  return {Rms(residuals), MaxAbs(residuals)};
}

}  // namespace gravcal
