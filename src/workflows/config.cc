#include "gravcal/workflows/config.h"

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <utility>

#include "gravcal/workflows/method_registry.h"
#include "workflows/config/config_key.h"

namespace gravcal {
namespace internal {

namespace {

// A part's section as a section of the whole Config: each handler sees its
// own part of the config only.
template <typename Part>
ConfigSection Lift(const SectionOf<Part>& section) {
  ConfigSection whole{section.name, section.use, {}};
  for (const KeyHandlerOf<Part>& h : section.keys) {
    whole.keys.push_back(
        {h.name,
         h.accepted ? h.help + ": " + h.accepted(Part()) : h.help,
         [set = h.set](const YAML::Node& n, Config* c, std::string* e) { return set(n, c, e); },
         [get = h.get](const Config& c) { return get(c); },
         [fields = h.fields](const Config& c) {
           return fields ? fields(c) : std::vector<const void*>();
         },
         {}});
  }
  return whole;
}

}  // namespace

const std::vector<ConfigSection>& ConfigSections() {
  // Never destroyed (Google style for static storage): a batch worker abandoned
  // with a hung unit may still read it while the process exits (found by TSan).
  static const std::vector<ConfigSection>& sections = *new std::vector<ConfigSection>{
      Lift(GeneralSection()),
      Lift(InputSection()),
      Lift(GravitySection()),
      Lift(DetectorSection()),
      Lift(PoseNoiseSection()),
      Lift(ModelSection()),
      Lift(SolverSection()),
      Lift(GyroSection()),
      Lift(AlignmentSection()),
      Lift(HandheldKalmanSection()),
      Lift(EffectsSection()),
      Lift(DiscoverySection()),
      Lift(NoiseSection()),
      Lift(SimulatorSection()),
      Lift(MotionSimulatorSection()),
      Lift(ThermalSection()),
      Lift(ThermalSimulatorSection()),
  };
  return sections;
}

namespace {

const ConfigKeyHandler* FindHandler(const std::string& name) {
  for (const ConfigSection& section : ConfigSections()) {
    for (const ConfigKeyHandler& h : section.keys) {
      if (h.name == name) return &h;
    }
  }
  return nullptr;
}

}  // namespace

std::vector<const void*> ConfigKeyFields(const Config& config, const std::string& name) {
  const ConfigKeyHandler* h = FindHandler(name);
  return h == nullptr ? std::vector<const void*>() : h->fields(config);
}

}  // namespace internal

namespace {

using internal::ConfigKeyHandler;
using internal::ConfigSection;
using internal::ConfigSections;
using internal::FindHandler;

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
  config->key_layers.resize(set.size(), 0);
  const auto it = std::find(set.begin(), set.end(), key);
  if (it == set.end()) {
    set.push_back(key);
    config->key_layers.push_back(config->layer);
  } else {
    config->key_layers[it - set.begin()] = config->layer;
  }
  return true;
}

// Duplicate keys of every map in the tree (yaml-cpp keeps both entries and
// the loader would silently take the last): false with "<name>:<line>: ..."
// naming the key and both lines.
bool CheckDuplicateKeys(const YAML::Node& node, const std::string& name, std::string* error) {
  if (node.IsSequence()) {
    for (const YAML::Node& item : node) {
      if (!CheckDuplicateKeys(item, name, error)) return false;
    }
    return true;
  }
  if (!node.IsMap()) return true;
  std::vector<std::pair<std::string, int>> seen;
  for (const auto& kv : node) {
    const int line = kv.first.Mark().line + 1;
    if (kv.first.IsScalar()) {
      const std::string& key = kv.first.Scalar();
      for (const auto& [other, other_line] : seen) {
        if (other != key) continue;
        std::ostringstream s;
        s << name << ":" << line << ": duplicate key '" << key << "' (first set on line "
          << other_line << "; a key may be set once)";
        *error = s.str();
        return false;
      }
      seen.emplace_back(key, line);
    }
    if (!CheckDuplicateKeys(kv.second, name, error)) return false;
  }
  return true;
}

bool KeySet(const Config& c, const std::string& key) {
  return std::find(c.keys_set.begin(), c.keys_set.end(), key) != c.keys_set.end();
}

// The layer `key` was last set in (Config::key_layers), -1 when it was not set.
int KeyLayer(const Config& c, const std::string& key) {
  const auto it = std::find(c.keys_set.begin(), c.keys_set.end(), key);
  if (it == c.keys_set.end()) return -1;
  const size_t i = it - c.keys_set.begin();
  return i < c.key_layers.size() ? c.key_layers[i] : 0;
}

// Whether `key`, set, is overridden by `path_switch` set in a later layer
// (e.g. --pose_variance false on a config file that sets the prior): then the
// key is quietly out of use, as the user asked; otherwise a key the switch
// leaves unused is an error.
bool OverriddenBy(const Config& c, const std::string& key, const std::string& path_switch) {
  return KeyLayer(c, path_switch) > KeyLayer(c, key);
}

// Settings that contradict each other, and keys set that the chosen solver
// or model path ignores (as a key the method ignores is an error): false
// with a message naming both keys. `reads` says whether the method reads a
// key (a rule about keys it does not read does not apply).
bool CheckConsistency(const Config& c, const std::function<bool(const char*)>& reads,
                      std::string* error) {
  const CalibrationOptions& o = c.calibration;
  const auto contradict = [&](const char* a, const char* b, const std::string& why) {
    *error = std::string("keys '") + a + "' and '" + b + "' contradict: " + why;
    return false;
  };
  const auto ignored = [&](const char* key, const std::string& when) {
    *error = std::string("key '") + key + "' is ignored " + when + " (remove it)";
    return false;
  };
  if (c.input.sample_rate > 0.0 && KeySet(c, "time_scale")) {
    return contradict("sample_rate", "time_scale",
                      "sample_rate makes the time of a log without a time column, time_scale "
                      "scales the time column of a log with one: one of them is ignored");
  }
  if (reads("gravity") && o.gravity.gravity > 0.0 && std::isfinite(o.gravity.latitude)) {
    return contradict("gravity", "latitude",
                      "a measured gravity replaces normal gravity at a latitude; set one");
  }
  if (reads("height") && KeySet(c, "height") &&
      !(o.gravity.gravity <= 0.0 && std::isfinite(o.gravity.latitude))) {
    return ignored("height",
                   "without 'latitude' or with 'gravity' (it is the height of "
                   "normal gravity at a latitude)");
  }
  if (reads("solver") && o.solver == RefinementSolver::kNewton) {
    if (reads("loss") && o.refinement.loss != LossType::kNone) {
      return contradict("solver", "loss", "the Newton solver has no robust loss (solver: ceres)");
    }
    if (reads("effects") && !c.effects.empty()) {
      return contradict("solver", "effects",
                        "the fit with effects is by Ceres only (solver: ceres)");
    }
  }
  if (reads("loss_scale") && KeySet(c, "loss_scale") && o.refinement.loss == LossType::kNone &&
      !OverriddenBy(c, "loss_scale", "loss")) {
    return ignored("loss_scale", "with loss: none (it is the scale of a robust loss)");
  }
  if (reads("newton_residual") && KeySet(c, "newton_residual") &&
      o.solver != RefinementSolver::kNewton && !OverriddenBy(c, "newton_residual", "solver")) {
    return ignored("newton_residual", "unless solver: newton");
  }
  if (reads("covariance") && reads("output_covariance") && !o.refinement.compute_covariance &&
      c.output_covariance && KeySet(c, "output_covariance")) {
    return contradict("covariance", "output_covariance",
                      "no covariance is computed with covariance: false, so none can be written");
  }
  if (reads("pose_noise_batches") && KeySet(c, "pose_noise_batches") &&
      o.pose_noise.method != PoseNoise::kBatchMeans &&
      !OverriddenBy(c, "pose_noise_batches", "pose_noise")) {
    return ignored("pose_noise_batches", "unless pose_noise: batch_means");
  }
  if (reads("pose_variance") && !o.refinement.estimate_pose_variance) {
    for (const char* key :
         {"pose_disturbance_prior", "pose_disturbance_prior_dof", "prior_conflict_level",
          "structure_test_level", "max_pose_disturbance"}) {
      if (reads(key) && KeySet(c, key) && !OverriddenBy(c, key, "pose_variance")) {
        return ignored(key, "unless pose_variance: true");
      }
    }
  }
  if (reads("gyro_model") && c.gyro.parameterization == GyroParameterization::kNone) {
    if (c.gyro.g_sensitivity && !OverriddenBy(c, "gyro_g_sensitivity", "gyro_model")) {
      return contradict("gyro_model", "gyro_g_sensitivity",
                        "gyro_model none estimates no gyroscope to give a g-sensitivity");
    }
    if (c.gyro.joint && !OverriddenBy(c, "gyro_joint", "gyro_model")) {
      return contradict("gyro_model", "gyro_joint",
                        "gyro_model none estimates no gyroscope to refine jointly");
    }
    for (const char* key : {"gyro_loss", "gyro_loss_scale", "gyro_edge", "gyro_max_rotation"}) {
      if (KeySet(c, key) && !OverriddenBy(c, key, "gyro_model")) {
        return ignored(key, "with gyro_model: none");
      }
    }
  }
  return true;
}

}  // namespace

