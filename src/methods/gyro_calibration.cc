#include "gravcal/methods/gyro_calibration.h"

#include <ceres/ceres.h>
#include <glog/logging.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "core/sensor_checks.h"
#include "core/warnings.h"
#include "estimation/accel_uncertainty.h"
#include "estimation/normalization.h"
#include "estimation/solver_settings.h"
#include "methods/direction_noise.h"
#include "methods/gyro_bias_wander.h"
#include "methods/gyro_covariance.h"
#include "methods/gyro_observability.h"
#include "methods/gyro_problem.h"
#include "methods/gyro_rotations.h"
#include "util/statistics.h"
#include "util/units.h"

namespace gravcal {

using internal::MaxAbs;
using internal::Normalization;
using internal::PropagateUncertainty;
using internal::Rms;

bool GyroCalibrationOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& what) {
    if (error) *error = what;
    return false;
  };
  if (!(loss_scale > 0.0 && std::isfinite(loss_scale))) {
    return fail("gyro_loss_scale: must be positive");
  }
  if (!(max_matrix_std > 0.0) || !(max_g_sensitivity_std > 0.0)) {
    return fail("gyro max_matrix_std, max_g_sensitivity_std: must be positive");
  }
  if (!(max_rotation_seconds > 0.0)) return fail("gyro max_rotation_seconds: must be positive");
  if (!(pose_variance >= 0.0) || !std::isfinite(pose_variance)) {
    return fail("gyro pose_variance: must be zero or positive");
  }
  if (!(edge_seconds >= 0.0 && std::isfinite(edge_seconds))) {
    return fail("gyro edge_seconds: must be zero or positive");
  }
  std::string solver_error;
  if (!solver.IsValid(&solver_error)) return fail("gyro " + solver_error);
  return true;
}

