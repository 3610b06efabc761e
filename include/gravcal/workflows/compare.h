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

// The check session's static poses are found with options.detector and
// their noise with options.pose_noise (the calibrate config's), then tested
// against `stored` (VerifyCheckSession). False with a one-line message naming
// the log when no pose is found or the log is invalid.
bool VerifyCheckLog(const ImuLog& log, const Calibration& stored, const CalibrationOptions& options,
                    const ComparisonOptions& comparison, CheckSessionResult* result,
                    std::string* error);

// The poses of a check as a JSON section ("poses" of verify.json).
std::string CheckPosesToJson(const CheckSessionResult& result);

}  // namespace gravcal

#endif  // GRAVCAL_WORKFLOWS_COMPARE_H_