bool Config::IsValid(std::string* error) const {
  const CalibrationMethod* chosen = FindCalibrationMethod(method);
  if (chosen == nullptr) {
    *error = "key 'method': unknown method (available: " + CalibrationMethodNames() + ")";
    return false;
  }
  for (const std::string& name : keys_set) {
    const ConfigKey* key = FindConfigKey(name);
    if (key != nullptr && key->use == ConfigSectionUse::kSomeMethods &&
        !MethodReadsKey(*chosen, *key)) {
      *error = "key '" + name + "' is not used by method '" + chosen->name +
               "' (remove it; 'gravcal help calibrate' lists the keys by section)";
      return false;
    }
  }
  const auto reads = [&](const char* name) {
    const ConfigKey* key = FindConfigKey(name);
    return key != nullptr && MethodReadsKey(*chosen, *key);
  };
  if (!CheckConsistency(*this, reads, error)) return false;
  if (chosen->validate && !chosen->validate(*this, error)) return false;
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

namespace {

// A parser's events, ignored but for where each document starts.
class DocumentStarts : public YAML::EventHandler {
 public:
  YAML::Mark last;
  void OnDocumentStart(const YAML::Mark& mark) override { last = mark; }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t,
                const std::string&) override {}
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {}
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {}
  void OnMapEnd() override {}
};

}  // namespace

