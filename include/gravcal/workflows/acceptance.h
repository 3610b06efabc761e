// gravcal/workflows/acceptance.h: acceptance limits and the calibration
// certificate (issue 36, production-line pass/fail).
//
// Limits file (YAML, calibrate --limits):
//
//   parameters:
//     accel.bias_z: {min: -0.2, max: 0.2, max_std: 0.002}
//     accel.u_xx: {min: 0.99, max: 1.01}
//     accel.nonorth_xy: {max_std: 0.001}      # intrinsic names too
//   residual_rms: 0.005     # |a| - g rms after calibration, m/s^2
//   gravity_std: 0.0001     # standard uncertainty of the gravity used, m/s^2
//   accel_noise_density: 0.002   # m/s^2/sqrt(Hz), the largest axis, measured in the holds
//   gyro_noise_density: {min: 5e-5, max: 5e-4}   # rad/s/sqrt(Hz), the same way
//   temperature: {min: 15, max: 35}   # degC, every hold, where the log has temperature
//   temperature_sensitivity: {accel_bias: 0.5, gyro_bias: 0.05}   # mg/K, deg/s/K
//
// Parameter names are compare's (estimation/calibration_comparison.h):
// model names (accel.bias_x, accel.u_xy, accel.rot_z, gyro.m_xy) and the
// intrinsic ones (accel.sensitivity_x, accel.nonorth_yz). A limit on a
// parameter the calibration does not estimate, or on the sigma of one it
// does not determine, fails with that said.
//
// Noise density: from the variance of each hold's mean that the fit used
// (the position's raw_mean_cov, as the config's pose_noise estimated it:
// white, or batch means that include correlated noise), taken through the
// calibrated matrix, sigma_mean_i^2 = (M diag(raw_mean_cov) M^T)_ii, m/s^2,
// and the hold's duration T: N_i = sigma_mean_i sqrt(T) (white noise of
// density N has a mean over T of variance N^2 / T). The calibration JSON
// keeps raw_std = sqrt(samples diag(raw_mean_cov)), so
// N_i^2 = (M diag(raw_std^2) M^T)_ii / f_s with f_s = (samples - 1) / T.
// The median over the holds per axis; the limit applies to the largest axis.
// Hand tremor in a hold raises it: it is the noise the calibration saw.
// The gyroscope's the same way, N_i = gyro_std_i / sqrt(f_s) in
// rad/s/sqrt(Hz) (1 deg/s/sqrt(Hz) = 0.0174533 rad/s/sqrt(Hz)), from each
// hold's gyro_std (core/calibration.h: through the gyroscope model, or the
// config's gyro_nominal_scale when the calibration has none; without either
// the raw unit is unknown and the limit fails as not measured). A noise
// density limit is a number (the maximum) or a map {min, max}: a minimum
// catches a stuck or disconnected sensor, whose holds show no noise.
//
// Temperature: every hold's mean temperature must lie in [min, max]. A log
// without temperature leaves the limit not checked (listed as such, not
// failed): the limit applies where the data carry temperature.
//
// Temperature sensitivity (issue 35's thermal model): the largest slope of
// the bias against temperature over the calibration's valid range and the
// three axes, taken through the calibrated matrix to SI,
// max_T,i |(M d db(x)/dx)_i|, in mg/K (accelerometer, g = 9.80665 m/s^2)
// and deg/s/K (gyroscope). A calibration without a thermal model leaves it
// not checked (said); one whose bias term was fitted as constant has 0.
//
// Certificate: each parameter with its standard uncertainty u_c and the
// expanded uncertainty U = k u_c (k = 2), and the budget whose squares sum to
// u_c^2:
//   - noise: the share of the fit variance from the poses' noise of the mean,
//   - pose scatter: the share from the per-pose variance the fit absorbed
//     (methods/pose_variance.h); the fit variance is split between the two in
//     proportion of their mean per-pose variances (exact when every pose has
//     the same noise);
//   - gravity: a gravity error dg scales the sensor matrix by 1 + dg / g, so
//     u = |p| u_g / g for the matrix and sensitivity terms, 0 for biases and
//     angles. u_g is the limits file's gravity_std or, by the gravity's
//     source, 1e-4 m/s^2 (given), 5e-3 (normal gravity at a latitude: local
//     anomalies), 0.03 (standard gravity: anywhere on Earth);
//   - temperature: listed as not modelled unless the calibration fitted
//     temperature terms (then it is part of the fit's own variance).
#ifndef GRAVCAL_WORKFLOWS_ACCEPTANCE_H_
#define GRAVCAL_WORKFLOWS_ACCEPTANCE_H_

