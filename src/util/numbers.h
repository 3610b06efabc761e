// util/numbers.h (private): a double's infinity, and its text as gravcal
// writes it into files.
#ifndef GRAVCAL_SRC_UTIL_NUMBERS_H_
#define GRAVCAL_SRC_UTIL_NUMBERS_H_

#include <charconv>
#include <limits>
#include <string>

namespace gravcal {
namespace internal {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The shortest decimal text that reads back to the same double.
inline std::string ExactNumber(double v) {
  char text[32];
  return std::string(text, std::to_chars(text, text + sizeof(text), v).ptr);
}

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_UTIL_NUMBERS_H_
