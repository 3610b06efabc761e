// gravcal/io/calibration_io.h: the calibration JSON file (docs/data_contract.md, "Calibration
// JSON"): accel.{model, bias, matrix, std.{bias, matrix}, covariance},
// gravity, residual, positions, solver, warnings, provenance. Standard deviations that
// were not estimated are null. Written atomically.
#ifndef GRAVCAL_IO_CALIBRATION_IO_H_
#define GRAVCAL_IO_CALIBRATION_IO_H_

#include <Eigen/Core>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "gravcal/core/accel_model.h"
#include "gravcal/core/calibration.h"
#include "gravcal/core/gyro_model.h"
#include "gravcal/core/imu_corrector.h"

namespace gravcal {

// The calibration as JSON text (2-space indent). `include_covariance` adds
// accel.covariance with its parameter order.
std::string CalibrationToJson(const Calibration& calibration, bool include_covariance);

bool WriteCalibrationJson(const Calibration& calibration, bool include_covariance,
                          const std::string& path, std::string* error);

// The same with extra top-level sections appended after the calibration's
// own keys: (key, JSON text) pairs, e.g. calibrate's "check" (plan_io.h,
// CoverageToJson). A section whose text is not valid JSON is left out.
using JsonSections = std::vector<std::pair<std::string, std::string>>;
std::string CalibrationToJson(const Calibration& calibration, bool include_covariance,
                              const JsonSections& sections);
bool WriteCalibrationJson(const Calibration& calibration, bool include_covariance,
                          const JsonSections& sections, const std::string& path,
                          std::string* error);

// Issue 4: the time history of a recursive method (calibration.history) as
// CSV: a header row with the column names, then one row per epoch. Fails
// (naming the path) when there is no history or the file cannot be written.
bool WriteHistoryCsv(const Calibration& calibration, const std::string& path, std::string* error);
// The text WriteHistoryCsv writes; false when there is no history.
bool HistoryToCsv(const Calibration& calibration, std::string* csv, std::string* error);

// One static position as the file records it (positions[k]): the mean raw
// accelerometer vector, the middle of its interval (s) and its mean
// temperature (NaN when the file has none).
struct RecordedPosition {
  Eigen::Vector3d raw_mean = Eigen::Vector3d::Zero();
  double time = 0.0;
  double temperature = NAN;
};

// What `apply` and `export` need from a calibration file: everything the
// correction uses (core/imu_corrector.h), the static positions, the gravity
// and where the calibration came from.
struct LoadedCalibration {
  ImuCorrector corrector;
  double gravity = kStandardGravity;
  std::string method;
  std::vector<RecordedPosition> positions;
  // provenance (empty in files written before it existed).
  CalibrationProvenance provenance;
  // Effect parameters the file reports as undetermined (null), read as 0.
  std::vector<std::string> undetermined;
};

// The checks every calibration is held to when it is read
// (docs/data_contract.md, "Calibration JSON: checks on load"):
// - accel.upper and accel.rotation are authoritative; accel.matrix must equal
//   rotation * upper to kCalibrationRelativeTolerance (Frobenius norm of the
//   difference over that of the product), and effects.accel_misalignment.value
//   must equal upper's (0,1), (0,2), (1,2) to the same tolerance relative to
//   the largest entry of upper. A file without upper and rotation has
//   accel.matrix authoritative (decomposed by QR).
// - rotation is orthonormal (|R^T R - I| <= kCalibrationRelativeTolerance per
//   entry) with det +1; upper is upper triangular with a positive diagonal.
// - accel.matrix and gyro.matrix pass CheckSensorMatrix.
constexpr double kCalibrationRelativeTolerance = 1e-9;
// Singular values of a sensor matrix lie in [min, max]: beyond these double
// arithmetic, not physics, breaks (M and M^-1 applied to readings of up to
// 1e150 stay finite). A well-conditioned 1e-120 * I is accepted.
constexpr double kCalibrationMinSingularValue = 1e-150;
constexpr double kCalibrationMaxSingularValue = 1e150;
// The largest condition number (largest / smallest singular value) of a
// sensor matrix: a triad whose axes differ in gain by more than this has
// lost an axis (a real sensor is near 1).
constexpr double kCalibrationMaxConditionNumber = 1e6;

// Checks a sensor matrix (raw units -> calibrated units): finite, det > 0 (a
// reflection is refused), singular values and condition number within the
// limits above. On failure sets `why` to what is wrong, without a key ("is a
// reflection (det = -1)").
bool CheckSensorMatrix(const Eigen::Matrix3d& m, std::string* why);

// Checks the models a calibration file was read into (CalibrationFromJson
// runs it; a future `verify` runs it on any LoadedCalibration): the
// accelerometer's rotation, upper and matrix and the gyroscope's matrix as
// above, every bias and effect finite. `error` names the file and key.
bool CheckCalibrationModels(const LoadedCalibration& calibration, const std::string& name,
                            std::string* error);

// Parses calibration JSON text; `name` is used in messages. Every error is
// one line naming the file and the key ("calib.json: key 'accel.bias': must
// be an array of 3 numbers"). Keys added after version 0.2.0 (provenance,
// positions[].temperature) are optional. The file is held to the checks
// above: a calibration that fails one is refused, naming the key (both keys
// when two redundant fields disagree).
bool CalibrationFromJson(const std::string& text, const std::string& name,
                         LoadedCalibration* calibration, std::string* error);
// The same for a file.
bool ReadCalibrationJson(const std::string& path, LoadedCalibration* calibration,
                         std::string* error);

// The provenance of a calibration made from the log at `path`: its file name
// as given, the content hash of its bytes and this gravcal's version.
bool LogProvenance(const std::string& path, CalibrationProvenance* provenance, std::string* error);
// The same from the log's bytes already in memory (batch).
CalibrationProvenance LogProvenanceOfBytes(const std::string& path, const std::string& bytes);

}  // namespace gravcal

#endif  // GRAVCAL_IO_CALIBRATION_IO_H_