#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "gravcal/core/calibration.h"

namespace gravcal {

struct ParameterLimit {
  std::string name;
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  double max_std = std::numeric_limits<double>::infinity();
};

struct AcceptanceLimits {
  std::vector<ParameterLimit> parameters;
  double max_residual_rms = std::numeric_limits<double>::infinity();
  // <= 0: by the gravity's source (above).
  double gravity_std = 0.0;
  // m/s^2/sqrt(Hz), the largest axis of MeasuredAccelNoiseDensity.
  double min_accel_noise_density = -std::numeric_limits<double>::infinity();
  double max_accel_noise_density = std::numeric_limits<double>::infinity();
  // rad/s/sqrt(Hz), the largest axis of MeasuredGyroNoiseDensity.
  double min_gyro_noise_density = -std::numeric_limits<double>::infinity();
  double max_gyro_noise_density = std::numeric_limits<double>::infinity();
  // degC, every hold's mean temperature.
  double min_temperature = -std::numeric_limits<double>::infinity();
  double max_temperature = std::numeric_limits<double>::infinity();
  // mg/K and deg/s/K, ThermalSensitivity.
  double max_accel_bias_tempco = std::numeric_limits<double>::infinity();
  double max_gyro_bias_tempco = std::numeric_limits<double>::infinity();
};

// The largest |d bias / dT| of a sensor's thermal model over its valid
// range and axes (above): mg/K for the accelerometer, deg/s/K for the
// gyroscope; NaN when the calibration has no thermal model (or no such
// sensor).
double ThermalSensitivity(const Calibration& calibration, ThermalSensor sensor);

// The accelerometer's white-noise density per axis measured in the holds
// (above), m/s^2/sqrt(Hz); NaN where no hold has a sample count, a duration
// and a raw standard deviation.
Eigen::Vector3d MeasuredAccelNoiseDensity(const Calibration& calibration);
// The gyroscope's, rad/s/sqrt(Hz), from the holds' gyro_std; NaN where no
// hold has one.
Eigen::Vector3d MeasuredGyroNoiseDensity(const Calibration& calibration);

// Parses the limits YAML; `name` is used in messages. Errors are one line
// naming the file and key ("limits.yaml: key 'parameters.accel.bias_z.min':
// must be a number").
bool AcceptanceLimitsFromYaml(const std::string& text, const std::string& name,
                              AcceptanceLimits* limits, std::string* error);
bool ReadAcceptanceLimits(const std::string& path, AcceptanceLimits* limits, std::string* error);

// One limit applied.
struct LimitCheck {
  // "accel.bias_z value", "accel.bias_z std", "residual_rms".
  std::string name;
  double measured = NAN;
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool pass = false;
  // False for a limit the data cannot be checked against (temperature of a
  // log without temperature): it passes, and `why` says so.
  bool checked = true;
  // Why it failed ("0.31 above max 0.2", "not estimated"), "" when passed.
  std::string why;
};

struct AcceptanceResult {
  bool pass = true;
  std::vector<LimitCheck> checks;
  // One line: "pass (7 limits)" or "fail: accel.bias_z value 0.31 above max 0.2".
  std::string message;
};

// Applies `limits` to `calibration`. A failed calibration fails.
void CheckAcceptance(const Calibration& calibration, const AcceptanceLimits& limits,
                     AcceptanceResult* result);

// What the certificate records besides the calibration.
struct CertificateInfo {
  std::string unit;
  std::string station;
  // ISO 8601 UTC.
  std::string date;
  std::string software_version;
  // Content hash of the program that made it (util/content_hash.h).
  std::string software_hash;
  std::string input_file;
  std::string input_hash;
  // The configuration, as given (YAML text) and the file's name.
  std::string config_name;
  std::string config_text;
  double coverage_factor = 2.0;
};

// Where a share of a parameter's uncertainty comes from (its budget).
enum class UncertaintySource { kPlacement, kNoise, kPoseScatter, kGravity };
// "placement", "noise", "pose scatter", "gravity".
const char* ToString(UncertaintySource source);
bool FromString(const std::string& name, UncertaintySource* source);
std::string AcceptedNames(UncertaintySource);

struct CertificateEntry {
  std::string name;
  std::string unit;
  double value = NAN;
  // NaN when the calibration does not determine the parameter.
  double standard_uncertainty = NAN;
  double expanded_uncertainty = NAN;
  // (source, standard uncertainty) whose squares sum to u_c^2.
  std::vector<std::pair<UncertaintySource, double>> budget;
};

struct Certificate {
  CertificateInfo info;
  double gravity = NAN;
  std::string gravity_source;
  double gravity_std = NAN;
  std::string method;
  double residual_rms = NAN;
  // Measured in the holds: MeasuredAccelNoiseDensity, and the coldest and
  // hottest hold (NaN without temperature).
  Eigen::Vector3d accel_noise_density = Eigen::Vector3d::Constant(NAN);
  // MeasuredGyroNoiseDensity, rad/s/sqrt(Hz).
  Eigen::Vector3d gyro_noise_density = Eigen::Vector3d::Constant(NAN);
  double temperature_min = NAN;
  double temperature_max = NAN;
  std::vector<CertificateEntry> parameters;
  // Notes on the budget (temperature not modelled, the split rule).
  std::vector<std::string> notes;
  bool has_limits = false;
  AcceptanceResult acceptance;
};

// False with a message when the calibration failed or has no covariance.
bool MakeCertificate(const Calibration& calibration, const CertificateInfo& info,
                     const AcceptanceLimits* limits, Certificate* certificate, std::string* error);

std::string CertificateToJson(const Certificate& certificate);
// The verdict and each limit as JSON ({"verdict", "message", "limits": [...]}),
// the shape of the certificate's "limits" (Python's check_limits).
std::string AcceptanceToJson(const AcceptanceResult& result);
// A self-contained HTML page (no script, no external resource).
std::string CertificateToHtml(const Certificate& certificate);

// After a batch (workflows/batch_folder.h) wrote <output_dir>/<unit>.json:
// each calibrated unit against the limits (when given), its certificate
// (when certificate_dir is given: <certificate_dir>/<unit>.json and .html),
// and its calibration filed in the store (when given, under the unit's id
// and `info.date`). Writes <output_dir>/limits.csv (unit, verdict, failed)
// and adds "acceptance" to <output_dir>/summary.json ({limits, checked,
// pass, fail, failed: [{unit, why}]}) and a section to the fleet report
// (`report`, when it exists). A unit without <unit>.json failed in the batch
// (summary.json says why) and is skipped.
struct BatchAcceptanceOptions {
  // Not owned; null: no limits (certificates and the store only).
  const AcceptanceLimits* limits = nullptr;
  // The limits file's name (in summary.json and the report).
  std::string limits_name;
  std::string certificate_dir;
  std::string store;
  std::string report;
  // station, date, software, config; unit and input are filled per unit.
  CertificateInfo info;
};

struct BatchAcceptance {
  size_t checked = 0;
  size_t passed = 0;
  // (unit, the failed limits).
  std::vector<std::pair<std::string, std::string>> failed;
  size_t certificates = 0;
  size_t filed = 0;
};

// `units`: (unit id, its log's path). False with a one-line message naming
// the file on a read or write error.
bool AcceptBatchFolder(const std::string& output_dir,
                       const std::vector<std::pair<std::string, std::string>>& units,
                       const BatchAcceptanceOptions& options, BatchAcceptance* result,
                       std::string* error);

}  // namespace gravcal

#endif  // GRAVCAL_WORKFLOWS_ACCEPTANCE_H_
