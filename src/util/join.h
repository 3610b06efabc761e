// util/join.h (private): a list of names written as one line of a message.
#ifndef GRAVCAL_SRC_UTIL_JOIN_H_
#define GRAVCAL_SRC_UTIL_JOIN_H_

#include <string>
#include <vector>

namespace gravcal {
namespace internal {

// "a, b, c"; empty for no items.
inline std::string Join(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& item : items) out += (out.empty() ? "" : ", ") + item;
  return out;
}

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_UTIL_JOIN_H_
