// libFuzzer target: MCAP files (seed with files from tests/formats/write_mcap.mjs) through
// ReadImuLog. Invariant (fuzz_recording.h): a contract-satisfying log or a one-line error naming
// the file.
#include <cstddef>
#include <cstdint>

#include "fuzz_recording.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return gravcal::fuzz::CheckReader(data, size, "", ".mcap");
}
