// libFuzzer target: EuRoC / TUM-VI CSV (the header is given, the rows are fuzzed) through
// ReadImuLog. Invariant (fuzz_recording.h): a contract-satisfying log or a one-line error naming
// the file.
#include <cstddef>
#include <cstdint>

#include "fuzz_recording.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return gravcal::fuzz::CheckReader(
      data, size,
      "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],a_RS_S_x [m "
      "s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n",
      ".csv");
}
