// gravcal/calibration.h: the multi-position accelerometer calibration, end to
// end: static detection -> positions -> coarse fit -> refinement (Ceres or
// the Newton baseline) -> housing rotation (affine) -> uncertainty.
//
// Where each parameter comes from:
// - b and U (bias, scale, non-orthogonality) from the gravity magnitude, the
//   fine step: independent of how well the poses were placed;
// - R (affine only) from the nominal axes of the axis-aligned positions: its
//   accuracy is that of the placement, and its uncertainty is estimated from
//   the placement errors the positions show.
#ifndef GRAVCAL_CALIBRATION_H_
#define GRAVCAL_CALIBRATION_H_

#include <Eigen/Core>
#include <cmath>
#include <string>
#include <vector>

#include "gravcal/accel_model.h"
#include "gravcal/coarse_fit.h"
#include "gravcal/gravity.h"
#include "gravcal/gyro_model.h"
#include "gravcal/imu_log.h"
#include "gravcal/model_effects.h"
#include "gravcal/newton_solver.h"
#include "gravcal/position.h"
#include "gravcal/refinement.h"
#include "gravcal/static_detector.h"

namespace gravcal {

enum class RefinementSolver { kCeres, kNewton };
const char* ToString(RefinementSolver solver);
// Accepts "ceres", "newton".
bool FromString(const std::string& name, RefinementSolver* solver);

struct CalibrationOptions {
  StaticDetectorOptions detector;
  GravityOptions gravity;
  CoarseFitOptions coarse;
  // The parameterisation, loss and covariance settings live here.
  RefinementOptions refinement;
  RefinementSolver solver = RefinementSolver::kCeres;
  // Only for solver = kNewton.
  NewtonResidual newton_residual = NewtonResidual::kSquaredMagnitude;
  // Raw units -> m/s^2 assumed before calibration (9.80665 / 16384 for a
  // +-2 g 16-bit accelerometer, 1 for data already in m/s^2); only used to
  // report the residual before calibration.
  double nominal_scale = 1.0;
  // The nominal up axis of each detected position in order ("+x", "-z",
  // "?"); empty = assign automatically.
  std::vector<int> nominal_up;
  // When the positions do not determine some parameter: false = fail with a
  // message naming it; true = succeed, report it without a standard
  // deviation and say so in the warnings.
  bool allow_undetermined = false;

