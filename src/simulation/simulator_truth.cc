// TruthToJson: a simulated session's truth as JSON (truth.json).
#include <exception>
#include <nlohmann/json.hpp>
#include <string>

#include "gravcal/simulation/simulator.h"
#include "io/json_helpers.h"
#include "simulation/simulator_fields.h"

namespace gravcal {
namespace {

using internal::JsonMatrix;
using internal::JsonVector;

nlohmann::json OptionJson(double v) { return internal::JsonNumber(v); }
nlohmann::json OptionJson(bool v) { return v; }
nlohmann::json OptionJson(const std::string& v) { return v; }
nlohmann::json OptionJson(const SimulatorScheme& v) { return ToString(v); }
nlohmann::json OptionJson(RotationProfile v) { return ToString(v); }

}  // namespace

std::string TruthToJson(const SimulatedSession& session, const SimulatorOptions& options) {
  try {
    nlohmann::json j;
    j["seed"] = session.seed;
    j["gravity"] = session.gravity;
    const AccelModel& a = session.accel_truth;
    j["accel"] = {{"model", ToString(a.parameterization)},
                  {"bias", JsonVector(a.bias)},
                  {"matrix", JsonMatrix(a.matrix())},
                  {"upper", JsonMatrix(a.upper)},
                  {"rotation", JsonMatrix(a.rotation)}};
    j["gyro"] = {{"bias", JsonVector(session.gyro_truth.bias)},
                 {"matrix", JsonMatrix(session.gyro_truth.matrix)},
                 {"g_sensitivity", JsonMatrix(session.gyro_g_sensitivity)}};
    j["accel_units_per_si"] = session.accel_units_per_si;
    j["gyro_units_per_si"] = session.gyro_units_per_si;
    nlohmann::json poses = nlohmann::json::array();
    const std::vector<double>& t = session.log.t;
    for (const SimulatedPose& p : session.poses) {
      const Eigen::Quaterniond& q = p.attitude;
      const bool inside = p.begin < p.end && p.end <= t.size();
      poses.push_back({{"begin", p.begin},
                       {"end", p.end},
                       {"t_begin", inside ? t[p.begin] : 0.0},
                       {"t_end", inside ? t[p.end - 1] : 0.0},
                       {"nominal_up", p.nominal_up},
                       {"quaternion", {q.w(), q.x(), q.y(), q.z()}}});
    }
    j["poses"] = poses;
    // Every keyed field, from the options' own table (simulator_fields.h);
    // a number that is not finite (latitude off) is null.
    nlohmann::json& fields = j["options"];
    fields = nlohmann::json::object();
    for (const internal::SimulatorField& field : internal::SimulatorFields()) {
      internal::WithFieldValue(field, options,
                               [&](const auto& value) { fields[field.name] = OptionJson(value); });
    }
    // Every effect's values by name (a 3x3 matrix as rows).
    const EffectParameters& e = session.effects;
    nlohmann::json& effects = j["effects"];
    effects = {{"reference_temperature", e.reference_temperature}};
    for (const EffectInfo& info : EffectCatalogue()) {
      if (e.Block(info.effect) == nullptr) continue;
      effects[info.name] = info.num_parameters == 9 ? JsonMatrix(e.Matrix(info.effect))
                                                    : JsonVector(e.Vector(info.effect));
    }
    return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
  } catch (const std::exception&) {
    return "{}";
  }
}

}  // namespace gravcal
