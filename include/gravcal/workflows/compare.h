// gravcal/workflows/compare.h: what gravcal compare and gravcal verify run
// besides the test itself (estimation/calibration_comparison.h,
// estimation/check_session.h): the difference two calibrations make to the
// corrected output of a log, and a check session read from a log.
#ifndef GRAVCAL_WORKFLOWS_COMPARE_H_
#define GRAVCAL_WORKFLOWS_COMPARE_H_

#include <string>

#include "gravcal/core/calibration.h"
#include "gravcal/core/imu_corrector.h"
#include "gravcal/core/imu_log.h"
#include "gravcal/estimation/check_session.h"
#include "gravcal/methods/twelve_position.h"

namespace gravcal {

// |a_b - a_a| over the samples of a log corrected by both calibrations
// (every term, core/imu_corrector.h), m/s^2, and the same for the
// gyroscope (rad/s) when both calibrations and the log have one.
struct OutputDifference {
  size_t samples = 0;
  double accel_rms = NAN;
  double accel_max = NAN;
  bool gyro = false;
  double gyro_rms = NAN;
  double gyro_max = NAN;
  // Samples one of the calibrations cannot correct (CorrectAccel false).
  size_t skipped = 0;
};

OutputDifference CorrectedOutputDifference(const ImuCorrector& a, const ImuCorrector& b,
                                           const ImuLog& log);

// As a JSON section ("output_difference" of compare.json).
std::string OutputDifferenceToJson(const OutputDifference& difference);

// Whether two calibrations map the same raw unit: their accelerometer
// matrices' mean scales |det M|^(1/3) (m/s^2 per raw unit), and the
// gyroscopes' when both have one, within a factor 2. A unit's own scale
// moves by percent; counts against m/s^2 or g against m/s^2 differ by a
// factor 9.8 or more, which no test of "the same unit, unchanged" should
// report as a change. False with a one-line message saying both scales.
bool SameRawUnits(const Calibration& a, const Calibration& b, std::string* error);

// The check session's static poses are found with options.detector and
// their noise with options.pose_noise (the calibrate config's), then tested
// against `stored` (VerifyCheckSession). False with a one-line message naming
// the log when no pose is found, the log is invalid, or its poses read
// |a| through the stored calibration more than a factor 2 from its gravity
// (the log's raw unit is not the calibration's).
bool VerifyCheckLog(const ImuLog& log, const Calibration& stored, const CalibrationOptions& options,
                    const ComparisonOptions& comparison, CheckSessionResult* result,
                    std::string* error);

// The poses of a check as a JSON section ("poses" of verify.json).
std::string CheckPosesToJson(const CheckSessionResult& result);

}  // namespace gravcal

#endif  // GRAVCAL_WORKFLOWS_COMPARE_H_
