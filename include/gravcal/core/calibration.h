// gravcal/core/calibration.h: the result every calibration method returns:
// the accelerometer and gyroscope models with their uncertainty, the effect
// terms, per-position residuals, the solver's report, warnings and, for
// recursive methods, the estimate history and convergence times.
#ifndef GRAVCAL_CORE_CALIBRATION_H_
#define GRAVCAL_CORE_CALIBRATION_H_

#include <Eigen/Core>
#include <cmath>
#include <string>
#include <vector>

#include "gravcal/core/accel_model.h"
#include "gravcal/core/gravity.h"
#include "gravcal/core/gyro_model.h"
#include "gravcal/core/imu_corrector.h"
#include "gravcal/core/imu_log.h"
#include "gravcal/core/model_effects.h"
#include "gravcal/core/position.h"
#include "gravcal/core/solver_result.h"
#include "gravcal/core/thermal_model.h"
#include "gravcal/core/types.h"

namespace gravcal {

// Summary of |a_k| - g over the positions, m/s^2.
struct ResidualSummary {
  double rms = 0.0;
  double max = 0.0;
};

// The rms and the largest absolute value of `residuals` (0 for none).
ResidualSummary SummarizeResiduals(const std::vector<double>& residuals);

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
  // The per-pose variance of |a| beyond the white noise, (m/s^2)^2
  // (twelve_position; methods/pose_variance.h).
  VarianceComponent pose_variance;
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
  // The gyroscope's noise in the hold: the standard deviation of one sample
  // per axis, rad/s, taken from the hold's raw gyroscope samples through the
  // calibration's gyroscope model (sqrt diag(M_g C M_g^T), C their sample
  // covariance) or, without one, the config's gyro_nominal_scale. NaN when
  // the log has no gyroscope or its unit is not known (no gyroscope model
  // and gyro_nominal_scale not set).
  Eigen::Vector3d gyro_std = Eigen::Vector3d::Constant(NAN);
  int nominal_up = -1;
  double residual_before = 0.0;
  double residual_after = 0.0;
  double sigma = 0.0;
  // |a| - g, m/s^2, with the nominal scale and after the coarse fit (for
  // the report); NaN where the method has no such stage.
  double residual_nominal = NAN;
  double residual_coarse = NAN;
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

// Where a calibration came from (calibration JSON key `provenance`): the
// log's file name and content hash (32 hex digits, util/content_hash.h over
// the file's bytes), and the gravcal version that wrote it. Empty = unknown.
struct CalibrationProvenance {
  std::string log_file;
  std::string log_hash;
  std::string gravcal_version;
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
  // Issue 35: bias, scale and misalignment against temperature
  // (thermal_model.h; calibration JSON key `thermal`). Inactive (all orders
  // 0) unless a thermal method filled it.
  ThermalModel thermal;
  // The method that produced this result (config key `method`).
  std::string method = ToString(Method::kTwelvePosition);
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
  // The code of each warning (same index; core/types.h WarningCode).
  std::vector<WarningCode> warning_codes;
  std::string message = "Calibrate was not called";
  // Issue 4: filled by recursive methods only.
  EstimateHistory history;
  ConvergenceReport convergence;
  // Issue 16: the input log (set by the caller that read it).
  CalibrationProvenance provenance;

  // The model this result holds, as apply, the exporters and Python apply
  // it (core/imu_corrector.h): the accelerometer, the gyroscope when
  // estimated, and the effects switched on with their values (their
  // reference temperature and time; accel_misalignment lives in
  // accel.model.upper). An effect parameter the data did not determine
  // (NaN) counts as 0, and its key, effects.<effect>.<parameter>, is added
  // to *undetermined (may be null). False with a one-line message naming
  // the key when the parts disagree: an effect with the wrong number of
  // values, a gyroscope effect without a gyroscope model, a temperature
  // effect without a reference temperature.
  bool Model(ImuCorrector* model, std::vector<std::string>* undetermined, std::string* error) const;

  // One line: the message and the fit's residual |a| - g before and after
  // (only after, when the raw data were read without a nominal scale).
  std::string BriefReport() const;
  // Several lines: the message, gravity, every estimate with its standard
  // deviation (or "not determined"), the residuals, the solver and the
  // warnings.
  std::string FullReport() const;
};

}  // namespace gravcal

#endif  // GRAVCAL_CORE_CALIBRATION_H_
