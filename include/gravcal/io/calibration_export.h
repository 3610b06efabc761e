// gravcal/io/calibration_export.h: a calibration written for the programs
// that use it (docs/workflows/export.md derives each conversion):
//
//   kalibr     imu.yaml: noise densities and Kalibr's scale-misalignment
//              intrinsics (accelerometers.M, gyroscopes.M, A, C_gyro_i, T_i_b)
//   openvins   kalibr_imu_chain.yaml for OpenVINS's "rpng" IMU model (Tw, Ta,
//              R_IMUtoGYRO, R_IMUtoACC, Tg) and the noise densities
//   ros        sensor_msgs/Imu covariances (discrete-time, at the log's rate)
//   px4        CAL_ACC0_*, CAL_GYRO0_* in QGroundControl's .params format, and
//              with a thermal model TC_A0_* / TC_G0_* (bias polynomials)
//   ardupilot  INS_ACCOFFS_*, INS_ACCSCAL_*, INS_GYROFFS_* as a .parm file,
//              and with a thermal model INS_TCAL1_* and the CALTEMPs
//   c          gravcal_correct.h / gravcal_correct.c, a C99 corrector with the
//              coefficients embedded
//
// What a target cannot hold is listed in ExportResult::dropped, with the rms
// of |a| - g over the calibration's own static positions with the truncated
// model against the full one, and written as a comment in the file.
#ifndef GRAVCAL_IO_CALIBRATION_EXPORT_H_
#define GRAVCAL_IO_CALIBRATION_EXPORT_H_

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "gravcal/core/imu_corrector.h"
#include "gravcal/core/noise_model.h"
#include "gravcal/io/calibration_io.h"

namespace gravcal {

enum class ExportTarget { kKalibr, kOpenVins, kRos, kPx4, kArduPilot, kC };

const char* ToString(ExportTarget target);
bool FromString(const std::string& name, ExportTarget* target);
// "kalibr, openvins, ros, px4, ardupilot or c".
std::string AcceptedNames(ExportTarget);
// kalibr, openvins and ros need a noise model.
bool NeedsNoise(ExportTarget target);

struct ExportOptions {
  ExportTarget target = ExportTarget::kC;
  // The calibration file's name, for the comment saying where it came from.
  std::string calibration_name;
  // Required when NeedsNoise(target).
  const ImuNoiseModel* noise = nullptr;
  // px4 with a thermal model: the device ids PX4 matches TC_A0_ID and
  // TC_G0_ID against (the vehicle's CAL_ACC0_ID, CAL_GYRO0_ID); 0 = not
  // given, and then the export is refused (it would do nothing).
  int64_t accel_device_id = 0;
  int64_t gyro_device_id = 0;
  // px4, ardupilot: leave the thermal model out (said in the file).
  bool drop_thermal = false;
  // ardupilot: the IMU instance n (1..3): INS_ACCnOFFS_*, INS_ACCnSCAL_*,
  // INS_GYRnOFFS_* (no n for the first IMU), INS_TCALn_*, INS_ACCn_CALTEMP,
  // INS_GYRn_CALTEMP.
  int ardupilot_imu = 1;
  bool IsValid(std::string* error) const;
};

struct ExportedFile {
  // Empty for single-file targets (the caller names it); the C target's two
  // file names.
  std::string name;
  std::string text;
};

struct ExportResult {
  std::vector<ExportedFile> files;
  // One line per dropped part of the model (empty = exact).
  std::vector<std::string> dropped;
  // rms of |a| - g over the recorded positions (m/s^2), full and truncated
  // model; NaN when the calibration records no positions.
  double full_rms = NAN;
  double truncated_rms = NAN;
  std::string message = "ExportCalibration was not called";
};

// False with a one-line *error when the calibration cannot be expressed at
// all (a PX4 scale outside its range, a missing noise term).
bool ExportCalibration(const LoadedCalibration& calibration, const ExportOptions& options,
                       ExportResult* result, std::string* error);

// rms over `positions` of |a| - g with `corrector` (positions at their
// recorded time and temperature). 0 for no positions.
double PositionResidualRms(const ImuCorrector& corrector,
                           const std::vector<RecordedPosition>& positions, double gravity);

// The correction a target holds, as an ImuCorrector: the model an exported
// file applies (used for the truncation error and in tests).
ImuCorrector TruncatedCorrector(const ImuCorrector& full, ExportTarget target);

}  // namespace gravcal

#endif  // GRAVCAL_IO_CALIBRATION_EXPORT_H_
