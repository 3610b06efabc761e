// Private: the temperature section of the calibration report (issue 35
// part 6), drawn when the calibration has an active thermal model
// (core/thermal_model.h):
//
// - each active term (bias, scale, misalignment of each sensor) against
//   temperature over the valid range, per component, with its 95 % band
//   (1.96 sigma from the coefficients' covariance; no band where the
//   covariance is missing or a coefficient is undetermined);
// - |a| - g and the gyroscope's output at rest after the whole correction
//   against temperature, every static sample (thinned), heating, cooling and
//   steady stretches in their own colours, beside the same without the
//   thermal model.
#ifndef GRAVCAL_SRC_WORKFLOWS_REPORT_THERMAL_REPORT_H_
#define GRAVCAL_SRC_WORKFLOWS_REPORT_THERMAL_REPORT_H_

#include <string>
#include <vector>

#include "gravcal/core/calibration.h"
#include "gravcal/core/imu_log.h"

namespace gravcal {
namespace internal {

// What the temperature is doing at each sample: the slope of the logged
// temperature over a window centred on it.
enum class ThermalBranch { kSteady, kHeating, kCooling };
// The window (s) and the slope (degC per minute) above which a stretch is
// heating or cooling.
constexpr double kBranchWindowSeconds = 30.0;
constexpr double kBranchSlopePerMinute = 0.2;
// One entry per sample of `log` (all steady without a temperature column).
std::vector<ThermalBranch> ThermalBranches(const ImuLog& log);
// The temperature's rate (degC/s) at each sample over the same window; NaN
// without a temperature column.
std::vector<double> TemperatureRates(const ImuLog& log);

// The section's HTML ("" when the calibration has no active thermal model).
std::string ThermalReportSection(const Calibration& c, const ImuLog& log);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_WORKFLOWS_REPORT_THERMAL_REPORT_H_
