#include "io/thermal_json.h"

#include <cmath>

#include "io/json_helpers.h"

namespace gravcal {
namespace internal {

namespace {

using nlohmann::json;

constexpr ThermalQuantity kQuantities[] = {ThermalQuantity::kBias, ThermalQuantity::kScale,
                                           ThermalQuantity::kMisalignment};
constexpr ThermalSensor kSensors[] = {ThermalSensor::kAccel, ThermalSensor::kGyro};

// A term is written when it is active or was fitted (max_order > 0: an
// order of 0 chosen from the data is a result too).
bool Written(const ThermalPolynomial& p) { return p.active() || p.max_order > 0; }

json TermJson(ThermalSensor s, ThermalQuantity q, const ThermalPolynomial& p) {
  json units = json::array();
  for (int k = 1; k <= p.order; ++k) units.push_back(ThermalUnit(q, k));
  json coefficients = json::array(), stds = json::array(), determined = json::array();
  for (int i = 0; i < p.coefficients.rows(); ++i) {
    json c = json::array(), d = json::array(), sd = json::array();
    for (int k = 1; k <= p.order; ++k) {
      const bool known = p.Determined(i, k);
      c.push_back(known ? JsonNumber(p.coefficients(i, k - 1)) : json(nullptr));
      d.push_back(known);
      double v = NAN;
      if (known && i < static_cast<int>(p.covariance.size()) &&
          p.covariance[i].rows() == p.order + 1) {
        v = std::sqrt(p.covariance[i](k, k));
      }
      sd.push_back(JsonNumber(v));
    }
    coefficients.push_back(c);
    stds.push_back(sd);
    determined.push_back(d);
  }
  json out = {{"order", p.order},
              {"max_order", p.max_order},
              {"selection", p.selection},
              {"components", ThermalComponentNames(s, q)},
              {"unit", units},
              {"coefficients", coefficients},
              {"std", stds},
              {"determined", determined}};
  if (!p.covariance.empty()) {
    json cov = json::array();
    for (const Eigen::MatrixXd& c : p.covariance) cov.push_back(JsonMatrix(c));
    out["covariance"] = cov;
  }
  return out;
}

class Reader {
 public:
  Reader(const std::string& name, std::string* error) : name_(name), error_(error) {}
  bool Fail(const std::string& key, const std::string& what) {
    *error_ = name_ + ": key 'thermal" + (key.empty() ? "" : "." + key) + "': " + what;
    return false;
  }
  bool Number(const json& parent, const std::string& field, const std::string& key, bool allow_null,
              double* v) {
    if (!parent.contains(field)) return Fail(key, "is missing");
    const json& j = parent[field];
    if (allow_null && j.is_null()) {
      *v = NAN;
      return true;
    }
    if (!j.is_number())
      return Fail(key, allow_null ? "must be a number or null" : "must be a number");
    *v = j.get<double>();
    if (!std::isfinite(*v)) return Fail(key, "must be finite");
    return true;
  }
  // A rows x cols array of numbers (null allowed: NaN).
  bool Table(const json& parent, const std::string& field, const std::string& key, int rows,
             int cols, Eigen::MatrixXd* m) {
    if (!parent.contains(field)) return Fail(key, "is missing");
    const json& j = parent[field];
    const std::string what = "must be " + std::to_string(rows) + " arrays of " +
                             std::to_string(cols) + " numbers or null";
    if (!j.is_array() || static_cast<int>(j.size()) != rows) return Fail(key, what);
    m->resize(rows, cols);
    for (int r = 0; r < rows; ++r) {
      if (!j[r].is_array() || static_cast<int>(j[r].size()) != cols) return Fail(key, what);
      for (int c = 0; c < cols; ++c) {
        if (j[r][c].is_null()) {
          (*m)(r, c) = NAN;
        } else if (j[r][c].is_number()) {
          (*m)(r, c) = j[r][c].get<double>();
          if (!std::isfinite((*m)(r, c))) return Fail(key, what);
        } else {
          return Fail(key, what);
        }
      }
    }
    return true;
  }

