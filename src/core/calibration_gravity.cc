#include "core/calibration_gravity.h"

#include <string>

#include "core/warnings.h"

namespace gravcal {
namespace internal {

bool ResolveCalibrationGravity(const GravityOptions& options, Calibration* calibration) {
  Calibration& c = *calibration;
  std::string error;
  if (!ResolveGravity(options, &c.gravity, &c.gravity_source, &error)) {
    c.message = error;
    return false;
  }
  if (c.gravity_source == "standard") {
    internal::AddWarning(
        WarningCode::kStandardGravity,
        "using standard gravity 9.80665 m/s^2: local gravity differs by up to 0.3 %, which goes "
        "into the scale factors; give gravity, or latitude and height",
        &c.warnings, &c.warning_codes);
  }
  return true;
}

}  // namespace internal
}  // namespace gravcal
