// Config sections of the accelerometer calibration (CalibrationOptions):
// "gravity" (GravityOptions), "detector" (StaticDetectorOptions), "model"
// (the parameterisation and coarse fit), "solver" (the refinement).
#include "workflows/config/config_key.h"

namespace gravcal {
namespace internal {

SectionOf<CalibrationConfig> GravitySection() {
  return {"gravity",
          ConfigSectionUse::kSomeMethods,
          {
              GRAVCAL_DOUBLE("gravity", calibration.gravity.gravity,
                             "local gravity, m/s^2 (0 = not given)"),
              GRAVCAL_DOUBLE("latitude", calibration.gravity.latitude,
                             "geodetic latitude, degrees, for normal gravity"),
              GRAVCAL_DOUBLE("height", calibration.gravity.height,
                             "height above the ellipsoid, m, for normal gravity"),
          }};
}

SectionOf<CalibrationConfig> DetectorSection() {
  return {"detector",
          ConfigSectionUse::kSomeMethods,
          {
              GRAVCAL_DOUBLE("window", calibration.detector.window_seconds,
                             "moving variance window, s"),
              GRAVCAL_DOUBLE("noise_quantile", calibration.detector.noise_quantile,
                             "quantile of the windowed variance taken as the noise floor"),
              GRAVCAL_DOUBLE("threshold_factor", calibration.detector.threshold_factor,
                             "static when the variance is below this times the noise floor"),
              GRAVCAL_DOUBLE("min_duration", calibration.detector.min_duration_seconds,
                             "shortest static interval kept, s"),
              GRAVCAL_DOUBLE("settle", calibration.detector.settle_seconds,
                             "trimmed from each end of a static interval, s"),
              GRAVCAL_DOUBLE("gyro_threshold_factor", calibration.detector.gyro_threshold_factor,
                             "gyroscope: static when its variance is below this times its floor"),
              GRAVCAL_DOUBLE("max_floor_ratio", calibration.detector.max_floor_ratio,
                             "noise floor capped at this times the sample-to-sample white noise"),
              GRAVCAL_DOUBLE("merge_gap_windows", calibration.detector.merge_gap_windows,
                             "longest gap, in windows, across which two intervals are merged"),
              GRAVCAL_BOOL("use_gyro", calibration.detector.use_gyro,
                           "use the gyroscope variance too, when present"),
              GRAVCAL_DOUBLE("merge_angle", calibration.detector.merge_angle_deg,
                             "adjacent intervals closer than this are one pose, degrees"),
              GRAVCAL_DOUBLE("trend_factor", calibration.detector.trend_factor,
                             "still only when a window's half means agree within this times "
                             "their noise (0 = off)"),
              GRAVCAL_DOUBLE("spread_factor", calibration.detector.spread_factor,
                             "an interval whose variance is above this times the floor is split "
                             "at its steps or named (0 = off)"),
              GRAVCAL_DOUBLE("step_factor", calibration.detector.step_factor,
                             "a still run is split where a step in its level is above this times "
                             "its noise (0 = off)"),
              GRAVCAL_DOUBLE("step_min", calibration.detector.step_min_deg,
                             "a step splits only when its two levels are this far apart, degrees"),
          }};
}

namespace {

bool ReadNominalUp(const YAML::Node& n, CalibrationConfig* c, std::string* e) {
  std::vector<std::string> names;
  if (!ReadStringList(n, &names, e)) return false;
  std::vector<int> axes;
  for (const std::string& s : names) {
    int found = -2;
    for (int a = -1; a < 6; ++a) {
      if (s == NominalAxisName(a)) found = a;
    }
    if (found == -2) {
      *e = "entry '" + s + "' must be +x, -x, +y, -y, +z, -z or ?";
      return false;
    }
    axes.push_back(found);
  }
  c->calibration.nominal_up = axes;
  return true;
}

std::string NominalUpText(const CalibrationConfig& c) {
  std::vector<std::string> names;
  for (int a : c.calibration.nominal_up) names.push_back(NominalAxisName(a));
  return ListText(names);
}

}  // namespace

SectionOf<CalibrationConfig> ModelSection() {
  return {
      "model",
      ConfigSectionUse::kSomeMethods,
      {
          GRAVCAL_ENUM("parameterization", calibration.refinement.parameterization,
                       "free accelerometer parameters (6, 9 gauge-free, 12 in this order)"),
          GRAVCAL_DOUBLE("axis_tolerance", calibration.coarse.axis_tolerance_deg,
                         "a position within this many degrees of an axis counts as axis-aligned"),
          GRAVCAL_KEY_AT("nominal_up",
                         "up axis of each detected position, e.g. [+z, -z, +x, ?]; empty = "
                         "automatic",
                         ReadNominalUp(n, c, e), NominalUpText(c), &c.calibration.nominal_up),
          GRAVCAL_BOOL(
              "allow_undetermined", calibration.allow_undetermined,
              "write parameters the positions do not determine as null instead of failing"),
          GRAVCAL_DOUBLE(
              "nominal_scale", calibration.nominal_scale,
              "m/s^2 per raw unit assumed before calibration (for the 'before' residual)"),
      }};
}

SectionOf<CalibrationConfig> SolverSection() {
  return {
      "solver",
      ConfigSectionUse::kSomeMethods,
      {
          GRAVCAL_ENUM("solver", calibration.solver,
                       "refinement solver (newton: the seed's hand-written iteration)"),
          GRAVCAL_ENUM("newton_residual", calibration.newton_residual,
                       "Newton residual (the seed's, or the same cost as ceres)"),
          GRAVCAL_ENUM("loss", calibration.refinement.loss, "robust loss on the residuals"),
          GRAVCAL_DOUBLE("loss_scale", calibration.refinement.loss_scale,
                         "robust loss scale, in standard deviations"),
          GRAVCAL_BOOL("covariance", calibration.refinement.compute_covariance,
                       "compute the covariance (standard deviations)"),
          GRAVCAL_INT("max_iterations", calibration.refinement.solver.max_iterations,
                      "solver iteration limit"),
          GRAVCAL_BOOL("pose_variance", calibration.refinement.estimate_pose_variance,
                       "estimate the per-pose variance the samples cannot show (REML) and add "
                       "it to every standard deviation"),
          GRAVCAL_DOUBLE("max_pose_disturbance", calibration.refinement.max_pose_disturbance,
                         "warn when the per-pose scatter s exceeds this, m/s^2"),
          GRAVCAL_DOUBLE("structure_test_level", calibration.refinement.structure_test_level,
                         "significance at which non-orthogonality, not noise, owns the excess"),
          GRAVCAL_DOUBLE("pose_disturbance_prior", calibration.refinement.pose_disturbance_prior,
                         "pose_variance: typical per-pose scatter of the placement, m/s^2"),
          GRAVCAL_DOUBLE("pose_disturbance_prior_dof",
                         calibration.refinement.pose_disturbance_prior_dof,
                         "pose_variance: weight of that prior in degrees of freedom (0 = none)"),
          GRAVCAL_DOUBLE("prior_conflict_level", calibration.refinement.prior_conflict_level,
                         "pose_variance: set the prior aside when the poses' scatter is in "
                         "either tail of F(dof, prior dof) beyond this"),
      }};
}

}  // namespace internal
}  // namespace gravcal