namespace internal {
namespace {

// Checks the inputs CalibrateGyroscope takes besides the log; false with
// *error.
bool CheckGyroInputs(const AccelModel& accel, const Eigen::MatrixXd& accel_covariance,
                     double gravity, const GyroCalibrationOptions& options, std::string* error) {
  if (!options.IsValid(error)) return false;
  if (options.parameterization == GyroParameterization::kNone) {
    *error = "gyro_model is 'none': there is nothing to calibrate";
    return false;
  }
  const int accel_parameters =
      3 + static_cast<int>(FreeUpperIndices(accel.parameterization).size());
  if (accel_covariance.size() > 0 &&
      (accel_covariance.rows() != accel_parameters || accel_covariance.cols() != accel_parameters ||
       !accel_covariance.allFinite())) {
    *error = "the accelerometer covariance must be finite and " + std::to_string(accel_parameters) +
             " x " + std::to_string(accel_parameters) + " (bias and free entries of U)";
    return false;
  }
  if (options.joint && !(gravity > 0.0 && std::isfinite(gravity))) {
    *error = "the joint accelerometer and gyroscope fit needs a positive gravity";
    return false;
  }
  return true;
}

// Initial values in normalised units: M' = M / k, b' = 0, G = 0, and
// (joint) the accelerometer's b_a', U' with the noise of every magnitude
// residual. False with *error when a pose has no accelerometer noise.
bool InitialValues(const GyroLayout& layout, const GyroPrepared& prep, const Eigen::Matrix3d& m0,
                   const AccelModel& accel, const Normalization& norm, bool joint,
                   std::vector<double>* x0, std::vector<double>* magnitude_sigmas,
                   std::string* error) {
  x0->assign(layout.size, 0.0);
  for (int i = 0; i < 9; ++i) (*x0)[layout.matrix + i] = m0(i / 3, i % 3) / prep.scale;
  if (!joint) return true;
  const AccelModel n = norm.Apply(accel);
  for (int i = 0; i < 3; ++i) (*x0)[layout.accel_bias + i] = n.bias(i);
  n.GetUpper(&(*x0)[layout.accel_upper]);
  if (accel.parameterization == AccelParameterization::kScale) {
    (*x0)[layout.accel_upper + 1] = (*x0)[layout.accel_upper + 2] = (*x0)[layout.accel_upper + 4] =
        0.0;
  }
  *magnitude_sigmas = MagnitudeSigmas(prep.positions, accel);
  for (double sigma : *magnitude_sigmas) {
    if (!(sigma > 0.0) || !std::isfinite(sigma)) {
      *error = "a static pose has no usable accelerometer noise estimate for the joint fit";
      return false;
    }
  }
  return true;
}

// The state of the solve: the estimate, the entries held, and the problem,
// weights and free columns of the last pass.
struct GyroSolve {
  std::vector<double> x;
  std::vector<bool> held;
  GyroWeights weights;
  GyroProblem built;
  GyroFreeColumns free;
  ceres::Solver::Summary summary;
  int iterations = 0;
  // Entries were held after the last solve: the estimate is not final.
  bool pending = false;
};

// Holds the entries in `weak` that can be held (matrix and G entries) at
// their initial value and records every name in *undetermined. Returns
// false with *error when the common scale itself is not determined; *changed
// tells whether a new entry was held.
bool HoldUndetermined(const std::vector<std::string>& weak, const GyroLayout& layout,
                      const std::vector<double>& x0, GyroSolve* solve,
                      std::vector<std::string>* undetermined, bool* changed, std::string* error) {
  *changed = false;
  for (const std::string& name : weak) {
    const auto it = std::find(layout.names.begin(), layout.names.end(), name);
    const int a = it == layout.names.end() ? -1 : static_cast<int>(it - layout.names.begin());
    if (name == "scale") {
      *error =
          "the rotations do not determine the gyroscope scale: the unit never turns "
          "about a horizontal axis between the static poses";
      return false;
    }
    if (a >= layout.matrix && (layout.accel_bias < 0 || a < layout.accel_bias)) {
      solve->held[a] = true;
      solve->x[a] = x0[a];
      *changed = true;
      undetermined->push_back(name);
    } else if (std::find(undetermined->begin(), undetermined->end(), name) == undetermined->end()) {
      undetermined->push_back(name);
    }
  }
  return true;
}

// Solves; then holds what the data does not determine and solves again, and
// re-weighs at the estimate while it still moves the weights (the noise of
// the integrated rate scales with M_g). False with *error on a failure
// other than non-convergence.
bool SolveHoldingUndetermined(const GyroPrepared& prep, const GyroLayout& layout,
                              const GyroCalibrationOptions& options, const AccelModel& accel,
                              const Normalization& norm, const std::vector<double>& x0,
                              const std::vector<double>& magnitude_sigmas, double gravity,
                              GyroSolve* solve, std::vector<std::string>* undetermined,
                              std::string* error) {
  ceres::Solver::Options solver_options = internal::SolverOptions(options.solver, ceres::DENSE_QR);
  // The rotations are evaluated in parallel for a single calibration; a
  // batch runs units in parallel instead, one thread each.
  solver_options.num_threads = internal::SingleCalibrationThreads();
  const AccelParameterization ap = accel.parameterization;
  solve->x = x0;
  solve->held.assign(layout.size, false);
  constexpr int kMaxPasses = 4;
  for (int pass = 0; pass < kMaxPasses; ++pass) {
    solve->pending = false;
    const AccelModel accel_now = GyroAccelAt(solve->x, layout, accel, norm);
    if (!WeighGyroResiduals(prep, layout, solve->x, accel_now, norm, &solve->weights, error)) {
      return false;
    }
    const std::vector<double> weighed_at = solve->x;
    BuildGyroProblem(prep, layout, options, ap, solve->held, solve->weights, magnitude_sigmas,
                     gravity, &solve->x, &solve->built);
    ceres::Solve(solver_options, solve->built.problem.get(), &solve->summary);
    solve->iterations += static_cast<int>(solve->summary.iterations.size()) - 1;
    if (!solve->summary.IsSolutionUsable()) break;

    solve->free = MakeGyroFreeColumns(layout, options.parameterization, ap, solve->held);
    const Eigen::MatrixXd jacobian =
        GyroAmbientJacobian(solve->built, layout, &solve->x) * solve->free.basis;
    bool changed = false;
    if (!HoldUndetermined(UndeterminedGyroParameters(jacobian, solve->free, options), layout, x0,
                          solve, undetermined, &changed, error)) {
      return false;
    }
    if (changed) {
      solve->pending = true;
      continue;
    }
    double moved = 0.0;
    for (int i = 0; i < 9; ++i) {
      moved =
          std::max(moved, std::fabs(solve->x[layout.matrix + i] - weighed_at[layout.matrix + i]));
    }
    if (moved < 1e-3) break;
  }
  return true;
}

// The angle between two directions, degrees.
double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * kRadToDeg;
}

// The residual of every rotation at the estimate x.
std::vector<GyroRotationReport> ReportRotations(const ImuLog& log, const GyroPrepared& prep,
                                                const GyroLayout& layout, const GyroSolve& solve,
                                                const AccelModel& accel_final,
                                                std::vector<double>* x) {
  std::vector<GyroRotationReport> reports;
  const size_t first_rotation_block = prep.static_gyro.size();
  for (size_t j = 0; j < prep.segments.size(); ++j) {
    const GyroSegment& seg = prep.segments[j];
    const GyroRotationData& d = solve.weights.rotations[j];
    GyroRotationReport report;
    report.from_pose = seg.from;
    report.to_pose = seg.to;
    report.first_sample = seg.first;
    report.last_sample = seg.last;
    report.t_begin = log.t[seg.first];
    report.t_end = log.t[seg.last];
    const Eigen::Vector3d ds = accel_final.Apply(prep.positions[seg.from].raw_mean).normalized();
    const Eigen::Vector3d de = accel_final.Apply(prep.positions[seg.to].raw_mean).normalized();
    report.gravity_angle_deg = AngleDeg(ds, de);
    double dq[4];
    IntegrateGyroRotation<double>(d, &(*x)[layout.bias], &(*x)[layout.matrix],
                                  layout.g >= 0 ? &(*x)[layout.g] : nullptr, dq);
    const Eigen::Vector3d predicted = RotationOf(dq).transpose() * ds;
    report.residual_deg = AngleDeg(predicted, de);
    report.sigma_deg = solve.weights.sigma_deg[j];
    const GyroProblem::Block& block = solve.built.blocks[first_rotation_block + j];
    std::vector<const double*> parameters;
    for (int o : block.offsets) parameters.push_back(x->data() + o);
    double residual[2];
    block.cost->Evaluate(parameters.data(), residual, nullptr);
    report.chi2 = residual[0] * residual[0] + residual[1] * residual[1];
    reports.push_back(report);
  }
  return reports;
}

// The estimate in SI / raw units, and the chi-square of all residuals
// (without the robust loss) at it.
void FillEstimate(const GyroPrepared& prep, const GyroLayout& layout, const GyroSolve& solve,
                  GyroCalibrationResult* result) {
  GyroCalibrationResult& r = *result;
  const std::vector<double>& x = solve.x;
  const double k = prep.scale;
  const Eigen::Matrix3d mn =
      Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(&x[layout.matrix]);
  r.model.matrix = k * mn;
  r.model.bias = prep.center + Eigen::Vector3d(x[0], x[1], x[2]) / k;
  if (layout.g >= 0) {
    r.g_sensitivity = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(&x[layout.g]);
  }
  if (!r.model.matrix.allFinite() || !r.model.bias.allFinite() || !r.g_sensitivity.allFinite()) {
    r.converged = false;
  }
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.apply_loss_function = false;
  double cost = 0.0;
  solve.built.problem->Evaluate(evaluate, &cost, nullptr, nullptr, nullptr);
  r.chi2 = 2.0 * cost;
  r.num_residuals = solve.built.rows;
  r.num_parameters = static_cast<int>(solve.free.names.size());
  r.dof = r.num_residuals - r.num_parameters;
}

// The joint fit's accelerometer as a refinement result.
void FillJointAccel(const GyroPrepared& prep, const AccelModel& accel,
                    const AccelModel& accel_final, const std::vector<double>& magnitude_sigmas,
                    double gravity, GyroCalibrationResult* r) {
  r->accel_refined = true;
  RefinementResult& a = r->accel;
  a.model = accel_final;
  a.converged = r->converged;
  a.parameter_names = MagnitudeParameterNames(accel.parameterization);
  a.num_parameters = static_cast<int>(a.parameter_names.size());
  a.num_residuals = static_cast<int>(prep.positions.size());
  a.sigmas = magnitude_sigmas;
  a.residuals_before = MagnitudeResiduals(prep.positions, accel, gravity);
  a.residuals_after = MagnitudeResiduals(prep.positions, accel_final, gravity);
  a.iterations = r->iterations;
  a.termination = r->termination;
  a.solve_seconds = r->solve_seconds;
  a.message = "refined jointly with the gyroscope";
}

// A warning when the residuals are far above the noise (chi-square test).
void WarnLargeResiduals(GyroCalibrationResult* result) {
  GyroCalibrationResult& r = *result;
  if (r.dof > 0) {
    const double p_value = ChiSquareUpperTail(r.chi2, r.dof);
    if (p_value < 1e-3) {
      std::ostringstream s;
      s.precision(3);
      s << "gyroscope residuals are " << std::sqrt(r.chi2 / r.dof)
        << " times the noise level (chi2 = " << r.chi2 << " on " << r.dof << " dof, p = " << p_value
        << "): the unit moved during a pose, the gyroscope has an effect the model lacks "
           "(g-sensitivity: set gyro_g_sensitivity), or its noise is not white; the standard "
           "deviations are too small by about that factor";
      internal::AddWarning(WarningCode::kResidualsAboveNoise, s.str(), &r.warnings,
                           &r.warning_codes);
    }
  }
}

std::string SuccessMessage(const GyroCalibrationOptions& options, const GyroCalibrationResult& r,
                           size_t poses) {
  double rms = 0.0;
  for (const GyroRotationReport& rot : r.rotations) rms += rot.residual_deg * rot.residual_deg;
  rms = std::sqrt(rms / static_cast<double>(r.rotations.size()));
  std::ostringstream s;
  s.precision(3);
  s << "calibrated the '" << ToString(options.parameterization) << "' gyroscope model"
    << (options.g_sensitivity ? " with g-sensitivity" : "")
    << (options.joint ? " jointly with the accelerometer" : "") << " from " << r.rotations.size()
    << " rotations between " << poses << " static poses (residual rms " << rms << " deg, "
    << r.iterations << " iterations)";
  return s.str();
}

}  // namespace
}  // namespace internal

