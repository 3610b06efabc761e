#include "gravcal/workflows/config.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <fstream>
#include <sstream>

#include "gravcal/workflows/method_registry.h"
#include "workflows/config/config_key.h"

namespace gravcal {
namespace internal {

const std::vector<ConfigSection>& ConfigSections() {
  // Never destroyed (Google style for static storage): a batch worker abandoned
  // with a hung unit may still read it while the process exits (found by TSan).
  static const std::vector<ConfigSection>& sections = *new std::vector<ConfigSection>{
      GeneralSection(),   InputSection(),          GravitySection(),         DetectorSection(),
      PoseNoiseSection(), ModelSection(),          SolverSection(),          GyroSection(),
      AlignmentSection(), HandheldKalmanSection(), EffectsSection(),         DiscoverySection(),
      NoiseSection(),     SimulatorSection(),      MotionSimulatorSection(),
  };
  return sections;
}

}  // namespace internal

namespace {

using internal::ConfigKeyHandler;
using internal::ConfigSection;
using internal::ConfigSections;

const ConfigKeyHandler* FindHandler(const std::string& name) {
  for (const ConfigSection& section : ConfigSections()) {
    for (const ConfigKeyHandler& h : section.keys) {
      if (h.name == name) return &h;
    }
  }
  return nullptr;
}

bool SetNode(const std::string& key, const YAML::Node& node, Config* config, std::string* error) {
  const ConfigKeyHandler* h = FindHandler(key);
  if (h == nullptr) {
    *error = "unknown key '" + key + "' (gravcal help lists the keys)";
    return false;
  }
  std::string what;
  if (!h->set(node, config, &what)) {
    *error = "key '" + key + "': " + what;
    return false;
  }
  std::vector<std::string>& set = config->keys_set;
  if (std::find(set.begin(), set.end(), key) == set.end()) set.push_back(key);
  return true;
}

}  // namespace

bool Config::IsValid(std::string* error) const {
  const CalibrationMethod* chosen = FindCalibrationMethod(method);
  if (chosen == nullptr) {
    *error = "key 'method': unknown method '" + method +
             "' (available: " + CalibrationMethodNames() + ")";
    return false;
  }
  for (const std::string& name : keys_set) {
    const ConfigKey* key = FindConfigKey(name);
    if (key != nullptr && key->use == ConfigSectionUse::kSomeMethods &&
        !MethodReadsKey(*chosen, *key)) {
      *error = "key '" + name + "' is not used by method '" + method +
               "' (remove it; 'gravcal help calibrate' lists the keys by section)";
      return false;
    }
  }
  if (chosen->validate && !chosen->validate(*this, error)) return false;
  MotionProfile profile;
  if (!sim_motion.empty() && !FromString(sim_motion, &profile)) {
    *error = "key 'sim_motion': must be empty, handheld, turntable, vertical or rate_table";
    return false;
  }
  if (!motion.IsValid(error)) return false;
  std::string what;
  if (!input.IsValid(&what)) {
    *error = "input: " + what;
    return false;
  }
  if (!calibration.IsValid(&what)) {
    *error = what;
    return false;
  }
  if (!gyro.IsValid(&what)) {
    *error = what;
    return false;
  }
  if (!discovery.IsValid(&what)) {
    *error = what;
    return false;
  }
  return true;
}

const std::vector<ConfigKey>& ConfigKeys() {
  // Never destroyed (Google style for static storage): a batch worker abandoned
  // with a hung unit may still read it while the process exits (found by TSan).
  static const std::vector<ConfigKey>& keys = *new std::vector<ConfigKey>([] {
    std::vector<ConfigKey> k;
    for (const ConfigSection& section : ConfigSections()) {
      for (const ConfigKeyHandler& h : section.keys) {
        k.push_back({h.name, section.name, h.help, section.use});
      }
    }
    return k;
  }());
  return keys;
}

const ConfigKey* FindConfigKey(const std::string& name) {
  for (const ConfigKey& key : ConfigKeys()) {
    if (key.name == name) return &key;
  }
  return nullptr;
}

bool IsConfigKey(const std::string& name) { return FindHandler(name) != nullptr; }

std::string ConfigValueText(const Config& config, const std::string& key) {
  const ConfigKeyHandler* h = FindHandler(key);
  return h == nullptr ? "" : h->get(config);
}

bool LoadConfigText(const std::string& text, const std::string& name, Config* config,
                    std::string* error) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    std::ostringstream s;
    s << name << ":" << e.mark.line + 1 << ": not valid YAML: " << e.msg;
    *error = s.str();
    return false;
  }
  if (root.IsNull()) return true;
  if (!root.IsMap()) {
    *error = name + ": the top level must be a map of keys";
    return false;
  }
  Config updated = *config;
  for (const auto& kv : root) {
    std::string what;
    const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : "?";
    if (!SetNode(key, kv.second, &updated, &what)) {
      std::ostringstream s;
      s << name << ":" << kv.first.Mark().line + 1 << ": " << what;
      *error = s.str();
      return false;
    }
  }
  *config = updated;
  return true;
}

bool LoadConfigFile(const std::string& path, Config* config, std::string* error) {
  std::ifstream in(path);
  if (!in) {
    *error = path + ": cannot open the config file";
    return false;
  }
  std::stringstream buffer;
  buffer << in.rdbuf();
  return LoadConfigText(buffer.str(), path, config, error);
}

bool SetConfigValue(const std::string& key, const std::string& value, Config* config,
                    std::string* error) {
  YAML::Node node;
  try {
    node = YAML::Load(value);
  } catch (const YAML::Exception&) {
    node = YAML::Node(value);
  }
  return SetNode(key, node, config, error);
}

}  // namespace gravcal
