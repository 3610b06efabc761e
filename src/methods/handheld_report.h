// Private: the results of the handheld calibration (handheld_kalman.h)
// from the final filter: the convergence report of every sensor state with
// the warnings on what the motion did not determine, and each sensor's
// estimate in the calibration models with its covariance.
#ifndef GRAVCAL_SRC_METHODS_HANDHELD_REPORT_H_
#define GRAVCAL_SRC_METHODS_HANDHELD_REPORT_H_

#include <Eigen/Core>
#include <sstream>
#include <string>
#include <vector>

#include "gravcal/core/calibration.h"
#include "gravcal/estimation/error_state_layout.h"
#include "gravcal/methods/handheld_kalman.h"
#include "methods/handheld_filter.h"

namespace gravcal {
namespace internal {

// v with three significant digits.
inline std::string FormatShort(double v) {
  std::ostringstream s;
  s.precision(3);
  s << v;
  return s.str();
}

// Fills the convergence report from the first pass's history (criterion in
// HandheldKalmanOptions) and warns about each state the motion did not
// determine; returns their names.
std::vector<std::string> ReportConvergence(const HandheldFilter& filter,
                                           const ErrorStateLayout& layout,
                                           const HandheldKalmanOptions& options, Calibration* c);

// One sensor's result in the calibration models: f = s (I + E)^-1 (v - b / s)
// is a = M (v - b_raw) with M = s (I + E)^-1 and b_raw = b / s (same for the
// gyroscope). Jacobians: db_raw/db = 1 / s, dM/dE_rc = -(1/s) M e_r e_c^T M.
// Entries of M that no estimated entry of E moves get NaN std.
struct SensorResult {
  Eigen::Vector3d bias;
  Eigen::Matrix3d matrix;
  Eigen::Vector3d bias_std;
  Eigen::Matrix3d matrix_std;
  Eigen::MatrixXd covariance;
  std::vector<std::string> names;
};

// The sensor at bias_offset / matrix_offset of the state (nominal scale
// `scale`, error terms `terms`) with its covariance from p.
SensorResult ToCalibrationModel(const HandheldSensorEstimate& est, double scale, int bias_offset,
                                int matrix_offset, const SensorErrorTerms& terms,
                                const Eigen::MatrixXd& p);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_METHODS_HANDHELD_REPORT_H_
