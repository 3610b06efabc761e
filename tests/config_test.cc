// Config: the YAML file and flag layer. Every shipped config must load and
// validate; every kind of bad input must fail with a message naming the file
// and line or the key, and leave the config untouched.
#include "gravcal/workflows/config.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <set>
#include <string>

#include "test_util.h"

namespace gravcal {
namespace {

TEST(Config, EveryShippedConfigLoadsAndValidates) {
  int loaded = 0;
  for (const auto& entry :
       std::filesystem::directory_iterator(std::string(GRAVCAL_SOURCE_DIR) + "/configs")) {
    if (entry.path().extension() != ".yaml") continue;
    Config config;
    std::string error;
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

TEST(Config, UnknownKeyNamesFileLineAndKey) {
  Config config;
  std::string error;
  EXPECT_FALSE(LoadConfigText("gravity: 9.8\ngravty: 9.8\n", "cfg.yaml", &config, &error));
  EXPECT_NE(error.find("cfg.yaml:2"), std::string::npos) << error;
  EXPECT_NE(error.find("gravty"), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos) << "one line: " << error;
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

TEST(Config, InvalidValuesAreCaughtByValidation) {
  Config config;
  std::string error;
  config.method = "thirteen_position";
  EXPECT_FALSE(config.IsValid(&error));
  EXPECT_NE(error.find("method"), std::string::npos) << error;
}

}  // namespace
}  // namespace gravcal
