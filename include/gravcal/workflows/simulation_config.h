// gravcal/workflows/simulation_config.h: the simulation part of a Config
// (config.h): what `gravcal simulate` and `gravcal demo` read. Its config
// sections are "simulator" (every sim_* key, made from SimulatorOptions'
// own table) and "motion simulator" (sim_motion and the hh_* keys); no
// calibration method reads them.
#ifndef GRAVCAL_WORKFLOWS_SIMULATION_CONFIG_H_
#define GRAVCAL_WORKFLOWS_SIMULATION_CONFIG_H_

#include <optional>
#include <string>

#include "gravcal/core/types.h"
#include "gravcal/simulation/handheld_simulator.h"
#include "gravcal/simulation/simulator.h"
#include "gravcal/simulation/thermal_simulator.h"

namespace gravcal {

struct SimulationConfig {
  // The multi-position simulator (sim_scheme and the other sim_* keys).
  SimulatorOptions simulation;
  // Issue 4: the motion simulator used when sim_motion names a profile
  // (handheld, turntable, vertical, rate_table; none, written empty = the
  // multi-position scheme). It replaces motion.profile.
  MotionOptions motion;
  std::optional<MotionProfile> sim_motion;
  // Issue 35: the thermal simulator (thermal_simulator.h), used when
  // sim_thermal names a profile (none, written empty = off). It replaces
  // thermal_simulation.profile.
  ThermalSimulatorOptions thermal_simulation;
  std::optional<ThermalProfile> sim_thermal;
};

}  // namespace gravcal

#endif  // GRAVCAL_WORKFLOWS_SIMULATION_CONFIG_H_
