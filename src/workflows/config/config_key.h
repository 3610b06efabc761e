// The machinery behind config.h: one ConfigKeyHandler per key, binding its
// name and help to a field of Config (how to set it from a YAML node, how to
// print it), and a ConfigSection per group of keys. Each section lives in
// its own file under src/workflows/config/ beside the options it fills;
// config.cc only strings the sections together.
#ifndef GRAVCAL_SRC_WORKFLOWS_CONFIG_CONFIG_KEY_H_
#define GRAVCAL_SRC_WORKFLOWS_CONFIG_CONFIG_KEY_H_

#include <yaml-cpp/yaml.h>

#include <functional>
#include <string>
#include <vector>

#include "gravcal/workflows/config.h"

namespace gravcal {
namespace internal {

// One key of a part of Config (Part: CalibrationConfig, SimulationConfig or
// DiscoveryConfig, or the whole Config): how to set it from a YAML node, how
// to print it as YAML, and where in the part it is kept (the fields `set`
// writes). A method reads a key when its options are filled from one of
// those fields (method_registry.cc), so the fields are what ties a key to
// the methods that read it; every key of a kSomeMethods section has them.
template <typename Part>
struct KeyHandlerOf {
  std::string name;
  std::string help;
  std::function<bool(const YAML::Node&, Part*, std::string*)> set;
  std::function<std::string(const Part&)> get;
  std::function<std::vector<const void*>(const Part&)> fields;
};

// A group of keys, owned by one part: its handlers reach that part's
// fields only.
template <typename Part>
struct SectionOf {
  std::string name;
  ConfigSectionUse use = ConfigSectionUse::kSomeMethods;
  std::vector<KeyHandlerOf<Part>> keys;
};

// Every section lifted to the whole Config (config.cc).
using ConfigKeyHandler = KeyHandlerOf<Config>;
using ConfigSection = SectionOf<Config>;

// The sections, in the order `gravcal help` lists them (config.cc).
const std::vector<ConfigSection>& ConfigSections();

// The fields of `config` that key `name` sets (KeyHandlerOf::fields); empty
// for an unknown key or one that names none.
std::vector<const void*> ConfigKeyFields(const Config& config, const std::string& name);

// One function per section, in its file, by the part that owns it.
// calibration (general_keys.cc, accelerometer_keys.cc, gyro_keys.cc,
// ten_position_keys.cc, handheld_kalman_keys.cc, noise_keys.cc,
// effects_keys.cc):
SectionOf<CalibrationConfig> GeneralSection();
SectionOf<CalibrationConfig> InputSection();
SectionOf<CalibrationConfig> GravitySection();
SectionOf<CalibrationConfig> DetectorSection();
SectionOf<CalibrationConfig> ModelSection();
SectionOf<CalibrationConfig> SolverSection();
SectionOf<CalibrationConfig> GyroSection();
SectionOf<CalibrationConfig> AlignmentSection();
SectionOf<CalibrationConfig> HandheldKalmanSection();
SectionOf<CalibrationConfig> PoseNoiseSection();
SectionOf<CalibrationConfig> NoiseSection();
SectionOf<CalibrationConfig> EffectsSection();
// thermal_keys.cc (issue 35):
SectionOf<CalibrationConfig> ThermalSection();
SectionOf<SimulationConfig> ThermalSimulatorSection();
// discovery (effects_keys.cc):
SectionOf<DiscoveryConfig> DiscoverySection();
// simulation (simulator_keys.cc):
SectionOf<SimulationConfig> SimulatorSection();
SectionOf<SimulationConfig> MotionSimulatorSection();

// Value readers: false with `error` saying what the value must be.
bool ReadDouble(const YAML::Node& n, double* v, std::string* error);  // null = NaN
bool ReadInt(const YAML::Node& n, int* v, std::string* error);
bool ReadBool(const YAML::Node& n, bool* v, std::string* error);
bool ReadString(const YAML::Node& n, std::string* v, std::string* error);
bool ReadStringList(const YAML::Node& n, std::vector<std::string>* v, std::string* error);
template <typename Enum>
bool ReadEnum(const YAML::Node& n, Enum* v, const char* choices, std::string* error) {
  std::string s;
  if (!ReadString(n, &s, error) || !FromString(s, v)) {
    *error = std::string("must be one of ") + choices;
    return false;
  }
  return true;
}

// Value printers (YAML text).
std::string DoubleText(double v);  // NaN = "null"
std::string ListText(const std::vector<std::string>& v);

// The reader and printer of a plain field by its type, for tables that bind
// members (simulation/simulator_fields.h).
inline bool ReadValue(const YAML::Node& n, double* v, std::string* e) {
  return ReadDouble(n, v, e);
}
inline bool ReadValue(const YAML::Node& n, int* v, std::string* e) { return ReadInt(n, v, e); }
inline bool ReadValue(const YAML::Node& n, bool* v, std::string* e) { return ReadBool(n, v, e); }
inline bool ReadValue(const YAML::Node& n, std::string* v, std::string* e) {
  return ReadString(n, v, e);
}
inline bool ReadValue(const YAML::Node& n, SimulatorScheme* v, std::string* e) {
  std::string text;
  return ReadString(n, &text, e) && ParseSimulatorScheme(text, v, e);
}
inline std::string ValueText(double v) { return DoubleText(v); }
inline std::string ValueText(int v) { return std::to_string(v); }
inline std::string ValueText(bool v) { return v ? "true" : "false"; }
inline std::string ValueText(const std::string& v) { return v.empty() ? "\"\"" : v; }
inline std::string ValueText(const SimulatorScheme& v) { return ToString(v); }

}  // namespace internal
}  // namespace gravcal

