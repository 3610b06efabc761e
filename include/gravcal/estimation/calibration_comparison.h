// gravcal/estimation/calibration_comparison.h: is it the same unit, unchanged?
// The statistical comparison of two calibrations (gravcal compare) and the
// result verify shares with it.
//
// Each calibration is a parameter vector p with covariance C (the
// covariance the calibration JSON carries). For the parameters both
// calibrations determine, the difference d = p_b - p_a has, when both are
// of the same unchanged unit and independent, covariance S = C_a + C_b, and
//
//   per parameter   z_j = d_j / sqrt(S_jj)                    ~ N(0, 1)
//   joint           chi2 = d^T S^+ d,  dof = rank(S)          ~ chi2(dof)
//   one term        t_j = (e_j^T S^+ d) / sqrt(e_j^T S^+ e_j) ~ N(0, 1)
//
// S^+ is the pseudo-inverse on the range of S (eigenvalues of the
// correlation matrix below 1e-10 of the largest are dropped), so a
// combination neither calibration determines adds nothing. t_j is the
// likelihood-ratio statistic for "only parameter j changed"; the
// parameter with the largest |t_j| is the one named, with its estimated
// change (e_j^T S^+ d) / (e_j^T S^+ e_j) in sigma of the difference.
//
// The verdict combines the two tests by Bonferroni: the joint chi-square
// (powerful against changes spread over many terms) and the largest |t_j|
// over the m compared parameters (powerful against one term moving; at 5
// sigma of the difference in one of nine parameters it has power 0.94 at
// level 0.01 where the chi-square alone has 0.87):
//
//   p = min(1, 2 min(p_chi2, p_max)),  p_max = min(1, m P(|N(0,1)| > max|t_j|)),
//
// which is a valid p-value for "unchanged" (its false-alarm rate is at most
// the level). consistent = p >= level.
//
// Parameter spaces:
//  - model: the calibration's own parameters (accel.bias_*, accel.u_*,
//    accel.m_*, accel.rot_*, gyro.bias_*, gyro.m_*), for two calibrations of
//    the same unit in the same mounting;
//  - intrinsic: the nine mount-invariant intrinsic parameters of a
//    three-axis accelerometer of Geist, Afridi, McGray and Gaitan (NIST),
//    "Gravity-based characterization of three-axis accelerometers in terms
//    of intrinsic accelerometer parameters", J. Res. NIST 122:32 (2017),
//    doi:10.6028/jres.122.032. With v = S a + b (S = M^-1, raw units per
//    m/s^2, rows s_x, s_y, s_z the axes' sensitivity vectors), they are the
//    offsets b_i (raw), the sensitivities |s_i| (raw per m/s^2) and the
//    angles between sensitivity vectors less 90 degrees (rad): nonorth_xy,
//    nonorth_xz, nonorth_yz. A remounting M -> Q M (Q a rotation) gives
//    S -> S Q^T and leaves S S^T, hence all nine, unchanged. Accelerometer
//    only. Their covariance is J C J^T with J by central differences.
#ifndef GRAVCAL_ESTIMATION_CALIBRATION_COMPARISON_H_
#define GRAVCAL_ESTIMATION_CALIBRATION_COMPARISON_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "gravcal/core/calibration.h"

