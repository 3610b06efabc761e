// The machinery behind config.h: one ConfigKeyHandler per key, binding its
// name and help to a field of Config (how to set it from a YAML node, how to
// print it), and a ConfigSection per group of keys. Each section lives in
// its own file under src/workflows/config/ beside the options it fills;
// config.cc only strings the sections together.
#ifndef GRAVCAL_SRC_WORKFLOWS_CONFIG_CONFIG_KEY_H_
#define GRAVCAL_SRC_WORKFLOWS_CONFIG_CONFIG_KEY_H_

#include <yaml-cpp/yaml.h>

#include <functional>
#include <optional>
#include <string>
#include <type_traits>
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
  // An enum key: the names its table accepts, which `gravcal help` adds to
  // `help` (config.cc); empty for other keys.
  std::function<std::string(const Part&)> accepted;
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
// An enum by its name in the enum's table (core/types.h); the error gives
// the value and the accepted names ("'x' is not one of a, b or c").
template <typename Enum>
bool ReadEnum(const YAML::Node& n, Enum* v, std::string* error) {
  std::string s;
  if (!ReadString(n, &s, error)) return false;
  if (FromString(s, v)) return true;
  *error = "'" + s + "' is not one of " + AcceptedNames(Enum());
  return false;
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
// An enum with a string table (core/types.h).
template <typename Enum, typename = std::enable_if_t<std::is_enum_v<Enum>>>
bool ReadValue(const YAML::Node& n, Enum* v, std::string* e) {
  return ReadEnum(n, v, e);
}
template <typename Enum, typename = std::enable_if_t<std::is_enum_v<Enum>>>
std::string ValueText(Enum v) {
  return ToString(v);
}
// An enum that may be absent (written empty): "'x' is not one of a, b or c
// (or empty)".
template <typename Enum>
bool ReadOptionalEnum(const YAML::Node& n, std::optional<Enum>* v, std::string* e) {
  std::string name;
  if (!ReadString(n, &name, e)) return false;
  Enum value{};
  if (name.empty()) {
    v->reset();
  } else if (FromString(name, &value)) {
    *v = value;
  } else {
    *e = "'" + name + "' is not one of " + AcceptedNames(value) + " (or empty)";
    return false;
  }
  return true;
}
template <typename Enum>
std::string ValueText(const std::optional<Enum>& v) {
  return v ? ValueText(*v) : ValueText(std::string());
}

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
        [](const auto& c) { return std::vector<const void*>{__VA_ARGS__}; }, {}    \
  }
#define GRAVCAL_KEY(name, help, read, print)                                       \
  {                                                                                \
    name, help, [](const YAML::Node& n, auto* c, std::string* e) { return read; }, \
        [](const auto& c) { return print; },                                       \
        [](const auto&) { return std::vector<const void*>(); }, {}                 \
  }
#define GRAVCAL_DOUBLE(name, field, help) \
  GRAVCAL_KEY_AT(name, help, ReadDouble(n, &c->field, e), ValueText(c.field), &c.field)
#define GRAVCAL_INT(name, field, help) \
  GRAVCAL_KEY_AT(name, help, ReadInt(n, &c->field, e), ValueText(c.field), &c.field)
#define GRAVCAL_BOOL(name, field, help) \
  GRAVCAL_KEY_AT(name, help, ReadBool(n, &c->field, e), ValueText(c.field), &c.field)
#define GRAVCAL_STRING(name, field, help) \
  GRAVCAL_KEY_AT(name, help, ReadString(n, &c->field, e), ValueText(c.field), &c.field)
// An enum key: its help ends in the names the enum's table accepts
// (KeyHandlerOf::accepted): GRAVCAL_ENUM("loss", ..., "robust loss") reads
// "robust loss: none, huber, ... or tukey".
#define GRAVCAL_ENUM(name, field, help)                                                         \
  {                                                                                             \
    name, help,                                                                                 \
        [](const YAML::Node& n, auto* c, std::string* e) { return ReadEnum(n, &c->field, e); }, \
        [](const auto& c) { return std::string(ToString(c.field)); },                           \
        [](const auto& c) { return std::vector<const void*>{&c.field}; },                       \
        [](const auto& c) { return AcceptedNames(c.field); }                                    \
  }

#endif  // GRAVCAL_SRC_WORKFLOWS_CONFIG_CONFIG_KEY_H_
