#include "gravcal/methods/ten_position.h"

#include <glog/logging.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/warnings.h"
#include "gravcal/estimation/refinement.h"
#include "methods/pose_variance.h"
#include "methods/static_positions.h"
#include "util/units.h"

namespace gravcal {
namespace {

// Fewest positions: step 4 has six unknowns (bias and three scales).
constexpr int kMinTenPositions = 6;

// Aligns every position on the specific force f = transform(raw) of its
// samples. Returns false with a message naming the position.
template <typename Transform>
bool AlignPositions(const ImuLog& log, const std::vector<StaticInterval>& intervals,
                    const StaticAlignmentOptions& options, double gyro_scale, Transform transform,
                    std::vector<StaticAlignmentResult>* alignments, std::string* error) {
  alignments->assign(intervals.size(), StaticAlignmentResult());
  std::vector<Eigen::Vector3d> force, rate;
  for (size_t k = 0; k < intervals.size(); ++k) {
    const double dt = internal::IntervalSamples(log, intervals[k], 1.0, gyro_scale, &force, &rate);
    for (Eigen::Vector3d& f : force) f = transform(f);
    if (!AlignStatic(force, rate, dt, options, &(*alignments)[k])) {
      std::ostringstream s;
      s << "static position " << k << " (t " << intervals[k].t_begin << "-" << intervals[k].t_end
        << " s): " << (*alignments)[k].message;
      *error = s.str();
      return false;
    }
  }
  return true;
}

// The parameterization step 4 fits: the rotation of the axes in the housing
// is invisible to |g_a,k| = g, so affine is fitted as scale_misalignment.
AccelParameterization Step4Parameterization(AccelParameterization requested) {
  return requested == AccelParameterization::kAffine ? AccelParameterization::kScaleMisalignment
                                                     : requested;
}

// Step 4: g_0 from |g_a,k| = g, the part of the self-aligned reference the
// accelerometer's errors do not reach, with the scale (and, unless the
// model is `scale`, the non-orthogonality) the magnitude needs to fit.
// Fills c->refinement; false with c->message on failure.
bool FitZeroBias(const std::vector<Position>& positions, double nominal_scale,
                 const CalibrationOptions& options, const std::string& where, Calibration* c) {
  RefinementOptions step4 = options.refinement;
  step4.parameterization = Step4Parameterization(step4.parameterization);
  AccelModel initial;
  initial.parameterization = step4.parameterization;
  initial.upper = nominal_scale * Eigen::Matrix3d::Identity();
  if (!Refine(positions, initial, c->gravity, step4, &c->refinement)) {
    c->message = where + "step 4: " + c->refinement.message;
    return false;
  }
  c->solver_name = "ceres_levenberg_marquardt (step 4) + normal equations (step 5)";
  // What the samples of a pose cannot show (pose_variance), as in
  // twelve_position: every standard deviation below carries it.
  internal::AccountForPoseVariance(positions, initial, c->gravity, step4, &c->refinement,
                                   &c->accel.pose_variance);
  internal::AppendWarnings(c->refinement.warnings, c->refinement.warning_codes,
                           "step 4: ", &c->warnings, &c->warning_codes);
  if (!c->refinement.converged) {
    c->not_converged = true;
    c->message = where + "step 4 (zero bias) did not converge: " + c->refinement.message;
    return false;
  }
  const std::vector<std::string>& undetermined = c->refinement.observability.undetermined;
  if (!undetermined.empty() && !options.allow_undetermined) {
    std::string names;
    for (const std::string& u : undetermined) names += (names.empty() ? "" : ", ") + u;
    c->message = where + "step 4: the positions do not determine " + names +
                 ": use positions with other axes up, or set allow_undetermined: true";
    return false;
  }
  return true;
}

// Step 5: align again on the corrected specific force (the INS with the
// new zero bias), then K from the normal equations. Fills c->accel.model,
// the alignments `second` and the residual sum of squares of the K fit.
bool SolveK(const ImuLog& log, const std::vector<StaticInterval>& intervals,
            const std::vector<Position>& positions, const StaticAlignmentOptions& align,
            double gyro_nominal_scale, const std::string& where,
            std::vector<StaticAlignmentResult>* second, double* fit_rss, Calibration* c) {
  const int n = static_cast<int>(positions.size());
  const Eigen::Vector3d g0 = c->refinement.model.bias;
  const Eigen::Matrix3d upper = c->refinement.model.upper;
  StaticAlignmentOptions align2 = align;
  if (c->refinement.covariance_available) {
    const Eigen::Matrix3d bias_cov_si =
        upper * c->refinement.covariance.topLeftCorner<3, 3>() * upper.transpose();
    align2.accel_bias_std = std::max(std::sqrt(bias_cov_si.diagonal().maxCoeff()), 1e-6);
  }
  std::string error;
  if (!AlignPositions(
          log, intervals, align2, gyro_nominal_scale,
          [&](const Eigen::Vector3d& v) { return Eigen::Vector3d(upper * (v - g0)); }, second,
          &error)) {
    c->message = where + "step 5: " + error;
    return false;
  }
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d right = Eigen::Matrix3d::Zero();
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector3d d = positions[k].raw_mean - g0;
    normal += d * d.transpose();
    right += d * (*second)[k].gravity_body.transpose();
  }
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(normal);
  const Eigen::Matrix3d k_matrix = ldlt.solve(right).transpose();
  if (ldlt.info() != Eigen::Success || !k_matrix.allFinite() ||
      !AccelModel::FromMatrix(g0, k_matrix, AccelParameterization::kAffine, &c->accel.model)) {
    c->message = where + "step 5: the normal equations for K are singular (positions coplanar?)";
    return false;
  }
  *fit_rss = 0.0;
  for (int k = 0; k < n; ++k) {
    *fit_rss += ((*second)[k].gravity_body - k_matrix * (positions[k].raw_mean - g0)).squaredNorm();
  }
  return true;
}

// Uncertainty: bias and the diagonal of K from step 4 (the magnitude is
// the information); the off-diagonal of K is not determined. Adds the
// warning that says so and the alignments' own warnings, once each.
void ReportStep4Uncertainty(AccelParameterization step4_parameterization,
                            const std::vector<StaticAlignmentResult>& second, Calibration* c) {
  if (c->refinement.covariance_available) {
    c->accel.covariance = c->refinement.covariance;
    c->accel.covariance_names = c->refinement.parameter_names;
    const std::vector<std::string>& names = c->refinement.parameter_names;
    const char* diagonal[3] = {"u_xx", "u_yy", "u_zz"};
    for (int i = 0; i < 3; ++i) {
      c->accel.bias_std(i) = std::sqrt(c->refinement.covariance(i, i));
      const int at =
          static_cast<int>(std::find(names.begin(), names.end(), diagonal[i]) - names.begin());
      c->accel.matrix_std(i, i) = std::sqrt(c->refinement.covariance(at, at));
    }
  }
  for (const std::string& u : c->refinement.observability.undetermined) {
    if (u.rfind("bias_", 0) == 0) c->accel.bias_std(u[5] - 'x') = NAN;
    if (u.rfind("u_", 0) == 0) c->accel.matrix_std(u[2] - 'x', u[3] - 'x') = NAN;
  }
  internal::AddWarning(
      WarningCode::kMethodScope,
      std::string("ten_position: the reference gravity g_a comes from self-alignment on this "
                  "accelerometer, so its direction inherits the sensor's own axes: the "
                  "off-diagonal entries of K (installation misalignment") +
          (step4_parameterization == AccelParameterization::kScale
               ? " and non-orthogonality"
               : "; the non-orthogonality in the sensor's own frame is u_xy, u_xz, u_yz of the "
                 "covariance") +
          ") are not determined and have no standard deviation; bias and scale come from |g_a| = "
          "g (step 4). Use known_attitude for all twelve parameters",
      &c->warnings, &c->warning_codes);
  for (const StaticAlignmentResult& a : second) {
    for (size_t i = 0; i < a.warnings.size(); ++i) {
      const std::string line = "alignment: " + a.warnings[i];
      if (std::find(c->warnings.begin(), c->warnings.end(), line) == c->warnings.end()) {
        internal::AddWarning(
            i < a.warning_codes.size() ? a.warning_codes[i] : WarningCode::kUnclassified, line,
            &c->warnings, &c->warning_codes);
      }
    }
  }
}

}  // namespace