namespace gravcal {

enum class ComparisonSpace {
  kModel,
  kIntrinsic,
};

const char* ToString(ComparisonSpace space);
bool FromString(const std::string& name, ComparisonSpace* space);
std::string AcceptedNames(ComparisonSpace);

// A calibration's parameters as one vector with its covariance.
struct ParameterVector {
  // "accel.bias_x", "accel.u_xy", "accel.sensitivity_x", "gyro.m_xy", ...
  std::vector<std::string> names;
  Eigen::VectorXd values;
  // In names order; empty when the calibration carries none.
  Eigen::MatrixXd covariance;
  // False where the calibration reports the parameter as not determined
  // by its data (a null standard deviation).
  std::vector<bool> determined;
  // Why there is no covariance, or "" (for the messages).
  std::string note;
  // Names in the calibration's covariance the space has no value for
  // (effect terms, g-sensitivity): compare lists them as not compared.
  std::vector<std::string> left_out;
};

// The parameters of `calibration` in `space`. The accelerometer's part needs
// accel.covariance (with its names); the gyroscope's is added when it was
// estimated and has a covariance. Names the space cannot map to a value
// (effect terms) are left out. False with a message when the space cannot be
// formed (no accelerometer covariance, a singular sensor matrix).
bool CalibrationParameters(const Calibration& calibration, ComparisonSpace space,
                           ParameterVector* parameters, std::string* error);

// One compared parameter.
struct ParameterDifference {
  std::string name;
  // b - a, its standard deviation sqrt(S_jj) and z = difference / std.
  double difference = 0.0;
  double std = 0.0;
  double z = 0.0;
  // t_j above (NaN when the parameter lies outside the range of S).
  double shift_z = NAN;
};

// The answer of compare and verify (docs/data_contract.md, compare.json).
struct ComparisonResult {
  // Whether the test was made (both have covariances, something to compare).
  bool tested = false;
  bool consistent = true;
  double p_value = NAN;
  double level = 0.01;
  double chi2 = NAN;
  int dof = 0;
  double chi2_p_value = NAN;
  double max_shift_p_value = NAN;
  std::vector<ParameterDifference> parameters;
  // Parameters one or both calibrations do not determine (left out of the
  // test), and names only one of them has (not compared).
  std::vector<std::string> undetermined;
  std::vector<std::string> not_compared;
  // The term most likely to have changed (largest |t_j|), its estimated
  // change in the parameter's unit and in sigma of the difference; "" when
  // consistent. Parameters whose one-term changes this data cannot tell
  // apart from it (|correlation| > 0.9 in S^+) are listed with it.
  std::string changed;
  double changed_size = NAN;
  double changed_sigmas = NAN;
  std::vector<std::string> indistinguishable;
  // The smallest change of each compared parameter this test detects with
  // `power` at `level` by the one-term test (same order as parameters;
  // verify fills it, compare too).
  double power = 0.9;
  std::vector<double> minimal_detectable_change;
  std::string message = "Compare was not called";
};

struct ComparisonOptions {
  // The significance level: "changed" when p < level.
  double level = 0.01;
  // The power the minimal detectable change is stated for.
  double power = 0.9;

  bool IsValid(std::string* error) const;
};

// Compares a and b (same space). Returns false (message set) only for
// invalid options; a calibration without covariance gives tested = false
// with the message saying which.
bool CompareParameters(const ParameterVector& a, const ParameterVector& b,
                       const ComparisonOptions& options, ComparisonResult* result);

// The test above in its general form, which compare and verify share: an
// observation y with covariance S that is zero when nothing changed, and
// per parameter j the change of y a unit change of j makes (column j of H).
// compare: y = d, H = I; verify: y the check poses' residuals, H their
// Jacobian. t_j = (H_j^T S^+ y) / sqrt(H_j^T S^+ H_j); each parameter's row
// reports its estimated one-term change (H_j^T S^+ y) / (H_j^T S^+ H_j), its
// standard deviation and t_j; `reference_std` (one per parameter) sizes the
// named change in sigmas (compare: sqrt(S_jj); verify: the stored sigma).
struct ShiftTestInput {
  std::vector<std::string> names;
  Eigen::VectorXd y;
  Eigen::MatrixXd s;
  Eigen::MatrixXd h;
  Eigen::VectorXd reference_std;
};
// Fills result's test fields (tested, consistent, p-values, parameters,
// changed, indistinguishable, minimal_detectable_change). False with the
// message when the sizes disagree.
bool TestShifts(const ShiftTestInput& input, const ComparisonOptions& options,
                ComparisonResult* result);

// One line: "consistent (p = 0.42, chi2 = 7.1 on 9 dof)" or "changed:
// accel.bias_z moved by 0.08 (11.0 sigma); p = 1e-12".
std::string ComparisonSummary(const ComparisonResult& result);

}  // namespace gravcal

#endif  // GRAVCAL_ESTIMATION_CALIBRATION_COMPARISON_H_
