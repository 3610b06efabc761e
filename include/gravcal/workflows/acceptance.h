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
//
// Parameter names are compare's (estimation/calibration_comparison.h):
// model names (accel.bias_x, accel.u_xy, accel.rot_z, gyro.m_xy) and the
// intrinsic ones (accel.sensitivity_x, accel.nonorth_yz). A limit on a
// parameter the calibration does not estimate, or on the sigma of one it
// does not determine, fails with that said.
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
};

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

struct CertificateEntry {
  std::string name;
  std::string unit;
  double value = NAN;
  // NaN when the calibration does not determine the parameter.
  double standard_uncertainty = NAN;
  double expanded_uncertainty = NAN;
  // (source, standard uncertainty) whose squares sum to u_c^2.
  std::vector<std::pair<std::string, double>> budget;
};

struct Certificate {
  CertificateInfo info;
  double gravity = NAN;
  std::string gravity_source;
  double gravity_std = NAN;
  std::string method;
  double residual_rms = NAN;
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
// A self-contained HTML page (no script, no external resource).
std::string CertificateToHtml(const Certificate& certificate);

}  // namespace gravcal

#endif  // GRAVCAL_WORKFLOWS_ACCEPTANCE_H_
