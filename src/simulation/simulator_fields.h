// Private: the fields of SimulatorOptions by name, one row each: the config
// key that sets it (sim_*), its name in truth.json's "options", its help
// line, and the member it binds. The options own their section: the config
// section "simulator" (workflows/config/simulator_keys.cc), `gravcal help`
// and the truth JSON (TruthToJson) are all made from this one table, so a
// new sim_ key is its field in SimulatorOptions plus one row here.
#ifndef GRAVCAL_SRC_SIMULATION_SIMULATOR_FIELDS_H_
#define GRAVCAL_SRC_SIMULATION_SIMULATOR_FIELDS_H_

#include <string>
#include <variant>
#include <vector>

#include "gravcal/simulation/simulator.h"

namespace gravcal {
namespace internal {

struct SimulatorField {
  // The config key, e.g. "sim_hold".
  const char* key;
  // The name in truth.json's "options", e.g. "hold_seconds" (the member's).
  const char* name;
  const char* help;
  std::variant<double SimulatorOptions::*, bool SimulatorOptions::*,
               std::string SimulatorOptions::*>
      member;
};

// Every field with a key, in the order `gravcal help` lists them.
const std::vector<SimulatorField>& SimulatorFields();

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_SIMULATION_SIMULATOR_FIELDS_H_
