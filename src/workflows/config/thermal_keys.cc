// Config section "thermal": the thermal calibration (issue 35,
// ThermalCalibrationOptions, methods/thermal_calibration.h), method
// `thermal`.
#include <cmath>

#include "workflows/config/config_key.h"

namespace gravcal {
namespace internal {

SectionOf<CalibrationConfig> ThermalSection() {
  return {
      "thermal",
      ConfigSectionUse::kSomeMethods,
      {
          GRAVCAL_INT("thermal_accel_bias_max_order", thermal.accel_bias_max_order,
                      "largest order of the accelerometer bias(T) searched (0 = off)"),
          GRAVCAL_INT("thermal_accel_scale_max_order", thermal.accel_scale_max_order,
                      "largest order of the accelerometer scale(T) searched (0 = off)"),
          GRAVCAL_INT("thermal_accel_misalignment_max_order", thermal.accel_misalignment_max_order,
                      "largest order of the accelerometer misalignment(T) searched (0 = off)"),
          GRAVCAL_INT("thermal_gyro_bias_max_order", thermal.gyro_bias_max_order,
                      "largest order of the gyroscope bias(T) searched (0 = off)"),
          GRAVCAL_INT("thermal_gyro_scale_max_order", thermal.gyro_scale_max_order,
                      "largest order of the gyroscope scale(T) from the turns (0 = off)"),
          GRAVCAL_INT("thermal_gyro_misalignment_max_order", thermal.gyro_misalignment_max_order,
                      "largest order of the gyroscope misalignment(T) from the turns (0 = off)"),
          GRAVCAL_INT("thermal_accel_bias_order", thermal.accel_bias_order,
                      "fixed order of the accelerometer bias(T); -1 = chosen from the data"),
          GRAVCAL_INT("thermal_accel_scale_order", thermal.accel_scale_order,
                      "fixed order of the accelerometer scale(T); -1 = chosen from the data"),
          GRAVCAL_INT("thermal_accel_misalignment_order", thermal.accel_misalignment_order,
                      "fixed order of the accelerometer misalignment(T); -1 = from the data"),
          GRAVCAL_INT("thermal_gyro_bias_order", thermal.gyro_bias_order,
                      "fixed order of the gyroscope bias(T); -1 = chosen from the data"),
          GRAVCAL_INT("thermal_gyro_scale_order", thermal.gyro_scale_order,
                      "fixed order of the gyroscope scale(T); -1 = chosen from the data"),
          GRAVCAL_INT("thermal_gyro_misalignment_order", thermal.gyro_misalignment_order,
                      "fixed order of the gyroscope misalignment(T); -1 = from the data"),
          GRAVCAL_BOOL("thermal_lag", thermal.fit_lag,
                       "try a first-order lag of the sensing element behind the temperature"),
          GRAVCAL_ENUM("thermal_selection", thermal.selection,
                       "information criterion that chooses the orders"),
          GRAVCAL_DOUBLE("thermal_reference_temperature", thermal.reference_temperature,
                         "T_ref of the polynomials, degC; null = the middle of the range"),
          GRAVCAL_DOUBLE("thermal_window_seconds", thermal.window_seconds,
                         "longest window a static pose is cut into, s"),
          GRAVCAL_DOUBLE("thermal_max_window_temperature_change",
                         thermal.max_window_temperature_change,
                         "largest temperature change within one window, degC"),
          GRAVCAL_DOUBLE("thermal_min_information", thermal.min_information,
                         "information below which a parameter is reported undetermined"),
      }};
}

namespace {

bool ReadTemperatures(const YAML::Node& n, std::vector<double>* v, std::string* e) {
  if (!n.IsSequence() || n.size() == 0) {
    *e = "must be a list of temperatures in degC, e.g. [-10, 5, 20, 35, 50]";
    return false;
  }
  std::vector<double> out;
  for (const YAML::Node& item : n) {
    double t = 0.0;
    if (!ReadDouble(item, &t, e) || !std::isfinite(t)) {
      *e = "must be a list of temperatures in degC, e.g. [-10, 5, 20, 35, 50]";
      return false;
    }
    out.push_back(t);
  }
  *v = out;
  return true;
}

std::string TemperaturesText(const std::vector<double>& v) {
  std::string out = "[";
  for (size_t i = 0; i < v.size(); ++i) out += (i ? ", " : "") + DoubleText(v[i]);
  return out + "]";
}

}  // namespace

SectionOf<SimulationConfig> ThermalSimulatorSection() {
  return {"thermal simulator",
          ConfigSectionUse::kCommand,
          {
              GRAVCAL_KEY("sim_thermal",
                          "thermal session to simulate instead of the pose scheme: " +
                              AcceptedNames(ThermalProfile()) + " (empty = off)",
                          ReadOptionalEnum(n, &c->sim_thermal, e), ValueText(c.sim_thermal)),
              GRAVCAL_KEY("sim_thermal_soaks", "soak temperatures of soak_steps, degC",
                          ReadTemperatures(n, &c->thermal_simulation.soak_temperatures, e),
                          TemperaturesText(c.thermal_simulation.soak_temperatures)),
              GRAVCAL_DOUBLE("sim_thermal_start", thermal_simulation.start_temperature,
                             "cold end of the ramps, degC"),
              GRAVCAL_DOUBLE("sim_thermal_end", thermal_simulation.end_temperature,
                             "warm end of the ramps, degC"),
              GRAVCAL_DOUBLE("sim_thermal_ramp_seconds", thermal_simulation.ramp_seconds,
                             "duration of each ramp, s"),
              GRAVCAL_DOUBLE("sim_thermal_time_constant", thermal_simulation.ramp_time_constant,
                             "time constant of the exponential ramps, s"),
              GRAVCAL_DOUBLE("sim_thermal_lag", thermal_simulation.lag_time_constant,
                             "lag of the sensing element behind the temperature sensor, s"),
              GRAVCAL_INT("sim_thermal_poses", thermal_simulation.poses,
                          "poses per cycle: the six faces, then 45-degree poses (6..12)"),
              GRAVCAL_DOUBLE("sim_thermal_hold", thermal_simulation.hold_seconds,
                             "seconds each pose is held"),
              GRAVCAL_BOOL("sim_thermal_shuffle", thermal_simulation.shuffle_poses,
                           "a new random pose order each pass (true), or the same (false)"),
              GRAVCAL_DOUBLE("sim_thermal_rate", thermal_simulation.sample_rate, "sample rate, Hz"),
          }};
}

}  // namespace internal
}  // namespace gravcal
