// Fuzz target: the calibration JSON reader (apply, export). A calibration
// read must have a finite accelerometer model.
#include <cstdint>
#include <string>

#include "fuzz_check.h"
#include "gravcal/io/calibration_io.h"

using gravcal::fuzz::Require;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // The text parser itself (ReadCalibrationJson reads the file and calls it).
  const std::string text(reinterpret_cast<const char*>(data), size);
  gravcal::LoadedCalibration calibration;
  std::string error;
  const bool ok = gravcal::CalibrationFromJson(text, "calibration.json", &calibration, &error);
  gravcal::fuzz::RequireOutcome(ok, error);
  if (ok) {
    const gravcal::AccelModel& accel = calibration.corrector.accel;
    Require(accel.bias.allFinite() && accel.upper.allFinite(), "non-finite accelerometer model");
  }
  return 0;
}