bool CalibrateGyroscope(const ImuLog& log, const std::vector<StaticInterval>& intervals,
                        const AccelModel& accel, const Eigen::MatrixXd& accel_covariance,
                        double gravity, const GyroCalibrationOptions& options,
                        GyroCalibrationResult* result) {
  CHECK(result != nullptr);
  *result = GyroCalibrationResult();
  GyroCalibrationResult& r = *result;
  internal::GyroPrepared prep;
  Eigen::Matrix3d m0;
  const std::string accel_like = internal::GyroLooksLikeAccelerometer(intervals);
  if (!accel_like.empty()) {
    r.message = log.source.empty() ? accel_like : log.source + ": " + accel_like;
    return false;
  }
  if (!internal::CheckGyroInputs(accel, accel_covariance, gravity, options, &r.message) ||
      !internal::PrepareGyroRotations(log, intervals, accel, options, &prep, &m0, &r.warnings,
                                      &r.message)) {
    internal::CodeNewWarnings(WarningCode::kRotationSkipped, r.warnings, &r.warning_codes);
    return false;
  }
  internal::CodeNewWarnings(WarningCode::kRotationSkipped, r.warnings, &r.warning_codes);
  r.initial_matrix = m0;
  r.gyro_noise = prep.gyro_cov.diagonal().cwiseSqrt();

  const internal::GyroLayout layout(options.g_sensitivity, options.joint);
  const Normalization norm = Normalization::For(accel);
  prep.normalized_positions = norm.Apply(prep.positions);
  std::vector<double> x0, magnitude_sigmas;
  if (!internal::InitialValues(layout, prep, m0, accel, norm, options.joint, &x0, &magnitude_sigmas,
                               &r.message)) {
    return false;
  }

  internal::GyroSolve solve;
  const auto start = std::chrono::steady_clock::now();
  const bool solved =
      internal::SolveHoldingUndetermined(prep, layout, options, accel, norm, x0, magnitude_sigmas,
                                         gravity, &solve, &r.undetermined, &r.message);
  r.iterations = solve.iterations;
  if (!solved) return false;
  r.solve_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.termination = ceres::TerminationTypeToString(solve.summary.termination_type);
  r.converged = solve.summary.IsSolutionUsable() &&
                solve.summary.termination_type == ceres::CONVERGENCE && !solve.pending;
  internal::FillEstimate(prep, layout, solve, &r);
  const AccelModel accel_final = internal::GyroAccelAt(solve.x, layout, accel, norm);
  r.rotations = internal::ReportRotations(log, prep, layout, solve, accel_final, &solve.x);
  if (options.compute_covariance && r.converged) {
    internal::ComputeGyroCovariance(prep, layout, solve.built, solve.free, solve.weights, accel,
                                    accel_final, norm, accel_covariance, &solve.x, &r);
    internal::AddSessionBiasWander(prep, options, &r);
  }
  if (layout.accel_bias >= 0) {
    internal::FillJointAccel(prep, accel, accel_final, magnitude_sigmas, gravity, &r);
  }
  internal::WarnUndeterminedGyro(r.undetermined, &r.warnings);
  internal::CodeNewWarnings(WarningCode::kUndetermined, r.warnings, &r.warning_codes);
  internal::WarnLargeResiduals(&r);
  const std::string handedness = internal::HandednessWarning("gyroscope", r.model.matrix);
  if (!handedness.empty()) {
    internal::AddWarning(WarningCode::kSensorData, handedness, &r.warnings, &r.warning_codes);
  }
  if (!r.converged) {
    r.message = "the gyroscope calibration did not converge (" + r.termination + ": " +
                solve.summary.message + ")";
    return false;
  }
  r.message = internal::SuccessMessage(options, r, prep.positions.size());
  if (r.bias_wander_std.norm() > 0.0) r.message += "; " + r.bias_wander_note;
  return true;
}

