// Fuzz target: noise.json (NoiseFromJson), the input of calibrate --noise.
#include <cstdint>
#include <string>

#include "fuzz_check.h"
#include "gravcal/io/noise_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  gravcal::ImuNoise noise;
  std::string error;
  gravcal::fuzz::RequireOutcome(gravcal::NoiseFromJson(text, "fuzz.json", &noise, &error), error);
  return 0;
}
