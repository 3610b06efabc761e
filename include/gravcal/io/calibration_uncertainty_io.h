// gravcal/io/calibration_uncertainty_io.h: a calibration JSON file read with
// its uncertainty (docs/data_contract.md, "Calibration JSON"): the models as
// CalibrationFromJson reads and checks them, plus accel.std,
// accel.covariance, gyro.std and gyro.covariance, which compare and verify
// test against. A file without a covariance is read (its covariance left
// empty); a covariance that is present must be a square matrix of finite
// numbers with one named parameter per row, symmetric, or the file is
// refused naming the key.
#ifndef GRAVCAL_IO_CALIBRATION_UNCERTAINTY_IO_H_
#define GRAVCAL_IO_CALIBRATION_UNCERTAINTY_IO_H_

#include <string>

#include "gravcal/core/calibration.h"
#include "gravcal/io/calibration_io.h"

namespace gravcal {

// Fills calibration->accel (model, bias_std, matrix_std, covariance and its
// names), ->gyro (the same, estimated when the file has "gyro"), ->gravity,
// ->method, ->provenance, ->thermal, ->residual_refined.rms
// (residual.after.rms, NaN when absent) and ->positions (t_begin, t_end,
// raw_mean, samples, raw_std, gyro_std and temperature; NaN where absent);
// `loaded` (may be null) receives what
// ReadCalibrationJson reads. Errors are one line naming the file and key.
bool CalibrationUncertaintyFromJson(const std::string& text, const std::string& name,
                                    Calibration* calibration, LoadedCalibration* loaded,
                                    std::string* error);
bool ReadCalibrationUncertainty(const std::string& path, Calibration* calibration,
                                LoadedCalibration* loaded, std::string* error);

}  // namespace gravcal

#endif  // GRAVCAL_IO_CALIBRATION_UNCERTAINTY_IO_H_