bool AddGyroscopeCalibration(const ImuLog& log, const std::vector<StaticInterval>& intervals,
                             const GyroCalibrationOptions& options, Calibration* calibration) {
  CHECK(calibration != nullptr);
  Calibration& c = *calibration;
  auto fail = [&](const std::string& message) {
    c.success = false;
    c.message = message;
    return false;
  };
  if (!c.success) return fail("the gyroscope needs a calibrated accelerometer first");
  GyroCalibrationResult g;
  const Eigen::MatrixXd accel_covariance =
      c.refinement.covariance_available ? c.refinement.covariance : Eigen::MatrixXd();
  // The per-pose variance the accelerometer step absorbed moves every pose's
  // gravity direction too.
  GyroCalibrationOptions with_poses = options;
  if (c.accel.pose_variance.absorbed) with_poses.pose_variance = c.accel.pose_variance.variance;
  with_poses.estimate_static_variance = c.accel.pose_variance.estimated;
  if (!CalibrateGyroscope(log, intervals, c.accel.model, accel_covariance, c.gravity, with_poses,
                          &g)) {
    internal::AppendWarnings(g.warnings, g.warning_codes, "", &c.warnings, &c.warning_codes);
    return fail(g.message);
  }
  GyroCalibration& out = c.gyro;
  out = GyroCalibration();
  out.estimated = true;
  out.model = g.model;
  out.bias_std = g.bias_std;
  out.matrix_std = g.matrix_std;
  out.covariance = g.covariance;
  out.covariance_names = g.parameter_names;
  if (options.g_sensitivity) {
    for (int i = 0; i < 9; ++i) {
      out.extra_names.push_back(std::string("g_sensitivity_") + internal::kGyroAxisNames[i / 3] +
                                internal::kGyroAxisNames[i % 3]);
      out.extra_values.push_back(g.g_sensitivity(i / 3, i % 3));
      out.extra_std.push_back(g.g_sensitivity_std(i / 3, i % 3));
    }
  }
  for (int a = 0; a < 3 && g.bias_wander_std.norm() > 0.0; ++a) {
    // What the bias's standard deviation includes for the session's wander.
    out.extra_names.push_back(std::string("bias_wander_") + internal::kGyroAxisNames[a]);
    out.extra_values.push_back(g.bias_wander_std(a));
    out.extra_std.push_back(NAN);
  }
  for (const GyroRotationReport& r : g.rotations)
    out.rotation_residual_deg.push_back(r.residual_deg);
  if (g.accel_refined) {
    // The joint fit's accelerometer, with the housing rotation (affine) and
    // its uncertainty kept from the accelerometer step.
    HousingRotation housing;
    const bool affine = c.accel.model.parameterization == AccelParameterization::kAffine &&
                        c.accel.covariance.rows() >= 3 && !c.accel.covariance_names.empty() &&
                        c.accel.covariance_names.back() == "rot_z";
    if (affine) {
      housing.rotation = c.accel.model.rotation;
      housing.angle_covariance = c.accel.covariance.bottomRightCorner<3, 3>();
    }
    const AccelCalibration before = c.accel;
    c.accel.model = g.accel.model;
    if (g.accel.covariance_available) {
      PropagateUncertainty(g.accel, affine ? &housing : nullptr, &c.accel);
      if (c.accel.model.parameterization == AccelParameterization::kAffine && !affine) {
        c.accel.matrix_std.setConstant(NAN);
      }
    }
    c.accel.tilt_rms = before.tilt_rms;
    c.residual_refined = {Rms(g.accel.residuals_after), MaxAbs(g.accel.residuals_after)};
    for (size_t k = 0; k < c.positions.size() && k < g.accel.residuals_after.size(); ++k) {
      c.positions[k].residual_after = g.accel.residuals_after[k];
    }
    internal::AddWarning(WarningCode::kParameterSource,
                         "gyro_joint: the accelerometer's bias and U come from the joint fit "
                         "with the gyroscope rotations",
                         &c.warnings, &c.warning_codes);
  }
  internal::AppendWarnings(g.warnings, g.warning_codes, "", &c.warnings, &c.warning_codes);
  c.message += "; " + g.message;
  return true;
}

}  // namespace gravcal
