// Private: adding warnings with their codes (core/types.h WarningCode) to a
// result's parallel `warnings` (messages) and `warning_codes` vectors, so
// that the two stay in step.
#ifndef GRAVCAL_SRC_CORE_WARNINGS_H_
#define GRAVCAL_SRC_CORE_WARNINGS_H_

#include <string>
#include <vector>

#include "gravcal/core/types.h"

namespace gravcal {
namespace internal {

// Appends `message` to *warnings and `code` to *codes.
void AddWarning(WarningCode code, const std::string& message, std::vector<std::string>* warnings,
                std::vector<WarningCode>* codes);

// Appends every message of `messages`, prefixed by `prefix`, with its code
// from `codes` (kUnclassified where `codes` is short).
void AppendWarnings(const std::vector<std::string>& messages, const std::vector<WarningCode>& codes,
                    const std::string& prefix, std::vector<std::string>* warnings,
                    std::vector<WarningCode>* to_codes);

// Gives `code` to the warnings that have none yet (*codes grows to the size
// of `warnings`): for a helper that appends warnings of one kind to a plain
// list of messages.
void CodeNewWarnings(WarningCode code, const std::vector<std::string>& warnings,
                     std::vector<WarningCode>* codes);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_CORE_WARNINGS_H_
