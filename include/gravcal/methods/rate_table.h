// gravcal/methods/rate_table.h: the classical gyroscope rate-table calibration, the
// baseline Sun, Ding, Yan compare the handheld filter with.
//
// The table turns the unit about one of its axes at a known constant rate;
// the mean gyroscope output over segment k is
//
//   u_k = A w_k + b_g,     A = M_g^-1   (gyro_model.h: w = M_g (u - b_g))
//
// with w_k the known body rate (rad/s). Each output axis i is a linear
// least-squares problem in (row i of A, b_g,i): one equation per segment,
// weighted by the variance of that segment's mean (sample variance / count).
// Rotations about all three axes in both directions (or one direction plus
// a still segment) determine the full A, so scale and misalignment; M_g =
// A^-1 and its covariance follow by first-order propagation (dM = -M dA M).
// The Earth rate (7.3e-5 rad/s) is part of w_k if the caller adds it;
// ignored for MEMS gyroscopes it is a bias-sized error.
#ifndef GRAVCAL_METHODS_RATE_TABLE_H_
#define GRAVCAL_METHODS_RATE_TABLE_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "gravcal/core/calibration.h"
#include "gravcal/core/imu_log.h"
#include "gravcal/core/rate_table_segment.h"
#include "gravcal/methods/session.h"

namespace gravcal {

struct RateTableResult {
  bool success = false;
  GyroCalibration gyro;
  // Per segment: rms over axes of (u_k - A w_k - b_g) in units of its standard
  // deviation.
  std::vector<double> normalized_residuals;
  std::string message = "CalibrateRateTable was not called";
};

// Fits the gyroscope model from the segments of `log`. Returns false with a
// message when the log has no gyroscope, a segment is out of range or has
// fewer than 2 samples, or the rates do not determine A and b_g (fewer than
// 4 segments, or the points (w_k, 1) do not span four dimensions, for
// example rotations about two axes only).
bool CalibrateRateTable(const ImuLog& log, const std::vector<RateTableSegment>& segments,
                        RateTableResult* result);

// The method reads no options section: the segments say everything.
struct RateTableMethodOptions {
  bool IsValid(std::string*) const { return true; }
};

// The same on a session's log and segments, as a Calibration: the
// gyroscope, with the accelerometer left the identity (a warning says so).
bool CalibrateRateTable(const Session& session, const RateTableMethodOptions& options,
                        Calibration* calibration);

}  // namespace gravcal

#endif  // GRAVCAL_METHODS_RATE_TABLE_H_
