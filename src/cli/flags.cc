// The gflags definitions and the lookup table of GRAVCAL_FLAGS (flags.h).
#include "cli/flags.h"

#include <gflags/gflags.h>

#include <cstdlib>

#define GRAVCAL_DEFINE_FLAG(type, name, value, help) DEFINE_##type(name, value, help);
GRAVCAL_FLAGS(GRAVCAL_DEFINE_FLAG)
#undef GRAVCAL_DEFINE_FLAG

namespace gravcal {
namespace cli {

const FlagInfo* FindFlag(const std::string& name) {
#define GRAVCAL_FLAG_INFO(type, name, value, help) {#name, help},
  static const FlagInfo kFlags[] = {GRAVCAL_FLAGS(GRAVCAL_FLAG_INFO)};
#undef GRAVCAL_FLAG_INFO
  for (const FlagInfo& f : kFlags) {
    if (name == f.name) return &f;
  }
  return nullptr;
}

std::string FlagText(const char* name) {
  std::string text;
  gflags::GetCommandLineOption(name, &text);
  return text;
}

std::string FlagSpelling(const char* name) {
  std::string s = std::string("--") + name;
  for (char& c : s) {
    if (c == '_') c = '-';
  }
  return s;
}

void ParseFlagText(const std::string& text, std::string* value) { *value = text; }
void ParseFlagText(const std::string& text, bool* value) { *value = text == "true"; }
void ParseFlagText(const std::string& text, int* value) {
  *value = static_cast<int>(std::strtol(text.c_str(), nullptr, 10));
}
void ParseFlagText(const std::string& text, uint64_t* value) {
  *value = std::strtoull(text.c_str(), nullptr, 10);
}
void ParseFlagText(const std::string& text, double* value) {
  *value = std::strtod(text.c_str(), nullptr);
}

}  // namespace cli
}  // namespace gravcal