// Binders from a key name to a (nested) field of the section's part, e.g.
// GRAVCAL_DOUBLE("window", calibration.detector.window_seconds, "help"); in
// `read` and `print`, c is the part (a pointer in read), n the YAML node
// and e the error. GRAVCAL_KEY_AT's last arguments are the addresses of the
// fields `read` sets (&c.field, ...); GRAVCAL_KEY names none (for the keys of
// commands, which no method reads).
#define GRAVCAL_KEY_AT(name, help, read, print, ...)                               \
  {                                                                                \
    name, help, [](const YAML::Node& n, auto* c, std::string* e) { return read; }, \
        [](const auto& c) { return print; },                                       \
        [](const auto& c) { return std::vector<const void*>{__VA_ARGS__}; }        \
  }
#define GRAVCAL_KEY(name, help, read, print)                                       \
  {                                                                                \
    name, help, [](const YAML::Node& n, auto* c, std::string* e) { return read; }, \
        [](const auto& c) { return print; },                                       \
        [](const auto&) { return std::vector<const void*>(); }                     \
  }
#define GRAVCAL_DOUBLE(name, field, help) \
  GRAVCAL_KEY_AT(name, help, ReadDouble(n, &c->field, e), ValueText(c.field), &c.field)
#define GRAVCAL_INT(name, field, help) \
  GRAVCAL_KEY_AT(name, help, ReadInt(n, &c->field, e), ValueText(c.field), &c.field)
#define GRAVCAL_BOOL(name, field, help) \
  GRAVCAL_KEY_AT(name, help, ReadBool(n, &c->field, e), ValueText(c.field), &c.field)
#define GRAVCAL_STRING(name, field, help) \
  GRAVCAL_KEY_AT(name, help, ReadString(n, &c->field, e), ValueText(c.field), &c.field)
#define GRAVCAL_ENUM(name, field, choices, help)                                                 \
  GRAVCAL_KEY_AT(name, help, ReadEnum(n, &c->field, choices, e), std::string(ToString(c.field)), \
                 &c.field)

#endif  // GRAVCAL_SRC_WORKFLOWS_CONFIG_CONFIG_KEY_H_
