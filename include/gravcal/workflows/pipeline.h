// gravcal/workflows/pipeline.h: one entry point that runs whichever calibration method
// a Config names, on one unit's data. `gravcal calibrate`, `gravcal batch`
// and library users all go through RunCalibration, so a unit calibrated in a
// batch gets exactly the result it would get alone.
#ifndef GRAVCAL_WORKFLOWS_PIPELINE_H_
#define GRAVCAL_WORKFLOWS_PIPELINE_H_

#include <string>

#include "gravcal/core/calibration.h"
#include "gravcal/core/imu_log.h"
#include "gravcal/workflows/config.h"

namespace gravcal {

// What one unit brings besides the configuration.
struct PipelineInput {
  // The raw log (accelerometer, and gyroscope when the method uses it).
  ImuLog log;
  // Name used in messages (the input path, or a unit id).
  std::string source = "input";
  // Side input files (method_registry.h, MethodSideInput), read here for
  // the methods that need them; empty when not used.
  // kAttitudes: the per-position attitude CSV (--attitudes).
  std::string attitudes_path;
  // kSegments: the rate table's constant-rate segments (--segments).
  std::string segments_path;
  // The noise model from `gravcal noise` (noise.json, --noise); empty = none.
  // Read here for the methods that use one (CalibrationMethod::noise_model).
  std::string noise_path;
};

// Runs config.method (its registry entry) on the input, after reading the
// side input the method needs. Returns false with a one-line
// calibration->message on bad input, a method that cannot determine what it
// must, or no convergence (calibration->not_converged). Never prints, never
// exits.
bool RunCalibration(const Config& config, const PipelineInput& input, Calibration* calibration);

}  // namespace gravcal

#endif  // GRAVCAL_WORKFLOWS_PIPELINE_H_
