#include "gravcal/workflows/plan.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <sstream>

#include "gravcal/core/gravity.h"
#include "gravcal/estimation/refinement.h"
#include "gravcal/simulation/simulator.h"
#include "util/join.h"
#include "util/units.h"
#include "workflows/plan_start.h"

namespace gravcal {

namespace {

// Unit -> factor to scale-free (m/s^2 or rad/s for a bias, relative for a
// matrix entry).
bool UnitFactor(const std::string& unit, bool bias, bool gyro, double* factor) {
  static const std::map<std::string, double> kBias = {
      {"mg", 1e-3 * kStandardGravity}, {"ug", 1e-6 * kStandardGravity}, {"m/s^2", 1.0}};
  static const std::map<std::string, double> kGyroBias = {{"deg/h", internal::kDegToRad / 3600.0},
                                                          {"dph", internal::kDegToRad / 3600.0},
                                                          {"deg/s", internal::kDegToRad},
                                                          {"mdps", 1e-3 * internal::kDegToRad},
                                                          {"rad/s", 1.0}};
  static const std::map<std::string, double> kMatrix = {
      {"ppm", 1e-6},  {"%", 1e-2},  {"mrad", 1e-3},
      {"urad", 1e-6}, {"rad", 1.0}, {"deg", internal::kDegToRad}};
  const auto& table = bias ? (gyro ? kGyroBias : kBias) : kMatrix;
  const auto it = table.find(unit);
  if (it == table.end()) return false;
  *factor = it->second;
  return true;
}

// The parameters a target name stands for (indices into the names).
std::vector<int> TargetColumns(const std::string& name, const std::vector<std::string>& names) {
  static const std::map<std::string, std::vector<std::string>> kGroups = {
      {"accel_bias", {"bias_x", "bias_y", "bias_z"}},
      {"accel_scale", {"u_xx", "u_yy", "u_zz", "m_xx", "m_yy", "m_zz"}},
      {"accel_misalignment",
       {"u_xy", "u_xz", "u_yz", "m_xy", "m_xz", "m_yx", "m_yz", "m_zx", "m_zy"}},
      {"gyro_bias", {"bias_x", "bias_y", "bias_z"}},
      {"gyro_scale", {"m_xx", "m_yy", "m_zz", "scale"}},
      {"gyro_misalignment", {"m_xy", "m_xz", "m_yx", "m_yz", "m_zx", "m_zy"}}};
  std::vector<std::string> members = {name};
  const auto group = kGroups.find(name);
  if (group != kGroups.end()) {
    members = group->second;
  } else if (name.rfind("gyro_", 0) == 0) {
    members = {name.substr(5)};
  }
  std::vector<int> columns;
  for (const std::string& m : members) {
    const auto it = std::find(names.begin(), names.end(), m);
    if (it != names.end()) columns.push_back(static_cast<int>(it - names.begin()));
  }
  return columns;
}

using internal::Join;

// The sensor-frame up direction of each pose of a seed scheme.
std::vector<Eigen::Vector3d> SchemeUps(PoseScheme kind) {
  const SimulatorScheme scheme{kind};
  std::vector<Eigen::Quaterniond> attitudes;
  std::vector<int> nominal_up;
  std::string error;
  std::vector<Eigen::Vector3d> ups;
  if (!SchemeAttitudes(scheme, 0, &attitudes, &nominal_up, &error)) return ups;
  for (const Eigen::Quaterniond& q : attitudes) {
    Eigen::Vector3d up = q.conjugate() * Eigen::Vector3d::UnitZ();
    // Exact zeros where the scheme means them (the quaternions round).
    for (int i = 0; i < 3; ++i) up(i) = std::fabs(up(i)) < 1e-12 ? 0.0 : up(i);
    ups.push_back(up.normalized());
  }
  return ups;
}

bool AllIn(const std::vector<Eigen::Vector3d>& ups, const std::vector<Eigen::Vector3d>& set) {
  return std::all_of(ups.begin(), ups.end(), [&](const Eigen::Vector3d& u) {
    return std::any_of(set.begin(), set.end(),
                       [&](const Eigen::Vector3d& c) { return (u - c).norm() < 1e-6; });
  });
}

// "bias_x 0.62 mg (target 0.5)" for every parameter above its target.
std::string Shortfalls(const std::vector<std::string>& names, const Eigen::VectorXd& std,
                       const Eigen::VectorXd& targets) {
  std::ostringstream s;
  s.precision(3);
  for (size_t i = 0; i < names.size(); ++i) {
    const ReadableUnit unit = ReadableUnitOf(names[i]);
    s << (i ? ", " : "") << names[i] << " " << std(i) * unit.factor << " " << unit.unit
      << " (target " << targets(i) * unit.factor << ")";
  }
  return s.str();
}

// DesignPoses over the pose set; for `free` also over its faces+45 subset
// (the greedy search over thousands of directions can miss the balanced
// 45-degree designs), keeping the better: meeting the targets in less time,
// else the smaller worst ratio.
bool DesignOver(PoseSet pose_set, int free_candidates, const DesignModel& model,
                const DesignNoise& noise, const DesignOptions& options, DesignResult* result) {
  std::vector<Eigen::Vector3d> candidates;
  CandidateDirections(pose_set, free_candidates, &candidates);
  if (!DesignPoses(candidates, model, noise, options, result)) return false;
  if (pose_set != PoseSet::kFree) return true;
  CandidateDirections(PoseSet::kFacesAnd45, 0, &candidates);
  DesignResult subset;
  if (!DesignPoses(candidates, model, noise, options, &subset)) return true;
  const bool better = subset.meets_targets && result->meets_targets
                          ? subset.total_seconds < result->total_seconds
                          : (subset.meets_targets ||
                             (!result->meets_targets && subset.worst_ratio < result->worst_ratio));
  if (better) *result = subset;
  return true;
}

// The most accurate design over the pose set within `options`' limits (and
// max_time_seconds, when positive): ranked by the largest sigma relative to
// 1 mg, 100 ppm and 0.1 mrad, i.e. against targets far below reach, then
// evaluated against options.targets.
bool MostAccurateDesign(PoseSet pose_set, int free_candidates, const DesignModel& model,
                        const DesignNoise& noise, const DesignOptions& options,
                        const std::vector<std::string>& names, double max_time_seconds,
                        DesignResult* design) {
  DesignOptions accuracy = options;
  for (size_t i = 0; i < names.size(); ++i) accuracy.targets(i) = 1e-9 * ReferenceStd(names[i]);
  accuracy.max_time_seconds = max_time_seconds;
  if (!DesignOver(pose_set, free_candidates, model, noise, accuracy, design)) return false;
  *design = EvaluateDesign(design->poses, model, noise, options);
  return true;
}

// Datasheet densities (N, and B and K when positive) on every axis of
// *axes; returns "N = ... <unit>, B = ..., K = ...".
std::string DatasheetNoise(double n, double b, double k, const char* unit,
                           std::array<AxisNoiseModel, 3>* axes) {
  for (AxisNoiseModel& axis : *axes) {
    axis.white_noise.value = n;
    if (b > 0.0) axis.bias_instability.value = b;
    if (k > 0.0) axis.random_walk.value = k;
  }
  std::ostringstream s;
  s << "N = " << n << " " << unit;
  if (b > 0.0) s << ", B = " << b;
  if (k > 0.0) s << ", K = " << k;
  return s.str();
}

// The gyroscope's half of the plan: the turns between the poses (in
// handling order) chosen for the gyroscope-between-poses model, extra poses
// appended while its targets need them, and the accelerometer's figures
// again with those poses.
bool PlanRotations(const Config& config, const PlanRequest& request,
                   const internal::PlanStart& start, const DesignModel& model,
                   const DesignNoise& noise, const DesignOptions& options, RecordingPlan* out,
                   std::string* error) {
  const bool stated =
      std::any_of(start.gyro_targeted.begin(), start.gyro_targeted.end(), [](bool t) { return t; });
  if (!(noise.gyro[0].white_noise.value > 0.0)) {
    if (stated) {
      *error =
          "gyroscope targets need the gyroscope's noise: --noise noise.json with a gyroscope, or "
          "--gyro_noise_density";
      return false;
    }
    out->message += "; the gyroscope is not planned (no gyroscope noise: --gyro_noise_density)";
    return true;
  }
  std::vector<DesignPose> poses;
  for (const PlannedPose& p : out->poses) poses.push_back({p.up, p.hold_seconds});
  RotationDesignOptions rotation;
  rotation.targets = start.gyro_targets;
  rotation.free_axes = request.pose_set == PoseSet::kFree ? 12 : 0;
  rotation.seconds_per_180 = request.turn_seconds;
  rotation.extra_hold_seconds = options.min_hold_seconds;
  rotation.max_extra_poses = std::max(0, options.max_poses - static_cast<int>(out->poses.size()));
  CandidateDirections(PoseSet::kFacesAnd45, 0, &rotation.extra_candidates);
  GyroDesignModel gyro_model = start.gyro_model;
  GyroDesignResult design;
  if (!DesignRotations(poses, model, gyro_model, noise, rotation, &design)) {
    *error = design.message;
    return false;
  }
  const std::vector<std::string>& names = design.parameter_names;
  if (!design.meets_targets) {
    std::ostringstream s;
    s.precision(3);
    s << "the gyroscope's targets are not met within " << options.max_poses << " poses: ";
    for (size_t i = 0; i < names.size(); ++i) {
      const ReadableUnit unit = GyroReadableUnitOf(names[i]);
      s << (i ? ", " : "") << names[i] << " " << design.predicted_std(i) * unit.factor << " "
        << unit.unit << " (target " << start.gyro_targets(i) * unit.factor << ")";
    }
    *error = s.str();
    return false;
  }
  for (size_t k = out->poses.size(); k < design.poses.size(); ++k) {
    out->poses.push_back(
        {design.poses[k].up, design.poses[k].hold_seconds, PoseInstruction(design.poses[k].up)});
  }
  out->rotations.clear();
  for (size_t k = 0; k < design.turns.size(); ++k) {
    const DesignTurn& t = design.turns[k];
    PlannedRotation r = TurnAbout(t.axis, t.angle_deg, t.seconds);
    r.from = static_cast<int>(k);
    r.to = static_cast<int>(k + 1);
    out->rotations.push_back(r);
  }
  // The accelerometer with every pose, extra ones included.
  const DesignResult accel = EvaluateDesign(design.poses, model, noise, options);
  out->accel.predicted_std_scale_free = accel.predicted_std;
  out->accel.predicted_std = StdInRawUnits(accel.predicted_std, out->accel.nominal_scale);
  out->total_seconds = accel.total_seconds;
  out->gyro = internal::Prediction(names, design.predicted_std, start.gyro_targets,
                                   start.gyro_targeted, config.ten_position.gyro_nominal_scale);
  out->gyro_extra_poses = design.extra_poses;
  out->message += "; gyroscope: " + design.message;
  return true;
}

}  // namespace

bool PlanRequest::IsValid(std::string* error) const {
  if (free_candidates < 1 || free_candidates > 100000) {
    *error = "candidates: 1 to 100000 free directions";
    return false;
  }
  if (!(max_time_seconds >= 0.0) || !(overhead_seconds >= 0.0) || !(min_hold_seconds > 0.0) ||
      !(max_hold_seconds >= min_hold_seconds) || !std::isfinite(max_hold_seconds) ||
      max_poses < 1 || extra_poses < 1) {
    *error =
        "max_time >= 0, overhead >= 0, 0 < min_hold <= max_hold, max_poses >= 1, extra_poses >= 1";
    return false;
  }
  if (!(turn_seconds > 0.0 && std::isfinite(turn_seconds))) {
    *error = "turn_seconds must be positive";
    return false;
  }
  for (double v : {accel_noise_density, accel_bias_instability, accel_random_walk, pose_disturbance,
                   gyro_noise_density, gyro_bias_instability, gyro_random_walk, attitude_std_deg}) {
    if (!(v >= 0.0 && std::isfinite(v))) {
      *error = "noise densities, pose_disturbance and attitude_std must be >= 0";
      return false;
    }
  }
  return true;
}

bool ParsePlanTargets(const std::string& text, const DesignModel& model, Eigen::VectorXd* targets,
                      std::string* error, GyroParameterization gp, Eigen::VectorXd* gyro_targets) {
  const std::vector<std::string> names = DesignParameterNames(model);
  const std::vector<std::string> gyro_names = GyroDesignParameterNames(gp);
  Eigen::VectorXd out = Eigen::VectorXd::Constant(names.size(), NAN);
  Eigen::VectorXd gyro_out = Eigen::VectorXd::Constant(gyro_names.size(), NAN);
  std::istringstream in(text);
  std::string entry;
  std::vector<std::string> unknown;
  while (in >> entry) {
    const size_t eq = entry.find('=');
    if (eq == std::string::npos || eq == 0) {
      *error = "target '" + entry + "': expected name=value<unit>, e.g. accel_bias=0.5mg";
      return false;
    }
    const std::string name = entry.substr(0, eq);
    const bool gyro = name.rfind("gyro_", 0) == 0 && gyro_targets != nullptr;
    const std::vector<int> columns = TargetColumns(name, gyro ? gyro_names : names);
    if (columns.empty() || (!gyro && name.rfind("gyro_", 0) == 0)) {
      unknown.push_back(name);
      continue;
    }
    const bool bias = columns.front() < 3;
    const std::string value_text = entry.substr(eq + 1);
    char* end = nullptr;
    const double value = std::strtod(value_text.c_str(), &end);
    const std::string unit = end ? std::string(end) : "";
    double factor = 0.0;
    if (end == value_text.c_str() || !(value > 0.0 && std::isfinite(value)) ||
        !UnitFactor(unit, bias, gyro, &factor)) {
      *error = "target '" + entry + "': expected a positive number and a unit (" +
               (bias ? (gyro ? "deg/h, dph, deg/s, mdps, rad/s" : "mg, ug, m/s^2")
                     : "ppm, %, mrad, urad, rad, deg") +
               ")";
      return false;
    }
    for (int c : columns) (gyro ? gyro_out : out)(c) = value * factor;
  }
  if (!unknown.empty()) {
    *error = "unknown parameter name(s) in --target: " + Join(unknown) +
             " (known: accel_bias, accel_scale, accel_misalignment, " + Join(names) +
             (gyro_targets != nullptr
                  ? ", gyro_bias, gyro_scale, gyro_misalignment, gyro_<" + Join(gyro_names) + ">"
                  : std::string()) +
             ")";
    return false;
  }
  *targets = out;
  if (gyro_targets != nullptr) *gyro_targets = gyro_out;
  return true;
}

bool PlanDesignNoise(const PlanRequest& request, DesignNoise* noise, std::string* source,
                     std::string* error) {
  DesignNoise out;
  if (request.noise_model != nullptr) {
    out.accel = request.noise_model->accel;
    for (const AxisNoiseModel& axis : out.accel) {
      if (!axis.white_noise.visible()) {
        *error = "the noise model shows no accelerometer white noise: give --accel_noise_density";
        return false;
      }
    }
    *source = "noise model (gravcal noise)";
  } else if (request.accel_noise_density > 0.0) {
    *source = "datasheet densities: " +
              DatasheetNoise(request.accel_noise_density, request.accel_bias_instability,
                             request.accel_random_walk, "m/s^2/sqrt(Hz)", &out.accel);
  } else {
    *error = "no noise: give --noise noise.json (gravcal noise) or --accel_noise_density";
    return false;
  }
  // The gyroscope, when the noise model shows it or a density is given
  // (the rotations are planned only then).
  if (request.noise_model != nullptr &&
      std::all_of(request.noise_model->gyro.begin(), request.noise_model->gyro.end(),
                  [](const AxisNoiseModel& a) { return a.white_noise.visible(); })) {
    out.gyro = request.noise_model->gyro;
  } else if (request.gyro_noise_density > 0.0) {
    *source += "; gyroscope datasheet densities: " +
               DatasheetNoise(request.gyro_noise_density, request.gyro_bias_instability,
                              request.gyro_random_walk, "rad/s/sqrt(Hz)", &out.gyro);
  }
  out.pose_disturbance = request.pose_disturbance;
  if (request.pose_disturbance > 0.0) {
    std::ostringstream s;
    s << "; per-pose disturbance " << request.pose_disturbance << " m/s^2";
    *source += s.str();
  }
  *noise = out;
  return true;
}

bool PlanDesignModel(const Config& config, DesignModel* model, std::string* error) {
  DesignModel out;
  out.parameterization = config.calibration.refinement.parameterization;
  std::string source;
  if (!ResolveGravity(config.calibration.gravity, &out.gravity, &source, error)) return false;
  // Measured with the simulator's turns: the detector keeps about the hold
  // (10.1 s of a 10 s hold: a turn starts and ends slowly, so the quiet
  // windows reach into it, and `settle` is trimmed from each end); the plan
  // counts the hold minus one `settle`.
  out.trimmed_seconds = config.calibration.detector.settle_seconds;
  out.known_attitude = config.method == Method::kKnownAttitude;
  if (!out.IsValid(error)) return false;
  *model = out;
  return true;
}

namespace internal {

SensorPrediction Prediction(const std::vector<std::string>& names,
                            const Eigen::VectorXd& std_scale_free, const Eigen::VectorXd& targets,
                            const std::vector<bool>& targeted, double nominal_scale) {
  SensorPrediction p;
  p.parameter_names = names;
  p.predicted_std_scale_free = std_scale_free;
  p.predicted_std = StdInRawUnits(std_scale_free, nominal_scale);
  p.targets_scale_free = targets;
  p.targeted = targeted;
  p.nominal_scale = nominal_scale;
  return p;
}

bool StartPlan(const Config& config, const PlanRequest& request, PlanStart* start,
               std::string* error) {
  if (!request.IsValid(error)) return false;
  PlanStart out;
  if (!PlanDesignModel(config, &out.model, error)) return false;
  out.model.attitude_std = request.attitude_std_deg * internal::kDegToRad;
  out.names = DesignParameterNames(out.model);
  Eigen::VectorXd stated, gyro_stated;
  out.gyro_model.parameterization = config.gyro.parameterization == GyroParameterization::kNone
                                        ? GyroParameterization::kFull
                                        : config.gyro.parameterization;
  out.gyro_model.edge_seconds = config.gyro.edge_seconds;
  if (!ParsePlanTargets(request.targets, out.model, &stated, error, out.gyro_model.parameterization,
                        &gyro_stated)) {
    return false;
  }
  out.gyro_names = GyroDesignParameterNames(out.gyro_model.parameterization);
  std::vector<std::string> gyro_stated_names;
  for (Eigen::Index i = 0; i < gyro_stated.size(); ++i) {
    if (std::isfinite(gyro_stated(i))) gyro_stated_names.push_back("gyro_" + out.gyro_names[i]);
  }
  out.gyro_planned = config.gyro.parameterization != GyroParameterization::kNone;
  if (!gyro_stated_names.empty() && !out.gyro_planned) {
    *error = "gyroscope targets (" + Join(gyro_stated_names) +
             ") but the config calibrates no gyroscope (gyro_model: none): use a gyroscope config "
             "(e.g. configs/twelve_position_gyro.yaml) or --gyro_model full";
    return false;
  }
  // Untargeted gyroscope parameters: the calibration's limit of a
  // determined matrix entry, and 1 deg/s for the bias.
  out.gyro_targets.resize(gyro_stated.size());
  out.gyro_targeted.resize(gyro_stated.size());
  for (Eigen::Index i = 0; i < gyro_stated.size(); ++i) {
    out.gyro_targeted[i] = std::isfinite(gyro_stated(i));
    out.gyro_targets(i) = out.gyro_targeted[i]
                              ? gyro_stated(i)
                              : (i < 3 ? internal::kDegToRad : config.gyro.max_matrix_std);
  }
  const RefinementOptions& r = config.calibration.refinement;
  const Eigen::Index p = static_cast<Eigen::Index>(out.names.size());
  out.limits.resize(p);
  out.targets.resize(p);
  out.targeted.resize(p);
  for (Eigen::Index i = 0; i < p; ++i) {
    out.limits(i) = i < 3 ? r.max_bias_std : r.max_matrix_std;
    out.targeted[i] = std::isfinite(stated(i));
    out.targets(i) = out.targeted[i] ? stated(i) : out.limits(i);
  }
  *start = out;
  return true;
}

}  // namespace internal

bool MakeRecordingPlan(const Config& config, const PlanRequest& request, RecordingPlan* plan,
                       std::string* error) {
  internal::PlanStart start;
  if (!internal::StartPlan(config, request, &start, error)) return false;
  const DesignModel& model = start.model;
  const std::vector<std::string>& names = start.names;
  const Eigen::VectorXd& targets = start.targets;
  const bool any_stated =
      std::any_of(start.targeted.begin(), start.targeted.end(), [](bool t) { return t; });
  if (!any_stated && !(request.max_time_seconds > 0.0)) {
    *error = "give --target (e.g. accel_bias=0.5mg accel_scale=50ppm) or --max_time";
    return false;
  }
  DesignNoise noise;
  RecordingPlan out;
  if (!PlanDesignNoise(request, &noise, &out.noise_source, error)) return false;

  DesignOptions options;
  options.targets = targets;
  options.overhead_seconds = request.overhead_seconds;
  options.min_hold_seconds = std::max(request.min_hold_seconds, model.trimmed_seconds + 1.0);
  options.max_hold_seconds = std::max(request.max_hold_seconds, options.min_hold_seconds);
  options.max_poses =
      std::max(request.max_poses, static_cast<int>(names.size()) + options.redundancy);
  const PoseSet pose_set = request.pose_set;
  std::vector<Eigen::Vector3d> candidates;
  CandidateDirections(pose_set, request.free_candidates, &candidates);
  const std::vector<std::pair<std::string, std::vector<Eigen::Vector3d>>> schemes = {
      {ToString(PoseScheme::kTwelve), SchemeUps(PoseScheme::kTwelve)},
      {ToString(PoseScheme::kSix), SchemeUps(PoseScheme::kSix)},
      {ToString(PoseScheme::kTen), SchemeUps(PoseScheme::kTen)}};
  for (const auto& [name, ups] : schemes) {
    if (AllIn(ups, candidates)) options.reference_designs.push_back(ups);
  }

  DesignResult design;
  if (!any_stated) {
    // Best accuracy within max_time.
    if (!MostAccurateDesign(pose_set, request.free_candidates, model, noise, options, names,
                            request.max_time_seconds, &design)) {
      *error = design.message;
      return false;
    }
  } else {
    if (!DesignOver(pose_set, request.free_candidates, model, noise, options, &design)) {
      *error = design.message;
      return false;
    }
    if (request.max_time_seconds > 0.0 &&
        !(design.meets_targets && design.total_seconds <= request.max_time_seconds)) {
      // What can be done within max_time, and how long the targets need.
      DesignOptions within = options;
      within.max_time_seconds = request.max_time_seconds;
      DesignResult best;
      std::ostringstream s;
      s.precision(4);
      s << "the targets cannot be met within --max_time " << request.max_time_seconds << " s";
      if (DesignOver(pose_set, request.free_candidates, model, noise, within, &best) &&
          std::isfinite(best.worst_ratio)) {
        s << "; achievable within it (" << best.poses.size()
          << " poses): " << Shortfalls(names, best.predicted_std, targets);
      } else {
        s << "; no design within it determines every parameter";
      }
      if (design.meets_targets) {
        s << "; meeting them takes " << design.total_seconds << " s (" << design.poses.size()
          << " poses)";
      }
      *error = s.str();
      return false;
    }
  }
  if (!design.meets_targets || !std::isfinite(design.worst_ratio)) {
    std::ostringstream s;
    s << "no design of at most " << options.max_poses << " poses held at most "
      << options.max_hold_seconds << " s meets the targets";
    // The search stops short of a design that misses the targets: say the
    // best it can reach, from the most accurate design within the limits.
    DesignResult best = design;
    if (!(std::isfinite(best.worst_ratio) && best.predicted_std.size() > 0) &&
        !MostAccurateDesign(
            pose_set, request.free_candidates, model, noise, options, names,
            options.max_poses * (options.max_hold_seconds + options.overhead_seconds), &best)) {
      best = design;
    }
    if (std::isfinite(best.worst_ratio) && best.predicted_std.size() > 0) {
      s.precision(4);
      s << "; the best it can reach (" << best.poses.size() << " poses, " << best.total_seconds
        << " s): " << Shortfalls(names, best.predicted_std, targets);
    } else {
      s << "; no design within these limits determines every parameter";
    }
    *error = s.str();
    return false;
  }

  std::vector<PlannedPose> poses;
  for (const DesignPose& p : design.poses) poses.push_back({p.up, p.hold_seconds, ""});
  OrderForHandling(poses, &out);
  out.accel = internal::Prediction(names, design.predicted_std, targets, start.targeted,
                                   config.calibration.nominal_scale);
  out.gravity = model.gravity;
  out.overhead_seconds = request.overhead_seconds;
  out.total_seconds = design.total_seconds;
  out.meets_targets = design.meets_targets;
  out.pose_set = ToString(request.pose_set);
  out.criterion =
      "target-weighted A-optimal: minimise sum_i (sigma_i / target_i)^2 over the candidate "
      "orientations (greedy + Fedorov exchange), least total time (holds + overhead) with "
      "every sigma_i <= target_i";
  for (const auto& [name, ups] : schemes) {
    SchemeComparison c;
    c.name = name;
    c.poses = static_cast<int>(ups.size());
    DesignResult r;
    c.meets_targets = ShortestHold(ups, model, noise, options, &r);
    if (!c.meets_targets) {
      std::vector<DesignPose> at_max;
      for (const Eigen::Vector3d& u : ups) at_max.push_back({u, options.max_hold_seconds});
      r = EvaluateDesign(at_max, model, noise, options);
    }
    c.hold_seconds = c.meets_targets ? r.poses.front().hold_seconds : NAN;
    c.total_seconds = c.meets_targets ? r.total_seconds : NAN;
    c.predicted_std = StdInRawUnits(r.predicted_std, out.accel.nominal_scale);
    out.schemes.push_back(c);
  }
  out.message = design.message;
  // Issue 35: the thermal method needs these poses repeated across a
  // temperature span wide enough for the orders it may fit.
  if (config.method == Method::kThermal) {
    const ThermalCalibrationOptions& t = config.thermal;
    int order = 0;
    for (const auto& [fixed, most] :
         {std::pair<int, int>{t.accel_bias_order, t.accel_bias_max_order},
          {t.accel_scale_order, t.accel_scale_max_order},
          {t.accel_misalignment_order, t.accel_misalignment_max_order},
          {t.gyro_bias_order, t.gyro_bias_max_order}}) {
      order = std::max(order, fixed >= 0 ? fixed : most);
    }
    char line[400];
    std::snprintf(line, sizeof(line),
                  "; thermal: repeat these poses across at least %.0f degC (order %d terms need "
                  "it; %.0f degC for linear ones): at several soak temperatures, or turned "
                  "through them again and again while the unit warms up from cold and, to see a "
                  "lag, while it cools; one pose on a ramp determines only the bias along gravity",
                  ThermalMinimumSpan(order), order, ThermalMinimumSpan(1));
    out.message += line;
  }
  if (start.gyro_planned) {
    if (!PlanRotations(config, request, start, model, noise, options, &out, error)) return false;
  }
  *plan = out;
  return true;
}

}  // namespace gravcal
