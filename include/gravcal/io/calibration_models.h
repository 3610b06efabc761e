// gravcal/io/calibration_models.h: from a calibration result in memory to
// what `apply` and `export` use (the corrector of core/imu_corrector.h, the
// recorded positions, gravity, provenance), without JSON text in between.
//
// The result is the LoadedCalibration that CalibrationFromJson gives for the
// text CalibrationToJson writes of the same result (the JSON numbers round
// trip exactly), held to the same checks (CheckCalibrationModels): an
// effect parameter the data did not determine (NaN) is read as 0 and named
// in `undetermined`, accel_misalignment lives in accel.upper.
#ifndef GRAVCAL_IO_CALIBRATION_MODELS_H_
#define GRAVCAL_IO_CALIBRATION_MODELS_H_

#include <string>

#include "gravcal/core/calibration.h"
#include "gravcal/io/calibration_io.h"

namespace gravcal {

// False with a one-line message naming `name` and the key when a model
// fails the checks on load.
bool ModelsFromCalibration(const Calibration& calibration, const std::string& name,
                           LoadedCalibration* models, std::string* error);

}  // namespace gravcal

#endif  // GRAVCAL_IO_CALIBRATION_MODELS_H_
