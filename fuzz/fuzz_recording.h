// fuzz/fuzz_recording.h: the invariant every log-reader fuzz target checks.
// The bytes are written to a file (the bag and MCAP readers read files)
// whose name ends in `extension`, read with ReadImuLog, and then either the
// log satisfies the contract (gravcal/core/imu_log.h: non-empty, sizes
// agree, finite, t strictly increasing) or the error is one non-empty line
// naming the file. Anything else aborts, which libFuzzer reports.
#ifndef GRAVCAL_FUZZ_FUZZ_RECORDING_H_
#define GRAVCAL_FUZZ_FUZZ_RECORDING_H_

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "fuzz_check.h"
#include "gravcal/core/imu_log.h"
#include "gravcal/io/log_reader.h"

namespace gravcal {
namespace fuzz {

// Says which part of the invariant broke, then aborts.
[[noreturn]] inline void Broken(const char* what, const std::string& error) {
  std::fprintf(stderr, "fuzz invariant broken: %s; error: '%s'\n", what, error.c_str());
  std::abort();
}

inline int CheckReader(const uint8_t* data, size_t size, const std::string& prefix,
                       const std::string& extension) {
  const std::string path = ScratchPath(extension);
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) return 0;
  std::fwrite(prefix.data(), 1, prefix.size(), f);
  if (size > 0) std::fwrite(data, 1, size, f);
  std::fclose(f);
  ImuLog log;
  std::string error;
  const bool ok = ReadImuLog(path, LogReaderOptions(), &log, &error);
  std::remove(path.c_str());
  if (ok) {
    std::string why;
    if (log.t.empty() || !log.Validate(&why)) Broken("log breaks the contract", why);
    for (size_t i = 1; i < log.t.size(); ++i) {
      if (!(log.t[i] > log.t[i - 1])) Broken("time does not increase", "");
    }
    return 0;
  }
  if (error.empty() || error.find('\n') != std::string::npos) Broken("not one line", error);
  if (error.compare(0, path.size(), path) != 0) Broken("does not name the file", error);
  return 0;
}

}  // namespace fuzz
}  // namespace gravcal

#endif  // GRAVCAL_FUZZ_FUZZ_RECORDING_H_