  bool IsValid(std::string* error) const;
};

// Summary of |a_k| - g over the positions, m/s^2.
struct ResidualSummary {
  double rms = 0.0;
  double max = 0.0;
};

struct AccelCalibration {
  AccelModel model;
  // Standard deviations of b and of M = R U, element by element; NaN where
  // the parameter was not estimated (fixed by the parameterisation) or the
  // data does not determine it.
  Eigen::Vector3d bias_std = Eigen::Vector3d::Constant(NAN);
  Eigen::Matrix3d matrix_std = Eigen::Matrix3d::Constant(NAN);
  // Covariance of the estimated parameters, in covariance_names order
  // (bias_*, u_*, and for affine rot_x, rot_y, rot_z, the small rotation
  // vector of R in rad). Empty when not computed.
  Eigen::MatrixXd covariance;
  std::vector<std::string> covariance_names;
  // Placement error the axis-aligned positions show, rad (affine only).
  double tilt_rms = 0.0;
};

// The gyroscope part of a calibration, filled by the methods that estimate
// it (estimated = false otherwise, and the JSON has no "gyro" key).
struct GyroCalibration {
  bool estimated = false;
  GyroModel model;
  // Standard deviations of b_g (raw units) and of M_g, element by element;
  // NaN where the parameter was not estimated or is not determined.
  Eigen::Vector3d bias_std = Eigen::Vector3d::Constant(NAN);
  Eigen::Matrix3d matrix_std = Eigen::Matrix3d::Constant(NAN);
  // Covariance of the estimated gyroscope parameters, covariance_names order.
  Eigen::MatrixXd covariance;
  std::vector<std::string> covariance_names;
  // Method-specific scalar results with their standard deviations (for
  // example "g_sensitivity_xy" in rad/s per m/s^2), written as
  // gyro.extra.<name> = {value, std}.
  std::vector<std::string> extra_names;
  std::vector<double> extra_values;
  std::vector<double> extra_std;
  // One residual per rotation (or per segment) in degrees, when the method
  // has them.
  std::vector<double> rotation_residual_deg;
};

struct PositionReport {
  Position position;
  // sqrt of the diagonal of the sample covariance, raw units.
  Eigen::Vector3d raw_std = Eigen::Vector3d::Zero();
  int nominal_up = -1;
  double residual_before = 0.0;
  double residual_after = 0.0;
  double sigma = 0.0;
  // The attitude the method used for this position (ten_position: from
  // static alignment; known_attitude: as estimated with the fixture's
  // prior), degrees, and its standard deviation; NaN when the method has none.
  double roll_deg = NAN;
  double pitch_deg = NAN;
  double roll_std_deg = NAN;
  double pitch_std_deg = NAN;
};

// Issue 4: results of recursive estimators (the handheld Kalman filter).
// Time history: one row per filter epoch, `columns` names them (first "t",
// seconds), values row-major. Empty for batch methods.
struct EstimateHistory {
  std::vector<std::string> columns;
  std::vector<double> values;
  size_t rows() const { return columns.empty() ? 0 : values.size() / columns.size(); }
};

// When each estimated parameter converged, by the method's stated criterion.
struct ConvergenceEntry {
  std::string name;
  // Final estimate and its standard deviation at the start and at the end,
  // in the method's own units (see `unit`).
  double value = NAN;
  double sigma_initial = NAN;
  double sigma_final = NAN;
  std::string unit;
  // Seconds from the start of the log; NaN when it did not converge.
  double time = NAN;
  bool converged = false;
};

struct ConvergenceReport {
  std::string criterion;
  std::vector<ConvergenceEntry> entries;
};

struct Calibration {
  bool success = false;
  // The refinement ran and did not converge (the coarse result is kept).
  bool not_converged = false;
  AccelCalibration accel;
  GyroCalibration gyro;
  // Effects beyond the textbook model (config key `effects`); empty when
  // none were asked for.
  EffectCalibration effects;
  // The method that produced this result (config key `method`).
  std::string method = "twelve_position";
  double gravity = kStandardGravity;
  std::string gravity_source;
  // |a| - g over positions with the nominal scale, the coarse fit, the
  // refined model.
  ResidualSummary residual_nominal;
  ResidualSummary residual_coarse;
  ResidualSummary residual_refined;
  std::vector<PositionReport> positions;
  // The coarse result, kept when the refinement fails.
  CoarseFitResult coarse;
  RefinementResult refinement;
  std::string solver_name;
  std::vector<std::string> warnings;
  std::string message = "Calibrate was not called";
  // Issue 4: filled by recursive methods only.
  EstimateHistory history;
  ConvergenceReport convergence;
};

// From a raw log: detects the static positions, then CalibrateFromPositions.
// `intervals`, when given, receives the detected static intervals, so that
// later steps on the same log (gyroscope, effects) need not detect again.
bool CalibrateAccelerometer(const ImuLog& log, const CalibrationOptions& options,
                            Calibration* calibration,
                            std::vector<StaticInterval>* intervals = nullptr);

// From positions already extracted. Returns false with a one-line message
// on invalid options, too few positions (how many found, how many needed),
// no coarse fit, parameters the positions do not determine (unless
// allow_undetermined), or a refinement that did not converge (the coarse result
// is then in calibration->accel.model).
bool CalibrateFromPositions(const std::vector<Position>& positions,
                            const CalibrationOptions& options, Calibration* calibration);

}  // namespace gravcal

#endif  // GRAVCAL_CALIBRATION_H_
