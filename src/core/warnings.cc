#include "core/warnings.h"

namespace gravcal {
namespace internal {

void AddWarning(WarningCode code, const std::string& message, std::vector<std::string>* warnings,
                std::vector<WarningCode>* codes) {
  // Earlier messages without a code keep their place as unclassified.
  codes->resize(warnings->size(), WarningCode::kUnclassified);
  warnings->push_back(message);
  codes->push_back(code);
}

void AppendWarnings(const std::vector<std::string>& messages, const std::vector<WarningCode>& codes,
                    const std::string& prefix, std::vector<std::string>* warnings,
                    std::vector<WarningCode>* to_codes) {
  for (size_t i = 0; i < messages.size(); ++i) {
    AddWarning(i < codes.size() ? codes[i] : WarningCode::kUnclassified, prefix + messages[i],
               warnings, to_codes);
  }
}

void CodeNewWarnings(WarningCode code, const std::vector<std::string>& warnings,
                     std::vector<WarningCode>* codes) {
  codes->resize(warnings.size(), code);
}

}  // namespace internal
}  // namespace gravcal
