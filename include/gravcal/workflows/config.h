// gravcal/workflows/config.h: the YAML configuration shared by the command-line tool
// and library users.
//
// Keys are flat, one name per setting, so the same name works in the YAML
// file and as a command-line flag (`gravity: 9.81744` or `--gravity
// 9.81744`). Keys come in sections, each owned by the options it fills
// (src/workflows/config/*_keys.cc); simulator keys start with `sim_`. A key
// that does not exist is an error naming it (and the line in a file); so is
// a value of the wrong type or out of range, and so is a key the user set
// that the chosen method does not use (method_registry.h). `gravcal help`
// lists every key with its default.
#ifndef GRAVCAL_WORKFLOWS_CONFIG_H_
#define GRAVCAL_WORKFLOWS_CONFIG_H_

#include <string>
#include <vector>

#include "gravcal/estimation/noise_characterisation.h"
#include "gravcal/io/log_reader.h"
#include "gravcal/methods/gyro_calibration.h"
#include "gravcal/methods/handheld_kalman.h"
#include "gravcal/methods/ten_position.h"
#include "gravcal/methods/twelve_position.h"
#include "gravcal/simulation/handheld_simulator.h"
#include "gravcal/simulation/simulator.h"
#include "gravcal/workflows/discovery.h"

namespace gravcal {

struct Config {
  // Calibration method (its registry entry: method_registry.h).
  Method method = Method::kTwelvePosition;
  LogReaderOptions input;
  CalibrationOptions calibration;
  SimulatorOptions simulation;
  // Gyroscope from the rotations between the poses (gyro_model != none).
  GyroCalibrationOptions gyro;
  // Issue 3: the ten-position method's alignment settings.
  TenPositionOptions ten_position;
  // Write accel.covariance into the calibration JSON.
  bool output_covariance = true;
  // Issue 4: the handheld Kalman calibration (method handheld_kalman; its
  // gravity and accelerometer nominal scale come from `calibration`), and
  // the motion simulator used by `gravcal simulate` when sim_motion names a
  // profile (empty = the multi-position scheme).
  HandheldKalmanOptions handheld;
  MotionOptions motion;
  std::string sim_motion;
  // Issue 6: effects beyond the textbook model fitted by `calibrate` (and
  // already in the baseline of `discover`), and the discovery workflow.
  std::vector<Effect> effects;
  DiscoveryOptions discovery;
  // Issue 14: `gravcal noise` (its scales and detector come from the keys
  // nominal_scale, gyro_nominal_scale and the detector section).
  NoiseOptions noise;
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
