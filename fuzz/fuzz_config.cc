// Fuzz target: the YAML config and the command line's key=value overrides.
// Input: YAML text; when it holds a line "--key value" after a 0 byte, that
// is also set as a flag would be. A config that loads must pass IsValid or
// the load must have said why not.
#include <cstdint>
#include <string>

#include "fuzz_check.h"
#include "gravcal/workflows/config.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string text(reinterpret_cast<const char*>(data), size);
  std::string flag;
  const size_t split = text.find('\0');
  if (split != std::string::npos) {
    flag = text.substr(split + 1);
    text.resize(split);
  }
  gravcal::Config config;
  std::string error;
  const bool ok = gravcal::LoadConfigText(text, "fuzz.yaml", &config, &error);
  gravcal::fuzz::RequireOutcome(ok, error);
  if (!flag.empty()) {
    const size_t space = flag.find(' ');
    const std::string key = flag.substr(0, space);
    const std::string value = space == std::string::npos ? "" : flag.substr(space + 1);
    if (gravcal::IsConfigKey(key)) {
      error.clear();
      gravcal::fuzz::RequireOutcome(gravcal::SetConfigValue(key, value, &config, &error), error);
    }
  }
  std::string why;
  config.IsValid(&why);  // Must not crash on whatever was loaded.
  for (const gravcal::ConfigKey& key : gravcal::ConfigKeys()) {
    gravcal::ConfigValueText(config, key.name);
  }
  return 0;
}
