// fuzz/fuzz_check.h: what every fuzz target checks besides "no crash".
//
// A reader either succeeds with data that satisfies its contract or fails
// with a message. A broken invariant aborts, so libFuzzer keeps the input.
#ifndef GRAVCAL_FUZZ_FUZZ_CHECK_H_
#define GRAVCAL_FUZZ_FUZZ_CHECK_H_

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

namespace gravcal {
namespace fuzz {

// A scratch path of this process under $TMPDIR (/tmp when unset):
// "<dir>/gravcal_fuzz_<pid><suffix>".
inline std::string ScratchPath(const std::string& suffix) {
  const char* dir = std::getenv("TMPDIR");
  std::string folder = dir != nullptr && *dir != '\0' ? dir : "/tmp";
  if (folder.back() != '/') folder += '/';
  return folder + "gravcal_fuzz_" + std::to_string(getpid()) + suffix;
}

inline void Require(bool condition, const char* what) {
  if (condition) return;
  std::fprintf(stderr, "fuzz invariant broken: %s\n", what);
  std::abort();
}

// A reader's outcome: true with data, or false with a non-empty message.
inline void RequireOutcome(bool ok, const std::string& error) {
  Require(ok || !error.empty(), "a reader failed without a message");
}

// A scratch file of this process, rewritten with `bytes` for readers that
// take a path.
inline std::string WriteScratch(const std::string& suffix, const uint8_t* data, size_t size) {
  const std::string path = ScratchPath(suffix);
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

}  // namespace fuzz
}  // namespace gravcal

#endif  // GRAVCAL_FUZZ_FUZZ_CHECK_H_
