#include "gravcal/methods/twelve_position.h"

#include <glog/logging.h>

#include <Eigen/Geometry>
#include <cmath>
#include <sstream>

#include "core/calibration_gravity.h"
#include "core/sensor_checks.h"
#include "core/warnings.h"
#include "estimation/accel_uncertainty.h"
#include "estimation/newton_solver.h"
#include "gravcal/estimation/housing_rotation.h"
#include "methods/pose_variance.h"
#include "methods/static_positions.h"
#include "util/source_prefix.h"
#include "util/statistics.h"
#include "util/units.h"

namespace gravcal {

using internal::MaxAbs;
using internal::NewtonOptions;
using internal::NewtonRefine;
using internal::PropagateUncertainty;
using internal::ResolveCalibrationGravity;
using internal::Rms;

bool CalibrationOptions::IsValid(std::string* error) const {
  if (!detector.IsValid(error) || !gravity.IsValid(error) || !coarse.IsValid(error) ||
      !refinement.IsValid(error) || !pose_noise.IsValid(error)) {
    return false;
  }
  if (!(nominal_scale > 0.0 && std::isfinite(nominal_scale))) {
    *error = "nominal_scale: must be positive";
    return false;
  }
  for (int up : nominal_up) {
    if (up < -1 || up > 5) {
      *error = "nominal_up: entries must be +x, -x, +y, -y, +z, -z or ?";
      return false;
    }
  }
  return true;
}

namespace {

ResidualSummary Summarise(const std::vector<double>& r) { return {Rms(r), MaxAbs(r)}; }

// The refinement with the configured solver (Ceres or the Newton baseline).
bool RefineWithSolver(const std::vector<Position>& placed, const CalibrationOptions& options,
                      Calibration* calibration) {
  Calibration& c = *calibration;
  const AccelParameterization p = options.refinement.parameterization;
  bool ok;
  if (options.solver == RefinementSolver::kCeres) {
    ok = Refine(placed, c.coarse.model, c.gravity, options.refinement, &c.refinement);
    c.solver_name = "ceres_levenberg_marquardt";
  } else {
    NewtonOptions newton;
    newton.parameterization = p;
    newton.residual = options.newton_residual;
    newton.max_iterations = options.refinement.solver.max_iterations;
    newton.compute_covariance = options.refinement.compute_covariance;
    ok = NewtonRefine(placed, c.coarse.model, c.gravity, newton, &c.refinement);
    c.solver_name = std::string("newton_") + ToString(options.newton_residual);
  }
  return ok;
}

// affine: the rotation of the sensor axes in the housing from the nominal
// axes of the axis-aligned positions, and the accelerometer's uncertainty
// with it (or without a housing rotation).
void AddHousingRotation(const std::vector<Position>& placed, AccelParameterization p,
                        Calibration* calibration) {
  Calibration& c = *calibration;
  std::string error;
  HousingRotation housing;
  bool have_housing = false;
  if (p == AccelParameterization::kAffine) {
    if (EstimateHousingRotation(placed, c.coarse.nominal_up, c.accel.model, &housing, &error)) {
      c.accel.model.rotation = housing.rotation;
      c.accel.tilt_rms = housing.tilt_rms;
      have_housing = true;
      std::ostringstream s;
      s.precision(3);
      s << "affine: bias, scale and non-orthogonality come from the gravity magnitude; the "
           "rotation of the sensor axes in the housing comes from the nominal axes of "
        << housing.positions_used << " axis-aligned positions (placement error seen: "
        << housing.tilt_rms * internal::kRadToDeg
        << " deg rms), so its accuracy is that of the placement";
      internal::AddWarning(WarningCode::kParameterSource, s.str(), &c.warnings, &c.warning_codes);
    } else {
      internal::AddWarning(WarningCode::kUndetermined,
                           "affine: the rotation of the sensor axes in the housing is not "
                           "determined (" +
                               error +
                               "); it is left at identity with no standard "
                               "deviation",
                           &c.warnings, &c.warning_codes);
    }
  }
  if (c.refinement.covariance_available) {
    PropagateUncertainty(c.refinement, have_housing ? &housing : nullptr, &c.accel);
    if (p == AccelParameterization::kAffine && !have_housing) c.accel.matrix_std.setConstant(NAN);
  }
}

}  // namespace

bool CalibrateFromPositions(const std::vector<Position>& positions,
                            const CalibrationOptions& options, Calibration* calibration) {
  CHECK(calibration != nullptr);
  *calibration = Calibration();
  Calibration& c = *calibration;
  std::string error;
  if (!options.IsValid(&error)) {
    c.message = error;
    return false;
  }
  if (!ResolveCalibrationGravity(options.gravity, calibration)) return false;
  const AccelParameterization p = options.refinement.parameterization;
  const int needed = p == AccelParameterization::kScale ? 6 : 9;
  if (static_cast<int>(positions.size()) < needed) {
    std::ostringstream s;
    s << "found " << positions.size() << " static positions; the '" << ToString(p)
      << "' model needs at least " << needed;
    c.message = s.str();
    return false;
  }
  std::vector<Position> placed = positions;
  if (!options.nominal_up.empty()) {
    if (options.nominal_up.size() != positions.size()) {
      std::ostringstream s;
      s << "nominal_up: gives " << options.nominal_up.size() << " axes for " << positions.size()
        << " detected positions";
      c.message = s.str();
      return false;
    }
    for (size_t k = 0; k < placed.size(); ++k) placed[k].nominal_up = options.nominal_up[k];
  }

  if (!CoarseFit(placed, c.gravity, p, options.coarse, &c.coarse)) {
    c.message = c.coarse.message;
    return false;
  }
  for (size_t k = 0; k < placed.size(); ++k) placed[k].nominal_up = c.coarse.nominal_up[k];

  const bool ok = RefineWithSolver(placed, options, &c);
  if (!ok) {
    c.message = c.refinement.message;
    return false;
  }
  if (options.solver == RefinementSolver::kCeres) {
    internal::AccountForPoseVariance(placed, c.coarse.model, c.gravity, options.refinement,
                                     &c.refinement, &c.accel.pose_variance);
  }
  c.accel.model = c.refinement.model;
  internal::AppendWarnings(c.refinement.warnings, c.refinement.warning_codes, "", &c.warnings,
                           &c.warning_codes);

  // Residual summaries.
  AccelModel nominal;
  nominal.upper = options.nominal_scale * Eigen::Matrix3d::Identity();
  const std::vector<double> nominal_residuals = MagnitudeResiduals(placed, nominal, c.gravity);
  const std::vector<double> coarse_residuals =
      MagnitudeResiduals(placed, c.coarse.model, c.gravity);
  c.residual_nominal = Summarise(nominal_residuals);
  c.residual_coarse = Summarise(coarse_residuals);
  c.residual_refined = Summarise(MagnitudeResiduals(placed, c.accel.model, c.gravity));

  AddHousingRotation(placed, p, &c);

  const std::vector<double>& sigmas = c.refinement.sigmas;
  for (size_t k = 0; k < placed.size(); ++k) {
    c.positions.push_back(internal::MakePositionReport(
        placed[k], c.refinement.residuals_before[k],
        c.refinement.residuals_after.empty() ? NAN : c.refinement.residuals_after[k], sigmas[k]));
    c.positions.back().residual_nominal = nominal_residuals[k];
    c.positions.back().residual_coarse = coarse_residuals[k];
  }

  const std::vector<std::string>& undetermined = c.refinement.observability.undetermined;
  if (!undetermined.empty() && !options.allow_undetermined) {
    std::string names;
    for (const std::string& n : undetermined) names += (names.empty() ? "" : ", ") + n;
    c.message = "the positions do not determine " + names + " of the '" + ToString(p) +
                "' model: record more poses with other axes up or down, choose a smaller "
                "parameterization (scale), or set allow_undetermined: true to report them "
                "without a number";
    return false;
  }
  if (!c.refinement.converged) {
    c.not_converged = true;
    c.accel = AccelCalibration();
    c.accel.model = c.coarse.model;
    c.message = "refinement did not converge (" + c.refinement.message +
                "); the coarse result is kept and is not a calibration to trust";
    return false;
  }
  c.success = true;
  std::ostringstream s;
  s << "calibrated '" << ToString(p) << "' from " << placed.size() << " positions ("
    << c.coarse.message << "; refinement " << c.refinement.message << ")";
  c.message = s.str();
  return true;
}

bool CalibrateAccelerometer(const ImuLog& log, const CalibrationOptions& options,
                            Calibration* calibration, std::vector<StaticInterval>* intervals) {
  Session session;
  session.log = log;
  return internal::CalibrateAccelerometer(session, options, calibration, intervals);
}

namespace internal {

bool CalibrateAccelerometer(const Session& session, const CalibrationOptions& options,
                            Calibration* calibration, std::vector<StaticInterval>* intervals) {
  CHECK(calibration != nullptr);
  *calibration = Calibration();
  std::vector<StaticInterval> detected;
  std::vector<std::string> data_warnings;
  if (!options.IsValid(&calibration->message) ||
      !SessionIntervals(session, options.detector, &detected, &calibration->message,
                        &data_warnings)) {
    return false;
  }
  if (intervals != nullptr) *intervals = detected;
  std::vector<Position> positions;
  std::vector<std::string> notes;
  if (!PosesFromIntervals(session.log, detected, options, &positions, &notes,
                          &calibration->message)) {
    return false;
  }
  const bool ok = CalibrateFromPositions(positions, options, calibration);
  for (const std::string& w : data_warnings) {
    AddWarning(WarningCode::kSensorData, w, &calibration->warnings, &calibration->warning_codes);
  }
  if (ok) {
    const std::string handedness =
        HandednessWarning("accelerometer", calibration->accel.model.matrix());
    if (!handedness.empty()) {
      AddWarning(WarningCode::kSensorData, handedness, &calibration->warnings,
                 &calibration->warning_codes);
    }
  }
  for (const std::string& n : notes) {
    AddWarning(WarningCode::kNoiseModel, n, &calibration->warnings, &calibration->warning_codes);
  }
  if (!ok) calibration->message = PrefixSource(session.log.source, calibration->message);
  return ok;
}

}  // namespace internal

}  // namespace gravcal
