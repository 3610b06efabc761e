// util/error.h (private): the one way a bool-returning function reports why
// it failed.
#ifndef GRAVCAL_SRC_UTIL_ERROR_H_
#define GRAVCAL_SRC_UTIL_ERROR_H_

#include <string>
#include <utility>

namespace gravcal {
namespace internal {

// Stores `message` in *error (when error is not null) and returns false, so
// a reader can `return SetError(error, "...")`.
inline bool SetError(std::string* error, std::string message) {
  if (error != nullptr) *error = std::move(message);
  return false;
}

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_UTIL_ERROR_H_
