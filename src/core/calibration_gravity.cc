#include "core/calibration_gravity.h"

#include <string>

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
    c.warnings.push_back(
        "using standard gravity 9.80665 m/s^2: local gravity differs by up to 0.3 %, which goes "
        "into the scale factors; give gravity, or latitude and height");
  }
  return true;
}

}  // namespace internal
}  // namespace gravcal