bool LoadConfigText(const std::string& text, const std::string& name, Config* config,
                    std::string* error) {
  // The first document, and whether a second one starts. The parser is asked
  // for two documents at most: YAML::LoadAll's loop over documents never ends
  // on some malformed text (yaml-cpp 0.7; found by fuzz_config, the input is
  // in fuzz/regressions/config).
  std::vector<YAML::Node> documents;
  YAML::Mark second_start = YAML::Mark::null_mark();
  try {
    std::istringstream in(text);
    YAML::Parser parser(in);
    DocumentStarts starts;
    if (parser.HandleNextDocument(starts)) {
      documents.push_back(YAML::Load(text));
      if (parser.HandleNextDocument(starts)) {
        documents.emplace_back();
        second_start = starts.last;
      }
    }
  } catch (const YAML::Exception& e) {
    std::ostringstream s;
    s << name << ":" << e.mark.line + 1 << ": not valid YAML: " << e.msg;
    *error = s.str();
    return false;
  }
  if (documents.size() > 1) {
    std::ostringstream s;
    s << name;
    if (!second_start.is_null()) s << ":" << second_start.line + 1;
    s << ": a second YAML document (a config is one document: remove the '---' and what "
         "follows, or merge it into the first)";
    *error = s.str();
    return false;
  }
  if (documents.empty()) return true;
  const YAML::Node& root = documents[0];
  if (!CheckDuplicateKeys(root, name, error)) return false;
  if (root.IsNull()) return true;
  if (!root.IsMap()) {
    *error = name + ": the top level must be a map of keys";
    return false;
  }
  Config updated = *config;
  for (const auto& kv : root) {
    std::string what;
    const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : "?";
    // 'gravity:' with nothing after it is a value forgotten, not a default.
    if (kv.second.IsNull()) what = "key '" + key + "' has no value (give one, or remove the line)";
    if (!what.empty() || !SetNode(key, kv.second, &updated, &what)) {
      std::ostringstream s;
      s << name << ":" << kv.first.Mark().line + 1 << ": " << what;
      *error = s.str();
      return false;
    }
  }
  // What is set after this file overrides it (Config::key_layers).
  updated.layer = config->layer + 1;
  *config = updated;
  return true;
}

bool LoadConfigFile(const std::string& path, Config* config, std::string* error) {
  // A folder, a device or a pipe is refused before it is read (an ifstream
  // opens a folder and reads nothing: the defaults would run).
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status)) {
    *error = path + ": not a regular file (" +
             (std::filesystem::is_directory(status) ? "a folder" : "a device, pipe or socket") +
             "); --config names a YAML file";
    return false;
  }
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
