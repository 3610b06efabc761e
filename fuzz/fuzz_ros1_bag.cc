// libFuzzer target: ROS 1 bags (librosbag_storage) through ReadImuLog.
// Invariant (fuzz_recording.h): a contract-satisfying log or a one-line
// error naming the file.
#include <cstddef>
#include <cstdint>

#include "fuzz_recording.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return gravcal::fuzz::CheckReader(data, size, "#ROSBAG V2.0\n", ".bag");
}
