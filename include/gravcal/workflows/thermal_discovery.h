// gravcal/workflows/thermal_discovery.h: what `gravcal discover` says about
// temperature beyond the effect catalogue's linear terms (issue 35 part 7).
//
// When the log has a temperature column spanning at least
// ThermalMinimumSpan(1) over its static poses, the thermal calibration
// (methods/thermal_calibration.h) searches each bias term's order (up to 3),
// a linear scale term and the element's lag by BIC, as `calibrate` with
// configs/thermal.yaml would. Two findings can be named:
// - "temperature_higher_order": a bias term of order 2 or more is chosen,
//   more than the catalogue's linear accel_temperature_bias /
//   gyro_temperature_bias can represent;
// - "thermal_hysteresis": the lag term is chosen, the heating and cooling
//   branches disagree (the sensing element lags the temperature sensor by
//   tau).
#ifndef GRAVCAL_WORKFLOWS_THERMAL_DISCOVERY_H_
#define GRAVCAL_WORKFLOWS_THERMAL_DISCOVERY_H_

#include <cmath>
#include <string>
#include <vector>

#include "gravcal/core/imu_log.h"
#include "gravcal/core/thermal_model.h"
#include "gravcal/methods/thermal_calibration.h"

namespace gravcal {

struct ThermalDiscovery {
  // Whether the search ran; `reason` says why not (no temperature column,
  // span too small, too few windows).
  bool tried = false;
  std::string reason;
  double span = NAN;
  // The orders chosen and the lag.
  int accel_bias_order = 0;
  int accel_scale_order = 0;
  int gyro_bias_order = 0;
  bool lag = false;
  double lag_time_constant = NAN;
  double lag_time_constant_std = NAN;
  // "temperature_higher_order", "thermal_hysteresis" (see above).
  std::vector<std::string> named;
  // One sentence per finding, and the search's steps.
  std::vector<std::string> findings;
  std::vector<std::string> steps;
};

// Runs the search on `log` with `options` (its detector, gravity and
// nominal scales). Never fails: a log the search cannot use gives
// tried = false with the reason.
ThermalDiscovery DiscoverThermal(const ImuLog& log, const ThermalCalibrationOptions& options);

}  // namespace gravcal

#endif  // GRAVCAL_WORKFLOWS_THERMAL_DISCOVERY_H_
