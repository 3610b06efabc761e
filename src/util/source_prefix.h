// util/source_prefix.h (private): "<source>: <message>", the file named once.
//
// Messages pass through several layers (the static detector, the pose
// finder, a method) and each would name the log it worked on; the first
// layer that does so is enough ("raw.csv: raw.csv: 2 samples are too few"
// is what prefixing at every layer gave).
#ifndef GRAVCAL_SRC_UTIL_SOURCE_PREFIX_H_
#define GRAVCAL_SRC_UTIL_SOURCE_PREFIX_H_

#include <string>

namespace gravcal {
namespace internal {

// `message` with "<source>: " in front, unless `source` is empty or the
// message already begins with it.
inline std::string PrefixSource(const std::string& source, const std::string& message) {
  if (source.empty()) return message;
  const std::string prefix = source + ": ";
  if (message.compare(0, prefix.size(), prefix) == 0) return message;
  return prefix + message;
}

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_UTIL_SOURCE_PREFIX_H_
