#include "gravcal/io/comparison_io.h"

#include <nlohmann/json.hpp>

#include "io/json_helpers.h"

namespace gravcal {

std::string ComparisonToJson(const ComparisonResult& r, const JsonSections& sections) {
  using Json = nlohmann::ordered_json;
  using internal::JsonNumber;
  Json j;
  j["consistent"] = r.consistent;
  j["p_value"] = JsonNumber<Json>(r.p_value);
  j["level"] = r.level;
  Json parameters = Json::array();
  for (size_t i = 0; i < r.parameters.size(); ++i) {
    const ParameterDifference& p = r.parameters[i];
    Json row;
    row["name"] = p.name;
    row["difference"] = JsonNumber<Json>(p.difference);
    row["std"] = JsonNumber<Json>(p.std);
    row["z"] = JsonNumber<Json>(p.z);
    row["shift_z"] = JsonNumber<Json>(p.shift_z);
    row["minimal_detectable_change"] = JsonNumber<Json>(
        i < r.minimal_detectable_change.size() ? r.minimal_detectable_change[i] : NAN);
    parameters.push_back(row);
  }
  j["parameters"] = parameters;
  j["tested"] = r.tested;
  j["chi2"] = JsonNumber<Json>(r.chi2);
  j["dof"] = r.dof;
  j["chi2_p_value"] = JsonNumber<Json>(r.chi2_p_value);
  j["max_shift_p_value"] = JsonNumber<Json>(r.max_shift_p_value);
  Json changed = nullptr;
  if (!r.changed.empty()) {
    changed = Json::object();
    changed["name"] = r.changed;
    changed["size"] = JsonNumber<Json>(r.changed_size);
    changed["sigmas"] = JsonNumber<Json>(r.changed_sigmas);
    changed["indistinguishable"] = r.indistinguishable;
  }
  j["changed"] = changed;
  j["undetermined"] = r.undetermined;
  j["not_compared"] = r.not_compared;
  j["power"] = r.power;
  j["message"] = r.message;
  for (const auto& [key, text] : sections) {
    const Json section = Json::parse(text, nullptr, false);
    if (!section.is_discarded()) j[key] = section;
  }
  return j.dump(2) + "\n";
}

}  // namespace gravcal
