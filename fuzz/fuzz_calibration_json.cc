// Fuzz target: the calibration JSON reader (apply, export). A calibration
// read must have a finite accelerometer model.
#include <cstdint>
#include <string>

#include "fuzz_check.h"
#include "gravcal/io/calibration_io.h"

using gravcal::fuzz::Require;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = gravcal::fuzz::WriteScratch("_calibration.json", data, size);
  gravcal::LoadedCalibration calibration;
  std::string error;
  const bool ok = gravcal::ReadCalibrationJson(path, &calibration, &error);
  gravcal::fuzz::RequireOutcome(ok, error);
  if (ok) {
    Require(calibration.accel.bias.allFinite() && calibration.accel.upper.allFinite(),
            "non-finite accelerometer model");
  }
  return 0;
}
