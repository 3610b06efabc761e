// gravcal/io/calibration_io.h: the calibration JSON file (docs/data_contract.md, "Calibration
// JSON"): accel.{model, bias, matrix, std.{bias, matrix}, covariance},
// gravity, residual, positions, solver, warnings. Standard deviations that
// were not estimated are null. Written atomically.
#ifndef GRAVCAL_IO_CALIBRATION_IO_H_
#define GRAVCAL_IO_CALIBRATION_IO_H_

#include <string>

#include "gravcal/core/accel_model.h"
#include "gravcal/core/calibration.h"
#include "gravcal/core/gyro_model.h"

namespace gravcal {

// The calibration as JSON text (2-space indent). `include_covariance` adds
// accel.covariance with its parameter order.
std::string CalibrationToJson(const Calibration& calibration, bool include_covariance);

bool WriteCalibrationJson(const Calibration& calibration, bool include_covariance,
                          const std::string& path, std::string* error);

// Issue 4: the time history of a recursive method (calibration.history) as
// CSV: a header row with the column names, then one row per epoch. Fails
// (naming the path) when there is no history or the file cannot be written.
bool WriteHistoryCsv(const Calibration& calibration, const std::string& path, std::string* error);

// What `apply` needs from a calibration file: the accelerometer model and,
// when the file has one, the gyroscope model.
struct LoadedCalibration {
  AccelModel accel;
  bool has_gyro = false;
  GyroModel gyro;
  double gravity = kStandardGravity;
};

// Reads a calibration JSON file; errors name the file and the key.
bool ReadCalibrationJson(const std::string& path, LoadedCalibration* calibration,
                         std::string* error);
// Same as ReadCalibrationJson on JSON text in memory; `name` is used in
// messages in place of the path.
bool ParseCalibrationJson(const std::string& text, const std::string& name,
                          LoadedCalibration* calibration, std::string* error);

}  // namespace gravcal

#endif  // GRAVCAL_IO_CALIBRATION_IO_H_
