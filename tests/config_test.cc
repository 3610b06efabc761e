// Config: the YAML file and flag layer. Every shipped config must load and
// validate; every kind of bad input must fail with a message naming the file
// and line or the key, and leave the config untouched.
#include "gravcal/workflows/config.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "gravcal/simulation/simulator.h"
#include "gravcal/workflows/method_registry.h"
#include "gravcal/workflows/multi_imu_log.h"
#include "test_util.h"

namespace gravcal {
namespace {

TEST(Config, EveryShippedConfigLoadsAndValidates) {
  int loaded = 0;
  for (const auto& entry :
       std::filesystem::directory_iterator(std::string(GRAVCAL_SOURCE_DIR) + "/configs")) {
    if (entry.path().extension() != ".yaml") continue;
    std::string error;
    // A multi-IMU config (issue 38) has a loader of its own.
    if (IsMultiImuConfigFile(entry.path().string())) {
      MultiImuConfig multi;
      EXPECT_TRUE(LoadMultiImuConfig(entry.path().string(), &multi, &error)) << error;
      ++loaded;
      continue;
    }
    Config config;
    ASSERT_TRUE(LoadConfigFile(entry.path().string(), &config, &error)) << error;
    EXPECT_TRUE(config.IsValid(&error)) << entry.path() << ": " << error;
    ++loaded;
  }
  EXPECT_GE(loaded, 4);
}

TEST(Config, KeysAreUniqueAndEachPrintsItsDefault) {
  std::set<std::string> names;
  const Config defaults;
  for (const ConfigKey& key : ConfigKeys()) {
    EXPECT_TRUE(names.insert(key.name).second) << "duplicate key " << key.name;
    EXPECT_TRUE(IsConfigKey(key.name));
    EXPECT_FALSE(key.help.empty()) << key.name;
    // The printed default must load back to the same printed value.
    const std::string text = ConfigValueText(defaults, key.name);
    Config round_trip;
    std::string error;
    ASSERT_TRUE(SetConfigValue(key.name, text, &round_trip, &error))
        << key.name << " = " << text << ": " << error;
    EXPECT_EQ(ConfigValueText(round_trip, key.name), text) << key.name;
  }
}

TEST(Config, SetsValuesFromText) {
  Config config;
  std::string error;
  ASSERT_TRUE(LoadConfigText("gravity: 9.79871\nparameterization: scale\nloss: cauchy\n", "t.yaml",
                             &config, &error))
      << error;
  EXPECT_DOUBLE_EQ(config.calibration.gravity.gravity, 9.79871);
  EXPECT_EQ(config.calibration.refinement.parameterization, AccelParameterization::kScale);
  ASSERT_TRUE(SetConfigValue("gravity", "9.81", &config, &error)) << error;
  EXPECT_DOUBLE_EQ(config.calibration.gravity.gravity, 9.81);
}

// A list typed as on a command line (--columns t,ax,ay,az) is the list of
// its names; an empty name is refused with where it is.
TEST(Config, ANameListTakesCommasAsOnACommandLine) {
  Config config;
  std::string error;
  ASSERT_TRUE(SetConfigValue("columns", "t, ax,ay ,az", &config, &error)) << error;
  EXPECT_EQ(config.input.columns, (std::vector<std::string>{"t", "ax", "ay", "az"}));
  ASSERT_TRUE(SetConfigValue("columns", "[t, ax, ay, az]", &config, &error)) << error;
  EXPECT_EQ(config.input.columns.size(), 4u);
  EXPECT_FALSE(SetConfigValue("columns", "t,,ax", &config, &error));
  EXPECT_NE(error.find("empty name at character 3"), std::string::npos) << error;
  EXPECT_FALSE(SetConfigValue("columns", "t,ax,", &config, &error));
  EXPECT_EQ(config.input.columns.size(), 4u) << "left unchanged";
}

TEST(Config, UnknownKeyNamesFileLineAndKey) {
  Config config;
  std::string error;
  EXPECT_FALSE(LoadConfigText("gravity: 9.8\ngravty: 9.8\n", "cfg.yaml", &config, &error));
  EXPECT_NE(error.find("cfg.yaml:2"), std::string::npos) << error;
  EXPECT_NE(error.find("gravty"), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos) << "one line: " << error;
}

// A key with nothing after it ('gravity:') was read as a null and failed
// later in validation, with a message naming neither the file nor the line.
TEST(Config, AKeyWithNoValueNamesFileLineAndKey) {
  for (const std::string key : {"gravity", "loss", "method", "effects"}) {
    Config config;
    const std::string before = ConfigValueText(config, "nominal_scale");
    std::string error;
    EXPECT_FALSE(LoadConfigText("nominal_scale: 2.0\n" + key + ":\n", "c.yaml", &config, &error));
    EXPECT_NE(error.find("c.yaml:2"), std::string::npos) << error;
    EXPECT_NE(error.find("'" + key + "' has no value"), std::string::npos) << error;
    EXPECT_EQ(ConfigValueText(config, "nominal_scale"), before) << "the config is left unchanged";
  }
}

TEST(Config, WrongTypeOrBadEnumNamesTheKeyAndLeavesConfigUnchanged) {
  Config config;
  const std::string before = ConfigValueText(config, "gravity");
  std::string error;
  EXPECT_FALSE(LoadConfigText("gravity: 9.9\nwindow: fast\n", "c.yaml", &config, &error));
  EXPECT_NE(error.find("c.yaml:2"), std::string::npos) << error;
  EXPECT_NE(error.find("window"), std::string::npos) << error;
  // All or nothing: the valid first line was not applied either.
  EXPECT_EQ(ConfigValueText(config, "gravity"), before);

  EXPECT_FALSE(SetConfigValue("loss", "gaussian", &config, &error));
  EXPECT_NE(error.find("loss"), std::string::npos) << error;
  EXPECT_FALSE(SetConfigValue("no_such_key", "1", &config, &error));
  EXPECT_NE(error.find("no_such_key"), std::string::npos) << error;
}

TEST(Config, MalformedYamlAndMissingFile) {
  Config config;
  std::string error;
  EXPECT_FALSE(LoadConfigText("gravity: [1, 2\n", "broken.yaml", &config, &error));
  EXPECT_NE(error.find("broken.yaml:"), std::string::npos) << error;
  EXPECT_FALSE(LoadConfigText("- a\n- b\n", "list.yaml", &config, &error));
  EXPECT_NE(error.find("list.yaml"), std::string::npos) << error;
  EXPECT_FALSE(LoadConfigFile("/nonexistent/gravcal.yaml", &config, &error));
  EXPECT_NE(error.find("/nonexistent/gravcal.yaml"), std::string::npos) << error;
}

// Issue 32: a key set twice, in any map of the file, is an error naming the
// key and both lines (yaml-cpp keeps both, and the loader took the last).
TEST(Config, DuplicateKeyNamesTheKeyAndBothLines) {
  Config config;
  std::string error;
  EXPECT_FALSE(
      LoadConfigText("gravity: 9.81\nloss: cauchy\ngravity: 9.79\n", "dup.yaml", &config, &error));
  EXPECT_NE(error.find("dup.yaml:3: duplicate key 'gravity'"), std::string::npos) << error;
  EXPECT_NE(error.find("line 1"), std::string::npos) << error;
  EXPECT_DOUBLE_EQ(config.calibration.gravity.gravity, Config().calibration.gravity.gravity);
  EXPECT_FALSE(
      LoadConfigText("rename:\n  ax: acc_x\n  ax: acc_y\n", "nested.yaml", &config, &error));
  EXPECT_NE(error.find("nested.yaml:3: duplicate key 'ax'"), std::string::npos) << error;
  // The same name in two different maps is no duplicate.
  EXPECT_TRUE(LoadConfigText("rename: {ax: t}\nformat: csv\n", "ok.yaml", &config, &error))
      << error;
}

TEST(Config, ASecondDocumentIsAnError) {
  Config config;
  std::string error;
  EXPECT_FALSE(LoadConfigText("gravity: 9.81\n---\nloss: cauchy\n", "two.yaml", &config, &error));
  EXPECT_NE(error.find("two.yaml:"), std::string::npos) << error;
  EXPECT_NE(error.find("second YAML document"), std::string::npos) << error;
  EXPECT_FALSE(LoadConfigText("gravity: 9.81\n---\n", "empty_second.yaml", &config, &error));
  EXPECT_NE(error.find("second YAML document"), std::string::npos) << error;
  // One document with its markers is one document.
  EXPECT_TRUE(LoadConfigText("---\ngravity: 9.81\n...\n", "one.yaml", &config, &error)) << error;
}

TEST(Config, APathThatIsNotARegularFileIsRefused) {
  Config config;
  std::string error;
  const std::string folder = std::string(GRAVCAL_SOURCE_DIR) + "/configs";
  EXPECT_FALSE(LoadConfigFile(folder, &config, &error));
  EXPECT_NE(error.find(folder + ": not a regular file"), std::string::npos) << error;
  EXPECT_FALSE(LoadConfigFile("/dev/null", &config, &error));
  EXPECT_NE(error.find("/dev/null: not a regular file"), std::string::npos) << error;
}

// Settings that contradict each other, and keys the chosen solver or model
// path ignores: errors naming both keys (each loads; IsValid refuses).
TEST(Config, ContradictionsAndIgnoredKeysNameBothKeys) {
  const std::vector<std::pair<std::string, std::vector<std::string>>> cases = {
      {"gravity: 9.81\nlatitude: 45\n", {"'gravity'", "'latitude'"}},
      {"sample_rate: 100\ntime_scale: 1e-9\n", {"'sample_rate'", "'time_scale'"}},
      {"height: 300\n", {"'height'", "latitude"}},
      {"gravity: 9.81\nlatitude: 45\nheight: 300\n", {"'gravity'", "'latitude'"}},
      {"solver: newton\nloss: cauchy\n", {"'solver'", "'loss'"}},
      {"solver: newton\neffects: [accel_bias_drift]\n", {"'solver'", "'effects'"}},
      {"newton_residual: magnitude\n", {"'newton_residual'", "solver: newton"}},
      {"gyro_g_sensitivity: true\n", {"'gyro_model'", "'gyro_g_sensitivity'"}},
      {"gyro_model: none\ngyro_joint: true\n", {"'gyro_model'", "'gyro_joint'"}},
      {"gyro_edge: 0.5\n", {"'gyro_edge'", "gyro_model: none"}},
      {"pose_disturbance_prior: 0.004\n", {"'pose_disturbance_prior'", "pose_variance: true"}},
      {"pose_noise_batches: 8\n", {"'pose_noise_batches'", "pose_noise: batch_means"}},
      {"covariance: false\noutput_covariance: true\n", {"'covariance'", "'output_covariance'"}},
      {"loss: none\nloss_scale: 2\n", {"'loss_scale'", "loss: none"}},
  };
  for (const auto& [text, names] : cases) {
    Config config;
    std::string error;
    ASSERT_TRUE(LoadConfigText(text, "c.yaml", &config, &error)) << text << error;
    EXPECT_FALSE(config.IsValid(&error)) << text;
    for (const std::string& name : names) {
      EXPECT_NE(error.find(name), std::string::npos) << text << ": " << error;
    }
  }
  // Their consistent forms are valid.
  for (const char* text :
       {"latitude: 45\nheight: 300\n", "gravity: 9.81\n", "solver: newton\nloss: none\n",
        "solver: newton\nnewton_residual: magnitude\n", "gyro_model: full\ngyro_joint: true\n",
        "gyro_model: bias\ngyro_g_sensitivity: true\ngyro_edge: 0.5\n",
        "pose_variance: true\npose_disturbance_prior: 0.004\n",
        "pose_noise: batch_means\npose_noise_batches: 8\n",
        "covariance: false\noutput_covariance: false\n", "effects: [accel_bias_drift]\n"}) {
    Config config;
    std::string error;
    ASSERT_TRUE(LoadConfigText(text, "c.yaml", &config, &error)) << text << error;
    EXPECT_TRUE(config.IsValid(&error)) << text << ": " << error;
  }
}

// A switch that turns a path off, set after the file that sets the path's
// keys (a flag after --config), overrides them; set in the same file, or
// before the keys, it leaves them an error.
TEST(Config, ASwitchSetLaterOverridesThePathsKeys) {
  const std::string file =
      "pose_variance: true\npose_disturbance_prior: 0.004\ngyro_model: full\ngyro_edge: 0.5\n";
  for (const auto& [key, value] : std::vector<std::pair<std::string, std::string>>{
           {"pose_variance", "false"}, {"gyro_model", "none"}}) {
    Config config;
    std::string error;
    ASSERT_TRUE(LoadConfigText(file, "c.yaml", &config, &error)) << error;
    ASSERT_TRUE(SetConfigValue(key, value, &config, &error)) << error;
    EXPECT_TRUE(config.IsValid(&error)) << key << ": " << error;
  }
  // Every shipped static config can be turned to a fixture's white noise by flags.
  for (const char* name : {"twelve_position.yaml", "hand_placed.yaml"}) {
    Config config;
    std::string error;
    ASSERT_TRUE(LoadConfigFile(testing_util::SourceDir() + "/configs/" + name, &config, &error))
        << error;
    ASSERT_TRUE(SetConfigValue("pose_variance", "false", &config, &error)) << error;
    EXPECT_TRUE(config.IsValid(&error)) << name << ": " << error;
  }
  // The same switch within the file: the file contradicts itself.
  Config config;
  std::string error;
  ASSERT_TRUE(LoadConfigText("pose_variance: false\npose_disturbance_prior: 0.004\n", "c.yaml",
                             &config, &error))
      << error;
  EXPECT_FALSE(config.IsValid(&error));
  // A path key set by a flag after the file that switches the path off.
  Config later;
  ASSERT_TRUE(LoadConfigText("pose_variance: false\n", "c.yaml", &later, &error)) << error;
  ASSERT_TRUE(SetConfigValue("pose_disturbance_prior", "0.004", &later, &error)) << error;
  EXPECT_FALSE(later.IsValid(&error));
  EXPECT_NE(error.find("'pose_disturbance_prior'"), std::string::npos) << error;
}

TEST(Config, InvalidValuesAreCaughtByValidation) {
  Config config;
  std::string error;
  EXPECT_FALSE(SetConfigValue("method", "thirteen_position", &config, &error));
  EXPECT_NE(error.find("method"), std::string::npos) << error;
  EXPECT_EQ(config.method, Method::kTwelvePosition);
}

TEST(Config, UnknownMethodListsEveryRegistryMethod) {
  Config config;
  std::string error;
  EXPECT_FALSE(SetConfigValue("method", "nine_position", &config, &error));
  EXPECT_NE(error.find("key 'method': unknown method 'nine_position'"), std::string::npos) << error;
  for (const CalibrationMethod& m : CalibrationMethods()) {
    EXPECT_NE(error.find(m.name), std::string::npos) << error;
  }
}

TEST(Config, KeyTheMethodDoesNotUseIsAnErrorNamingKeyAndMethod) {
  struct Case {
    const char* yaml;
    const char* message;
  };
  for (const Case& k : {
           Case{"method: known_attitude\neffects: [accel_temperature_bias]\n",
                "key 'effects' is not used by method 'known_attitude'"},
           Case{"method: known_attitude\nparameterization: affine\n",
                "key 'parameterization' is not used by method 'known_attitude'"},
           Case{"method: known_attitude\nsolver: newton\n",
                "key 'solver' is not used by method 'known_attitude'"},
           Case{"method: ten_position\ngyro_model: full\n",
                "key 'gyro_model' is not used by method 'ten_position'"},
           Case{"method: ten_position\neffects: []\n",
                "key 'effects' is not used by method 'ten_position'"},
           Case{"method: handheld_kalman\nwindow: 2\n",
                "key 'window' is not used by method 'handheld_kalman'"},
           Case{"method: twelve_position\nhk_passes: 3\n",
                "key 'hk_passes' is not used by method 'twelve_position'"},
           Case{"method: twelve_position\nthermal_gyro_scale_order: 1\n",
                "key 'thermal_gyro_scale_order' is not used by method 'twelve_position'"},
           Case{"method: rate_table\ngravity: 9.81\n",
                "key 'gravity' is not used by method 'rate_table'"},
       }) {
    Config config;
    std::string error;
    ASSERT_TRUE(LoadConfigText(k.yaml, "c.yaml", &config, &error)) << error;
    EXPECT_FALSE(config.IsValid(&error)) << k.yaml;
    EXPECT_EQ(error.rfind(k.message, 0), 0u) << error;
  }
  // A key given on the command line counts the same as one in the file.
  Config config;
  std::string error;
  ASSERT_TRUE(SetConfigValue("method", "known_attitude", &config, &error)) << error;
  ASSERT_TRUE(config.IsValid(&error)) << error;
  ASSERT_TRUE(SetConfigValue("gyro_joint", "true", &config, &error)) << error;
  EXPECT_FALSE(config.IsValid(&error));
  EXPECT_NE(error.find("'gyro_joint'"), std::string::npos) << error;
}

TEST(Config, DefaultsCommandKeysAndUsedKeysAreNotErrors) {
  for (const CalibrationMethod& m : CalibrationMethods()) {
    // Defaults of keys the method ignores never count: only keys set do.
    Config config;
    config.method = m.id;
    std::string error;
    EXPECT_TRUE(config.IsValid(&error)) << m.name << ": " << error;
    // Simulator and discovery keys belong to commands, not to methods.
    ASSERT_TRUE(
        LoadConfigText("sim_hold: 5\nhh_rate: 30\ndiscovery_max_steps: 2\n"
                       "output_covariance: false\nformat: csv\n",
                       "c.yaml", &config, &error))
        << error;
    EXPECT_TRUE(config.IsValid(&error)) << m.name << ": " << error;
  }
  Config config;
  std::string error;
  ASSERT_TRUE(LoadConfigText("method: known_attitude\nloss: huber\nwindow: 2\ngravity: 9.8\n",
                             "c.yaml", &config, &error))
      << error;
  EXPECT_TRUE(config.IsValid(&error)) << error;
}

TEST(Config, EveryRegistryMethodIsReachableByMethodKey) {
  ASSERT_GE(CalibrationMethods().size(), 5u);
  const std::string help = FindConfigKey("method")->help;
  for (const CalibrationMethod& m : CalibrationMethods()) {
    Config config;
    std::string error;
    ASSERT_TRUE(LoadConfigText("method: " + m.name + "\n", "c.yaml", &config, &error)) << error;
    EXPECT_EQ(config.method, m.id);
    EXPECT_EQ(m.name, ToString(m.id));
    EXPECT_EQ(FindCalibrationMethod(config.method), &m);
    EXPECT_TRUE(config.IsValid(&error)) << m.name << ": " << error;
    EXPECT_NE(help.find(m.name + " ("), std::string::npos) << help;
    ASSERT_TRUE(m.run) << m.name;
  }
}

// The keys each method reads are derived from the parts of the config its
// options are copied from; they are the sections and single keys each
// method was documented to read when the lists were kept by hand.
TEST(Config, KeysAMethodReadsComeFromItsOptions) {
  struct Reads {
    Method method;
    std::vector<std::string> sections;
    std::vector<std::string> keys;
  };
  const std::vector<std::string> solver_fit = {"loss",
                                               "loss_scale",
                                               "covariance",
                                               "max_iterations",
                                               "pose_variance",
                                               "max_pose_disturbance",
                                               "pose_disturbance_prior",
                                               "pose_disturbance_prior_dof"};
  std::vector<std::string> ten_keys = solver_fit;
  for (const char* k :
       {"parameterization", "allow_undetermined", "structure_test_level", "prior_conflict_level"}) {
    ten_keys.push_back(k);
  }
  std::vector<std::string> known_keys = solver_fit;
  known_keys.push_back("gyro_nominal_scale");
  const std::vector<Reads> expected = {
      {Method::kTwelvePosition,
       {"gravity", "detector", "pose_noise", "model", "solver", "gyro", "effects"},
       {"gyro_nominal_scale"}},
      {Method::kTenPosition, {"gravity", "detector", "pose_noise", "alignment"}, ten_keys},
      {Method::kKnownAttitude, {"gravity", "detector", "pose_noise"}, known_keys},
      {Method::kHandheldKalman,
       {"gravity", "handheld_kalman"},
       {"nominal_scale", "gyro_nominal_scale"}},
      {Method::kRateTable, {}, {}},
      {Method::kThermal,
       {"gravity", "detector", "thermal"},
       {"nominal_scale", "gyro_nominal_scale", "max_iterations"}},
  };
  ASSERT_EQ(expected.size(), CalibrationMethods().size());
  const auto has = [](const std::vector<std::string>& v, const std::string& s) {
    return std::find(v.begin(), v.end(), s) != v.end();
  };
  for (const Reads& r : expected) {
    const CalibrationMethod& m = *FindCalibrationMethod(r.method);
    for (const ConfigKey& k : ConfigKeys()) {
      const bool want = k.use == ConfigSectionUse::kAllMethods ||
                        (k.use == ConfigSectionUse::kSomeMethods &&
                         (has(r.sections, k.section) || has(r.keys, k.name)));
      EXPECT_EQ(MethodReadsKey(m, k), want) << m.name << " " << k.name;
    }
  }
  // Every method-specific key is read by some method (no dead keys).
  for (const ConfigKey& k : ConfigKeys()) {
    if (k.use != ConfigSectionUse::kSomeMethods) continue;
    bool read = false;
    for (const CalibrationMethod& m : CalibrationMethods()) read |= MethodReadsKey(m, k);
    EXPECT_TRUE(read) << k.name;
  }
}

// The simulator's truth (truth.json "options") and its config section come
// from one table: every sim_ key of the section appears in the truth under a
// name of its own, the truth has no option without a key, and the truth read
// back through the keys gives the same config.
TEST(Config, SimulatorTruthHoldsEverySimulatorKey) {
  const Config defaults;
  const auto options_json = [](const Config& c) {
    return nlohmann::json::parse(TruthToJson(SimulatedSession(), c.simulation))["options"];
  };
  const nlohmann::json base = options_json(defaults);
  Config changed;
  std::map<std::string, std::string> truth_name;  // key -> its name in the truth
  std::set<std::string> names;
  for (const ConfigKey& key : ConfigKeys()) {
    if (key.section != "simulator") continue;
    // A value away from the default, of the key's type.
    const std::string text = ConfigValueText(defaults, key.name);
    std::string value = "changed_" + key.name;
    if (text == "true" || text == "false") {
      value = text == "true" ? "false" : "true";
    } else if (text == "null") {
      value = "1.5";
    } else if (text.find_first_not_of("0123456789.e+-") == std::string::npos) {
      value = std::to_string(std::stod(text) + 0.375);
    } else if (key.name == "sim_scheme") {
      value = "random:7";  // a SimulatorScheme
    } else if (key.name == "sim_rotation_profile") {
      value = "hand";  // a RotationProfile
    }
    Config one;
    std::string error;
    ASSERT_TRUE(SetConfigValue(key.name, value, &one, &error)) << error;
    ASSERT_TRUE(SetConfigValue(key.name, value, &changed, &error)) << error;
    std::vector<std::string> moved;
    const nlohmann::json options = options_json(one);
    for (const auto& [name, v] : options.items()) {
      if (!base.contains(name) || base[name] != v) moved.push_back(name);
    }
    ASSERT_EQ(moved.size(), 1u) << key.name << " moves " << moved.size() << " truth options";
    EXPECT_TRUE(names.insert(moved[0]).second) << key.name << " shares " << moved[0];
    truth_name[key.name] = moved[0];
  }
  EXPECT_GE(truth_name.size(), 43u);
  EXPECT_EQ(base.size(), truth_name.size()) << "a truth option without a sim_ key";
  // Round trip: the truth of `changed`, set back through the keys.
  const nlohmann::json truth = options_json(changed);
  Config read_back;
  for (const auto& [key, name] : truth_name) {
    const nlohmann::json& v = truth[name];
    std::string error;
    ASSERT_TRUE(
        SetConfigValue(key, v.is_string() ? v.get<std::string>() : v.dump(), &read_back, &error))
        << key << ": " << error;
    EXPECT_EQ(ConfigValueText(read_back, key), ConfigValueText(changed, key)) << key;
  }
}

}  // namespace
}  // namespace gravcal
