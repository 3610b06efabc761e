// Private: the fields of SimulatorOptions by name, one row each: the config
// key that sets it (sim_*), its name in truth.json's "options", its help
// line, and the member it binds. The options own their section: the config
// section "simulator" (workflows/config/simulator_keys.cc), `gravcal help`
// and the truth JSON (TruthToJson) are all made from this one table, so a
// new sim_ key is its field in SimulatorOptions plus one row here.
#ifndef GRAVCAL_SRC_SIMULATION_SIMULATOR_FIELDS_H_
#define GRAVCAL_SRC_SIMULATION_SIMULATOR_FIELDS_H_

#include <string>
#include <type_traits>
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
  std::string help;
  // The member, or the effect whose spread (SimulatorOptions::effect_std)
  // it is.
  std::variant<double SimulatorOptions::*, bool SimulatorOptions::*,
               std::string SimulatorOptions::*, SimulatorScheme SimulatorOptions::*,
               RotationProfile SimulatorOptions::*, Effect>
      member;
};

// Calls f with a reference to the field's value in `options` (const or not).
template <typename Options, typename F>
void WithFieldValue(const SimulatorField& field, Options& options, F&& f) {
  std::visit(
      [&](auto member) {
        if constexpr (std::is_same_v<decltype(member), Effect>) {
          f(options.effect_std.values[static_cast<int>(member)]);
        } else {
          f(options.*member);
        }
      },
      field.member);
}

// Every field with a key, in the order `gravcal help` lists them.
const std::vector<SimulatorField>& SimulatorFields();

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_SIMULATION_SIMULATOR_FIELDS_H_