 private:
  std::string name_;
  std::string* error_;
};

bool ReadTerm(const json& j, ThermalSensor s, ThermalQuantity q, const std::string& key, Reader* r,
              ThermalPolynomial* p) {
  if (!j.is_object()) return r->Fail(key, "must be an object");
  if (!j.contains("order") || !j["order"].is_number_integer()) {
    return r->Fail(key + ".order", "must be an integer");
  }
  const int order = j["order"].get<int>();
  if (order < 0 || order > kMaxThermalOrder) {
    return r->Fail(key + ".order", "must be between 0 and " + std::to_string(kMaxThermalOrder));
  }
  const int n = ThermalComponents(s, q);
  p->Resize(n, order);
  if (j.contains("max_order")) {
    if (!j["max_order"].is_number_integer())
      return r->Fail(key + ".max_order", "must be an integer");
    p->max_order = j["max_order"].get<int>();
  }
  if (j.contains("selection") && j["selection"].is_string()) {
    p->selection = j["selection"].get<std::string>();
  }
  if (order == 0) return true;
  Eigen::MatrixXd c;
  if (!r->Table(j, "coefficients", key + ".coefficients", n, order, &c)) return false;
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < order; ++k) {
      const bool known = std::isfinite(c(i, k));
      p->determined(i, k) = known;
      p->coefficients(i, k) = known ? c(i, k) : 0.0;
    }
  }
  if (j.contains("covariance")) {
    const json& cov = j["covariance"];
    if (!cov.is_array() || static_cast<int>(cov.size()) != n) {
      return r->Fail(key + ".covariance", "must hold one matrix per component");
    }
    for (int i = 0; i < n; ++i) {
      Eigen::MatrixXd m;
      json holder = {{"m", cov[i]}};
      if (!r->Table(holder, "m", key + ".covariance[" + std::to_string(i) + "]", order + 1,
                    order + 1, &m)) {
        return false;
      }
      p->covariance.push_back(m);
    }
  }
  return true;
}

}  // namespace

json ThermalJson(const ThermalModel& m) {
  json out = {{"reference_temperature", m.reference_temperature},
              {"valid_range", {JsonNumber(m.min_temperature), JsonNumber(m.max_temperature)}},
              {"temperature_unit", "degC"},
              {"lag_time_constant",
               {{"value", m.lag_time_constant},
                {"std", JsonNumber(m.lag_time_constant_std)},
                {"estimated", m.lag_estimated},
                {"unit", "s"}}}};
  for (ThermalSensor s : kSensors) {
    json sensor = json::object();
    for (ThermalQuantity q : kQuantities) {
      const ThermalPolynomial& p = m.Sensor(s).Term(q);
      if (Written(p)) sensor[ToString(q)] = TermJson(s, q, p);
    }
    if (!sensor.empty()) out[ToString(s)] = sensor;
  }
  out["notes"] = m.notes;
  return out;
}

bool ThermalFromJson(const json& j, const std::string& name, ThermalModel* model,
                     std::string* error) {
  Reader r(name, error);
  if (!j.is_object()) return r.Fail("", "must be an object");
  ThermalModel out;
  if (!r.Number(j, "reference_temperature", "reference_temperature", false,
                &out.reference_temperature)) {
    return false;
  }
  if (j.contains("valid_range")) {
    const json& v = j["valid_range"];
    Eigen::MatrixXd range;
    json holder = {{"v", json::array({v})}};
    if (!v.is_array() || !r.Table(holder, "v", "valid_range", 1, 2, &range)) {
      return r.Fail("valid_range", "must be [min, max] (numbers, or both null)");
    }
    out.min_temperature = range(0, 0);
    out.max_temperature = range(0, 1);
  }
  if (j.contains("lag_time_constant")) {
    const json& lag = j["lag_time_constant"];
    if (!lag.is_object()) return r.Fail("lag_time_constant", "must be an object");
    if (!r.Number(lag, "value", "lag_time_constant.value", false, &out.lag_time_constant)) {
      return false;
    }
    if (lag.contains("std") &&
        !r.Number(lag, "std", "lag_time_constant.std", true, &out.lag_time_constant_std)) {
      return false;
    }
    if (lag.contains("estimated") && lag["estimated"].is_boolean()) {
      out.lag_estimated = lag["estimated"].get<bool>();
    }
  }
  for (ThermalSensor s : kSensors) {
    if (!j.contains(ToString(s))) continue;
    const json& sensor = j[ToString(s)];
    if (!sensor.is_object()) return r.Fail(ToString(s), "must be an object");
    for (auto it = sensor.begin(); it != sensor.end(); ++it) {
      ThermalQuantity q;
      if (!FromString(it.key(), &q)) {
        return r.Fail(std::string(ToString(s)) + "." + it.key(),
                      "is not a thermal term (bias, scale, misalignment)");
      }
      if (!ReadTerm(it.value(), s, q, std::string(ToString(s)) + "." + it.key(), &r,
                    out.MutableSensor(s)->MutableTerm(q))) {
        return false;
      }
    }
  }
  if (j.contains("notes") && j["notes"].is_array()) {
    for (const json& n : j["notes"]) {
      if (n.is_string()) out.notes.push_back(n.get<std::string>());
    }
  }
  std::string why;
  if (!out.IsValid(&why)) {
    *error = name + ": key '" + why.substr(0, why.find(':')) + "'" + why.substr(why.find(':'));
    return false;
  }
  *model = std::move(out);
  return true;
}

}  // namespace internal
}  // namespace gravcal