bool TenPositionOptions::IsValid(std::string* error) const {
  if (!alignment.IsValid(error)) return false;
  if (!(gyro_nominal_scale > 0.0) || !std::isfinite(gyro_nominal_scale)) {
    *error = "gyro_nominal_scale: must be positive (rad/s per raw gyroscope unit)";
    return false;
  }
  if (recommended_positions < kMinTenPositions) {
    *error = "recommended_positions: must be at least 6";
    return false;
  }
  return true;
}

bool TenPositionMethodOptions::IsValid(std::string* error) const {
  return accel.IsValid(error) && alignment.IsValid(error);
}

bool CalibrateTenPosition(const ImuLog& log, const CalibrationOptions& options,
                          const TenPositionOptions& ten, Calibration* calibration) {
  Session session;
  session.log = log;
  return CalibrateTenPosition(session, {options, ten}, calibration);
}

bool CalibrateTenPosition(const Session& session, const TenPositionMethodOptions& method,
                          Calibration* calibration) {
  CHECK(calibration != nullptr);
  *calibration = Calibration();
  const ImuLog& log = session.log;
  const TenPositionOptions& ten = method.alignment;
  CalibrationOptions options = method.accel;
  if (session.noise) options.pose_noise.model = session.noise_model();
  Calibration& c = *calibration;
  c.method = ToString(Method::kTenPosition);
  std::string error;
  if (!ten.IsValid(&error)) {
    c.message = error;
    return false;
  }
  std::vector<StaticInterval> intervals;
  std::vector<Position> positions;
  if (!internal::DetectStaticPositions(session, options, &c, &intervals, &positions)) return false;
  const std::string where = log.source.empty() ? "" : log.source + ": ";
  const int n = static_cast<int>(positions.size());
  if (n < kMinTenPositions) {
    std::ostringstream s;
    s << where << "found " << n << " static positions; the ten-position method needs at least "
      << kMinTenPositions << " (the patent uses 10 with different roll and pitch)";
    c.message = s.str();
    return false;
  }
  if (n < ten.recommended_positions) {
    std::ostringstream s;
    s << "only " << n << " static positions (the procedure has " << ten.recommended_positions
      << "): fewer positions, less averaging of the noise";
    internal::AddWarning(WarningCode::kFewPoses, s.str(), &c.warnings, &c.warning_codes);
  }

  // Steps 1-3: align every position on the raw data scaled to m/s^2 by one
  // factor taken from the data itself (g over the mean |raw|), as an INS with
  // only its nominal scale would.
  double mean_norm = 0.0;
  for (const Position& p : positions) mean_norm += p.raw_mean.norm();
  const double nominal_scale = c.gravity * n / mean_norm;
  StaticAlignmentOptions align = ten.alignment;
  align.gravity = c.gravity;
  if (std::isnan(align.latitude_deg)) align.latitude_deg = options.gravity.latitude;
  std::vector<StaticAlignmentResult> first;
  if (!AlignPositions(
          log, intervals, align, ten.gyro_nominal_scale,
          [&](const Eigen::Vector3d& v) { return Eigen::Vector3d(nominal_scale * v); }, &first,
          &error)) {
    c.message = where + error;
    return false;
  }

  // Step 4: the zero bias g_0 from the magnitude.
  if (!FitZeroBias(positions, nominal_scale, options, where, &c)) return false;

  // Step 5: K from the normal equations on the realigned positions.
  std::vector<StaticAlignmentResult> second;
  double fit_rss = 0.0;
  if (!SolveK(log, intervals, positions, align, ten.gyro_nominal_scale, where, &second, &fit_rss,
              &c)) {
    return false;
  }
  ReportStep4Uncertainty(Step4Parameterization(options.refinement.parameterization), second, &c);

  AccelModel nominal;
  nominal.upper = nominal_scale * Eigen::Matrix3d::Identity();
  internal::ReportPositions(positions, nominal, c.accel.model, c.gravity, c.refinement.sigmas, &c);
  c.residual_coarse = c.residual_nominal;
  for (int k = 0; k < n; ++k) {
    PositionReport& r = c.positions[k];
    r.roll_deg = second[k].roll * internal::kRadToDeg;
    r.pitch_deg = second[k].pitch * internal::kRadToDeg;
    r.roll_std_deg = second[k].roll_std * internal::kRadToDeg;
    r.pitch_std_deg = second[k].pitch_std * internal::kRadToDeg;
  }
  c.success = true;
  std::ostringstream s;
  s.precision(3);
  s << "calibrated 'ten_position' from " << n << " positions (step 4 " << c.refinement.message
    << "; step 5: K from the normal equations, rms |g_a - K d| " << std::sqrt(fit_rss / n)
    << " m/s^2)";
  c.message = s.str();
  return true;
}

}  // namespace gravcal
