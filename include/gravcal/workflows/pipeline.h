// gravcal/workflows/pipeline.h: one entry point that runs whichever calibration method
// a Config names, on one unit's data. `gravcal calibrate`, `gravcal batch`
// and library users all go through RunCalibration, so a unit calibrated in a
// batch gets exactly the result it would get alone.
//
// The flow: the log is read (by the caller, once), the side files the
// method needs are read into the Session as values, the static poses are
// detected once (for a method that reads the detector section), and the
// method (its registry entry) runs on the Session. The caller keeps the
// Session, so the report and the coverage check read the same detection.
#ifndef GRAVCAL_WORKFLOWS_PIPELINE_H_
#define GRAVCAL_WORKFLOWS_PIPELINE_H_

#include <string>

#include "gravcal/core/calibration.h"
#include "gravcal/core/imu_log.h"
#include "gravcal/methods/session.h"
#include "gravcal/workflows/config.h"

namespace gravcal {

// The files a unit brings besides its log (method_registry.h,
// MethodSideInput); empty when not given. Read for the methods that need
// them.
struct SessionFiles {
  // kAttitudes: the per-position attitude CSV (--attitudes).
  std::string attitudes_path;
  // kSegments: the rate table's constant-rate segments (--segments).
  std::string segments_path;
  // The noise model from `gravcal noise` (noise.json, --noise); empty = none.
  // Read for the methods that use one (CalibrationMethod::noise_model).
  std::string noise_path;
};

// What one unit brings besides the configuration.
struct PipelineInput : SessionFiles {
  // The raw log (accelerometer, and gyroscope when the method uses it).
  ImuLog log;
  // Name used in messages (the input path, or a unit id).
  std::string source = "input";
};

// Runs config.method (its registry entry) on the input, after reading the
// side input the method needs. Returns false with a one-line
// calibration->message on bad input, a method that cannot determine what it
// must, or no convergence (calibration->not_converged). Never prints, never
// exits.
bool RunCalibration(const Config& config, const PipelineInput& input, Calibration* calibration);

// The same on a session whose log is read: the side files are read into
// *session, its static poses detected (unless they already are), and the
// method run on it. *session keeps them for the report and the check.
bool RunCalibration(const Config& config, const SessionFiles& files, Session* session,
                    Calibration* calibration);

}  // namespace gravcal

#endif  // GRAVCAL_WORKFLOWS_PIPELINE_H_
