// gravcal/workflows/config.h: the YAML configuration shared by the command-line tool
// and library users.
//
// Keys are flat, one name per setting, so the same name works in the YAML
// file and as a command-line flag (`gravity: 9.81744` or `--gravity
// 9.81744`). Keys come in sections, each owned by one part of the config
// (calibration, simulation, discovery) and bound to the options it fills
// (src/workflows/config/*_keys.cc); simulator keys start with `sim_`. A key
// that does not exist is an error naming it (and the line in a file); so is
// a value of the wrong type or out of range, and so is a key the user set
// that the chosen method does not use (method_registry.h). `gravcal help`
// lists every key with its default.
#ifndef GRAVCAL_WORKFLOWS_CONFIG_H_
#define GRAVCAL_WORKFLOWS_CONFIG_H_

#include <string>
#include <vector>

#include "gravcal/workflows/calibration_config.h"
#include "gravcal/workflows/discovery_config.h"
#include "gravcal/workflows/simulation_config.h"

namespace gravcal {

// The whole configuration: three parts, each owning its config sections
// (calibration_config.h, simulation_config.h, discovery_config.h), and the
// record of the keys set. The parts are plain data; Config is made of them
// so that config.calibration, config.simulation and config.discovery read
// the same whether a part or the whole is at hand, and a calibration needs
// only its CalibrationConfig.
struct Config : CalibrationConfig, SimulationConfig, DiscoveryConfig {
  // The keys set through LoadConfigText/LoadConfigFile/SetConfigValue, in
  // the order set (a key set twice appears once). Only these are checked
  // against the method: defaults never make a config invalid.
  std::vector<std::string> keys_set;
  // The layer each key of keys_set was last set in (same index): a config
  // file is one layer, and what is set after it (command-line flags,
  // SetConfigValue) the next. A switch that turns a path off (pose_variance:
  // false, gyro_model: none, ...) set in a later layer than the keys of that
  // path overrides them; set in the same layer as them (or left at its
  // default) the keys are an error, as the file contradicts itself.
  std::vector<int> key_layers;
  // The layer the next key is set in.
  int layer = 0;

  // Checks the method (a registry name), that every key in keys_set is used
  // by it (or by every method, or is a command key such as sim_*), and the
  // values of the options the method reads.
  bool IsValid(std::string* error) const;
};

// Who reads a section's keys.
enum class ConfigSectionUse {
  // Every calibration method (general, input).
  kAllMethods,
  // The methods whose registry entry lists the section or the key.
  kSomeMethods,
  // A command, never a method: simulate and demo (sim_*, hh_*), discover
  // (discovery_*). Never an error under any method.
  kCommand,
};

struct ConfigKey {
  std::string name;
  std::string section;
  std::string help;
  ConfigSectionUse use = ConfigSectionUse::kSomeMethods;
};

// Every key, in the order `gravcal help` lists them.
const std::vector<ConfigKey>& ConfigKeys();
bool IsConfigKey(const std::string& name);
// The key's entry, or nullptr when there is no such key.
const ConfigKey* FindConfigKey(const std::string& name);

// Current value of a key as YAML text (for help and reports).
std::string ConfigValueText(const Config& config, const std::string& key);

// Applies a YAML file on top of `config`. Errors: "<file>:<line>: ...".
bool LoadConfigFile(const std::string& path, Config* config, std::string* error);
// Same on text in memory; `name` is used in messages.
bool LoadConfigText(const std::string& text, const std::string& name, Config* config,
                    std::string* error);

// Sets one key from a value written as YAML ("9.81", "huber", "[t, ax]").
// Errors name the key.
bool SetConfigValue(const std::string& key, const std::string& value, Config* config,
                    std::string* error);

}  // namespace gravcal

#endif  // GRAVCAL_WORKFLOWS_CONFIG_H_
