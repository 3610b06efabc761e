#include "gravcal/io/plan_io.h"

#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>

#include "gravcal/io/files.h"
#include "io/json_helpers.h"

namespace gravcal {

namespace {

using internal::JsonNumber;
using internal::JsonVector;
using Json = nlohmann::ordered_json;

Json StdObject(const std::vector<std::string>& names, const Eigen::VectorXd& std) {
  Json out = Json::object();
  for (size_t i = 0; i < names.size() && static_cast<Eigen::Index>(i) < std.size(); ++i) {
    out[names[i]] = JsonNumber<Json>(std(i));
  }
  return out;
}

// One sensor's part of plan.json: its predicted_std (calibration JSON
// units), the same readable (value and unit) and its targets.
struct PredictionJson {
  Json std;
  Json readable = Json::object();
  Json targets = Json::object();
};

PredictionJson PredictionToJson(const SensorPrediction& p,
                                ReadableUnit (*unit_of)(const std::string&)) {
  PredictionJson out;
  out.std = StdObject(p.parameter_names, p.predicted_std);
  for (size_t i = 0; i < p.parameter_names.size(); ++i) {
    const std::string& name = p.parameter_names[i];
    const ReadableUnit unit = unit_of(name);
    out.readable[name] = {{"value", JsonNumber<Json>(p.predicted_std_scale_free(i) * unit.factor)},
                          {"unit", unit.unit}};
    if (static_cast<Eigen::Index>(i) < p.targets_scale_free.size()) {
      out.targets[name] = {{"value", JsonNumber<Json>(p.targets_scale_free(i) * unit.factor)},
                           {"unit", unit.unit},
                           {"stated", i < p.targeted.size() && p.targeted[i]}};
    }
  }
  return out;
}

}  // namespace

std::string PlanToJson(const RecordingPlan& plan) {
  Json poses = Json::array();
  for (const PlannedPose& p : plan.poses) {
    poses.push_back({{"up", JsonVector<Json>(p.up)},
                     {"hold_s", JsonNumber<Json>(p.hold_seconds)},
                     {"instruction", p.instruction}});
  }
  Json rotations = Json::array();
  for (const PlannedRotation& r : plan.rotations) {
    Json turn = {{"from", r.from},
                 {"to", r.to},
                 {"axis", JsonVector<Json>(r.axis)},
                 {"angle_deg", JsonNumber<Json>(r.angle_deg)}};
    if (r.seconds > 0.0) turn["duration_s"] = JsonNumber<Json>(r.seconds);
    turn["instruction"] = r.instruction;
    rotations.push_back(turn);
  }
  Json schemes = Json::object();
  for (const SchemeComparison& s : plan.schemes) {
    schemes[s.name] = {{"poses", s.poses},
                       {"hold_s", JsonNumber<Json>(s.hold_seconds)},
                       {"total_time_s", JsonNumber<Json>(s.total_seconds)},
                       {"meets_targets", s.meets_targets},
                       {"predicted_std", StdObject(plan.accel.parameter_names, s.predicted_std)}};
  }
  Json out;
  out["poses"] = poses;
  out["rotations"] = rotations;
  PredictionJson accel = PredictionToJson(plan.accel, ReadableUnitOf);
  out["predicted_std"] = std::move(accel.std);
  out["predicted_std_readable"] = std::move(accel.readable);
  out["targets"] = std::move(accel.targets);
  out["total_time_s"] = JsonNumber<Json>(plan.total_seconds);
  out["overhead_s"] = JsonNumber<Json>(plan.overhead_seconds);
  out["meets_targets"] = plan.meets_targets;
  out["nominal_scale"] = JsonNumber<Json>(plan.accel.nominal_scale);
  out["gravity"] = JsonNumber<Json>(plan.gravity);
  out["criterion"] = plan.criterion;
  out["pose_set"] = plan.pose_set;
  out["noise"] = plan.noise_source;
  out["schemes"] = schemes;
  if (!plan.gyro.parameter_names.empty()) {
    PredictionJson gyro = PredictionToJson(plan.gyro, GyroReadableUnitOf);
    out["gyro_predicted_std"] = std::move(gyro.std);
    out["gyro_predicted_std_readable"] = std::move(gyro.readable);
    out["gyro_targets"] = std::move(gyro.targets);
    out["gyro_nominal_scale"] = JsonNumber<Json>(plan.gyro.nominal_scale);
    out["gyro_extra_poses"] = plan.gyro_extra_poses;
  }
  out["message"] = plan.message;
  return out.dump(2) + "\n";
}

std::string CoverageToJson(const CoverageReport& r) {
  PredictionJson accel = PredictionToJson(r.accel, ReadableUnitOf);
  Json proposed = Json::array();
  for (const PlannedPose& p : r.proposed) {
    proposed.push_back({{"up", JsonVector<Json>(p.up)},
                        {"hold_s", JsonNumber<Json>(p.hold_seconds)},
                        {"instruction", p.instruction}});
  }
  Json out;
  out["positions"] = r.positions;
  out["nominal_scale"] = JsonNumber<Json>(r.accel.nominal_scale);
  out["predicted_std"] = std::move(accel.std);
  out["predicted_std_readable"] = std::move(accel.readable);
  out["undetermined"] = r.undetermined;
  out["short_of_target"] = r.short_of_target;
  out["proposed"] = proposed;
  out["undetermined_with_proposed"] = r.undetermined_with_proposed;
  if (std::isfinite(r.temperature_span)) {
    out["temperature_span"] = r.temperature_span;
    out["temperature"] = r.temperature;
  }
  out["message"] = r.message;
  return out.dump();
}

bool WritePlanJson(const RecordingPlan& plan, const std::string& path, std::string* error) {
  return WriteFileAtomically(path, PlanToJson(plan), error);
}

bool PlanPosesFromJson(const std::string& text, const std::string& name,
                       std::vector<PlannedPose>* poses, std::string* error) {
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (j.is_discarded() || !j.is_object()) {
    *error = name + (j.is_discarded() ? ": not valid JSON" : ": not a JSON object");
    return false;
  }
  if (const std::string twice = internal::DuplicateJsonKey(text); !twice.empty()) {
    *error = name + ": key '" + twice + "' appears twice (a key may be set once)";
    return false;
  }
  if (!j.contains("poses") || !j["poses"].is_array() || j["poses"].empty()) {
    *error = name + ": key 'poses' must be a non-empty array";
    return false;
  }
  std::vector<PlannedPose> out;
  for (size_t k = 0; k < j["poses"].size(); ++k) {
    const nlohmann::json& p = j["poses"][k];
    const std::string where = name + ": poses[" + std::to_string(k) + "]";
    PlannedPose pose;
    bool ok = p.is_object() && p.contains("up") && p["up"].is_array() && p["up"].size() == 3;
    for (int i = 0; ok && i < 3; ++i) {
      ok = p["up"][i].is_number();
      if (ok) pose.up(i) = p["up"][i].get<double>();
    }
    if (!ok || !pose.up.allFinite() || !(pose.up.norm() > 0.5 && pose.up.norm() < 1.5)) {
      *error = where + ": 'up' must be a unit vector of 3 numbers";
      return false;
    }
    pose.up.normalize();
    if (!p.contains("hold_s") || !p["hold_s"].is_number() ||
        !(p["hold_s"].get<double>() > 0.0 && std::isfinite(p["hold_s"].get<double>()))) {
      *error = where + ": 'hold_s' must be a positive number of seconds";
      return false;
    }
    pose.hold_seconds = p["hold_s"].get<double>();
    if (p.contains("instruction") && p["instruction"].is_string()) {
      pose.instruction = p["instruction"].get<std::string>();
    }
    out.push_back(pose);
  }
  *poses = std::move(out);
  return true;
}

bool PlanRotationsFromJson(const std::string& text, const std::string& name, size_t pose_count,
                           std::vector<PlannedRotation>* rotations, std::string* error) {
  rotations->clear();
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (j.is_discarded() || !j.is_object()) {
    *error = name + (j.is_discarded() ? ": not valid JSON" : ": not a JSON object");
    return false;
  }
  if (const std::string twice = internal::DuplicateJsonKey(text); !twice.empty()) {
    *error = name + ": key '" + twice + "' appears twice (a key may be set once)";
    return false;
  }
  if (!j.contains("rotations")) return true;
  if (!j["rotations"].is_array()) {
    *error = name + ": key 'rotations' must be an array";
    return false;
  }
  for (size_t k = 0; k < j["rotations"].size(); ++k) {
    const nlohmann::json& r = j["rotations"][k];
    const std::string where = name + ": rotations[" + std::to_string(k) + "]";
    PlannedRotation turn;
    // Each field checked on its own, so the message names the one that is
    // wrong.
    const auto fail = [&](const std::string& what) {
      *error = where + ": " + what;
      return false;
    };
    if (!r.is_object()) return fail("must be an object with from, to, axis and angle_deg");
    for (const char* key : {"from", "to"}) {
      if (!r.contains(key) || !r[key].is_number_integer()) {
        return fail(std::string("'") + key + "' must be a pose index (an integer)");
      }
    }
    // Read wide and range-check before narrowing, so 2^32 + 1 is refused
    // rather than read as pose 1.
    const int64_t from = r["from"].get<int64_t>();
    const int64_t to = r["to"].get<int64_t>();
    if (from < 0 || to != from + 1 || static_cast<uint64_t>(to) >= pose_count) {
      return fail("'from' and 'to' must be consecutive pose indices (to = from + 1 < " +
                  std::to_string(pose_count) + ")");
    }
    turn.from = static_cast<int>(from);
    turn.to = static_cast<int>(to);
    bool axis_ok = r.contains("axis") && r["axis"].is_array() && r["axis"].size() == 3;
    for (int i = 0; axis_ok && i < 3; ++i) {
      axis_ok = r["axis"][i].is_number();
      if (axis_ok) turn.axis(i) = r["axis"][i].get<double>();
    }
    if (!axis_ok || !turn.axis.allFinite() || !(turn.axis.norm() > 0.5 && turn.axis.norm() < 1.5)) {
      return fail("'axis' must be a unit vector of 3 numbers");
    }
    if (!r.contains("angle_deg") || !r["angle_deg"].is_number() ||
        !(r["angle_deg"].get<double>() >= 0.0 && r["angle_deg"].get<double>() <= 180.0)) {
      return fail("'angle_deg' must be a number in [0, 180]");
    }
    turn.angle_deg = r["angle_deg"].get<double>();
    if (r.contains("duration_s")) {
      if (!r["duration_s"].is_number() || !(r["duration_s"].get<double>() >= 0.0) ||
          !std::isfinite(r["duration_s"].get<double>())) {
        return fail("'duration_s' must be a number of seconds >= 0");
      }
      turn.seconds = r["duration_s"].get<double>();
    }
    turn.axis.normalize();
    if (r.contains("instruction") && r["instruction"].is_string()) {
      turn.instruction = r["instruction"].get<std::string>();
    }
    rotations->push_back(turn);
  }
  return true;
}

bool ReadPlanPoses(const std::string& path, std::vector<PlannedPose>* poses, std::string* error,
                   std::vector<PlannedRotation>* rotations) {
  std::string text;
  if (!ReadFileBytes(path, &text, error)) return false;
  if (!PlanPosesFromJson(text, path, poses, error)) return false;
  return rotations == nullptr || PlanRotationsFromJson(text, path, poses->size(), rotations, error);
}

}  // namespace gravcal
