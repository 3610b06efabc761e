#include "gravcal/workflows/thermal_discovery.h"

#include <algorithm>
#include <sstream>

namespace gravcal {

ThermalDiscovery DiscoverThermal(const ImuLog& log, const ThermalCalibrationOptions& given) {
  ThermalDiscovery out;
  if (!log.has_temperature()) {
    out.reason = "the log has no temperature column";
    return out;
  }
  ThermalCalibrationOptions options = given;
  options.accel_bias_max_order = std::min(3, std::max(options.accel_bias_max_order, 3));
  options.gyro_bias_max_order = std::min(3, std::max(options.gyro_bias_max_order, 3));
  options.fit_lag = true;
  // Discovery asks about the bias's order and the lag only: a linear scale
  // term stays available (so that a scale change is not read as curvature),
  // the misalignment search is left to calibrate (it keeps the search short).
  options.accel_scale_max_order = std::min(options.accel_scale_max_order, 1);
  options.accel_misalignment_max_order = 0;
  // Nor does it ask about the gyroscope's scale: no turn fit (its cost is
  // the turns' integration, several times the static fit's).
  options.gyro_scale_max_order = 0;
  options.gyro_scale_order = -1;
  Session session;
  session.log = log;
  Calibration c;
  ThermalFitReport report;
  if (!CalibrateThermal(session, options, &c, &report)) {
    out.reason = c.message;
    return out;
  }
  const ThermalModel& m = c.thermal;
  out.span = m.max_temperature - m.min_temperature;
  out.tried = true;
  out.steps = report.steps;
  out.accel_bias_order = m.accel.bias.order;
  out.accel_scale_order = m.accel.scale.order;
  out.gyro_bias_order = m.gyro.bias.order;
  std::ostringstream s;
  s.precision(3);
  const int highest = std::max(out.accel_bias_order, out.gyro_bias_order);
  if (highest >= 2) {
    out.named.push_back("temperature_higher_order");
    s << "temperature effect of order " << highest << " (accel bias order " << out.accel_bias_order
      << ", gyro bias order " << out.gyro_bias_order << ") over " << out.span
      << " degC: more than the catalogue's linear temperature terms hold; calibrate with "
         "configs/thermal.yaml";
    out.findings.push_back(s.str());
  }
  if (m.lag_estimated) {
    out.lag = true;
    out.lag_time_constant = m.lag_time_constant;
    out.lag_time_constant_std = m.lag_time_constant_std;
    out.named.push_back("thermal_hysteresis");
    std::ostringstream h;
    h.precision(3);
    h << "thermal hysteresis: the heating and cooling branches disagree; the sensing element "
         "lags the temperature sensor by "
      << m.lag_time_constant << " s (std " << m.lag_time_constant_std << " s)";
    out.findings.push_back(h.str());
  }
  return out;
}

}  // namespace gravcal
