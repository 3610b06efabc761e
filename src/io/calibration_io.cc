#include "gravcal/io/calibration_io.h"

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "gravcal/io/log_reader.h"
#include "io/json_helpers.h"
#include "util/units.h"

namespace gravcal {
namespace {

using internal::JsonArray;
using internal::JsonMatrix;
using internal::JsonNumber;
using internal::JsonVector;
using nlohmann::json;

}  // namespace

std::string CalibrationToJson(const Calibration& c, bool include_covariance) {
  json accel;
  accel["model"] = ToString(c.accel.model.parameterization);
  accel["bias"] = JsonVector(c.accel.model.bias);
  accel["matrix"] = JsonMatrix(c.accel.model.matrix());
  accel["upper"] = JsonMatrix(c.accel.model.upper);
  accel["rotation"] = JsonMatrix(c.accel.model.rotation);
  accel["std"] = {{"bias", JsonVector(c.accel.bias_std)},
                  {"matrix", JsonMatrix(c.accel.matrix_std)}};
  if (include_covariance && c.accel.covariance.size() > 0) {
    accel["covariance"] = {{"parameters", c.accel.covariance_names},
                           {"matrix", JsonMatrix(c.accel.covariance)}};
  }
  if (c.accel.pose_variance.estimated) {
    // s^2 of |a| between poses beyond the white noise, its standard
    // deviation, s itself, and whether the standard deviations carry it.
    const VarianceComponent& v = c.accel.pose_variance;
    accel["pose_variance"] = {{"value", JsonNumber(v.variance)},
                              {"std", JsonNumber(v.variance_std)},
                              {"unit", "(m/s^2)^2"},
                              {"s", JsonNumber(std::sqrt(v.variance))},
                              {"absorbed", v.absorbed},
                              {"dof", v.dof}};
  }
  if (c.accel.model.parameterization == AccelParameterization::kAffine) {
    accel["placement_error_deg"] = JsonNumber(c.accel.tilt_rms * internal::kRadToDeg);
  }
  json out;
  out["method"] = c.method;
  out["accel"] = accel;
  if (c.gyro.estimated) {
    json gyro;
    gyro["bias"] = JsonVector(c.gyro.model.bias);
    gyro["matrix"] = JsonMatrix(c.gyro.model.matrix);
    gyro["std"] = {{"bias", JsonVector(c.gyro.bias_std)},
                   {"matrix", JsonMatrix(c.gyro.matrix_std)}};
    if (include_covariance && c.gyro.covariance.size() > 0) {
      gyro["covariance"] = {{"parameters", c.gyro.covariance_names},
                            {"matrix", JsonMatrix(c.gyro.covariance)}};
    }
    json extra = json::object();
    for (size_t i = 0; i < c.gyro.extra_names.size(); ++i) {
      extra[c.gyro.extra_names[i]] = {{"value", JsonNumber(c.gyro.extra_values[i])},
                                      {"std", JsonNumber(c.gyro.extra_std[i])}};
    }
    if (!extra.empty()) gyro["extra"] = extra;
    if (!c.gyro.rotation_residual_deg.empty()) {
      gyro["rotation_residual_deg"] = JsonArray(c.gyro.rotation_residual_deg);
    }
    out["gyro"] = gyro;
  }
  // Issue 6: effects beyond the textbook model, by catalogue name.
  if (!c.effects.estimates.empty()) {
    json effects = {{"reference_temperature", JsonNumber(c.effects.reference_temperature)},
                    {"reference_time", JsonNumber(c.effects.reference_time)}};
    for (const EffectEstimate& e : c.effects.estimates) {
      json values = json::array(), stds = json::array();
      for (size_t i = 0; i < e.values.size(); ++i) {
        values.push_back(JsonNumber(e.values[i]));
        stds.push_back(JsonNumber(i < e.std.size() ? e.std[i] : NAN));
      }
      effects[ToString(e.effect)] = {
          {"parameters", e.names}, {"value", values}, {"std", stds}, {"unit", e.unit}};
    }
    out["effects"] = effects;
  }
  out["gravity"] = {{"value", c.gravity}, {"source", c.gravity_source}};
  auto summary = [](const ResidualSummary& s) {
    return json{{"rms", JsonNumber(s.rms)}, {"max", JsonNumber(s.max)}};
  };
  out["residual"] = {{"unit", "m/s^2"},
                     {"quantity", "|a| - g over static positions"},
                     {"before", summary(c.residual_nominal)},
                     {"coarse", summary(c.residual_coarse)},
                     {"after", summary(c.residual_refined)}};
  json positions = json::array();
  for (const PositionReport& r : c.positions) {
    json p = {{"t_begin", r.position.t_begin},
              {"t_end", r.position.t_end},
              {"samples", r.position.sample_count},
              {"raw_mean", JsonVector(r.position.raw_mean)},
              {"raw_std", JsonVector(r.raw_std)},
              {"nominal_up", NominalAxisName(r.nominal_up)},
              {"residual_before", JsonNumber(r.residual_before)},
              {"residual_after", JsonNumber(r.residual_after)},
              {"sigma", JsonNumber(r.sigma)}};
    // Only the methods that use an attitude per position have one.
    if (std::isfinite(r.roll_deg) && std::isfinite(r.pitch_deg)) {
      p["attitude_deg"] = {{"roll", r.roll_deg},
                           {"pitch", r.pitch_deg},
                           {"roll_std", JsonNumber(r.roll_std_deg)},
                           {"pitch_std", JsonNumber(r.pitch_std_deg)}};
    }
    positions.push_back(p);
  }
  out["positions"] = positions;
  const RefinementResult& f = c.refinement;
  out["solver"] = {{"method", c.solver_name},
                   {"coarse", ToString(c.coarse.method)},
                   {"iterations", f.iterations},
                   {"termination", f.termination},
                   {"converged", f.converged},
                   {"time_s", f.solve_seconds},
                   {"initial_cost", f.initial_cost},
                   {"final_cost", f.final_cost},
                   {"chi2", f.chi2},
                   {"dof", f.dof},
                   {"message", f.message}};
  // Issue 4: per-parameter convergence of recursive methods.
  if (!c.convergence.entries.empty()) {
    json entries = json::object();
    for (const ConvergenceEntry& e : c.convergence.entries) {
      entries[e.name] = {{"value", JsonNumber(e.value)},
                         {"unit", e.unit},
                         {"sigma_initial", JsonNumber(e.sigma_initial)},
                         {"sigma_final", JsonNumber(e.sigma_final)},
                         {"converged", e.converged},
                         {"time_s", JsonNumber(e.time)}};
    }
    out["convergence"] = {{"criterion", c.convergence.criterion}, {"parameters", entries}};
  }
  out["warnings"] = c.warnings;
  out["message"] = c.message;
  return out.dump(2) + "\n";
}

bool WriteHistoryCsv(const Calibration& calibration, const std::string& path, std::string* error) {
  const EstimateHistory& h = calibration.history;
  if (h.rows() == 0) {
    *error = path + ": method '" + calibration.method + "' has no time history to write";
    return false;
  }
  std::ostringstream s;
  s.precision(10);
  for (size_t c = 0; c < h.columns.size(); ++c) s << (c ? "," : "") << h.columns[c];
  s << "\n";
  for (size_t r = 0; r < h.rows(); ++r) {
    for (size_t c = 0; c < h.columns.size(); ++c) {
      s << (c ? "," : "") << h.values[r * h.columns.size() + c];
    }
    s << "\n";
  }
  return WriteFileAtomically(path, s.str(), error);
}

bool WriteCalibrationJson(const Calibration& calibration, bool include_covariance,
                          const std::string& path, std::string* error) {
  return WriteFileAtomically(path, CalibrationToJson(calibration, include_covariance), error);
}

namespace {

bool ReadVector(const json& j, const std::string& key, const std::string& where, Eigen::Vector3d* v,
                std::string* error) {
  if (!j.contains(key) || !j[key].is_array() || j[key].size() != 3) {
    *error = where + ": key '" + key + "' must be an array of 3 numbers";
    return false;
  }
  for (int i = 0; i < 3; ++i) {
    if (!j[key][i].is_number()) {
      *error = where + ": key '" + key + "' must be an array of 3 numbers";
      return false;
    }
    (*v)(i) = j[key][i].get<double>();
  }
  return true;
}

bool ReadMatrix(const json& j, const std::string& key, const std::string& where, Eigen::Matrix3d* m,
                std::string* error) {
  const std::string message = where + ": key '" + key + "' must be a 3x3 array of numbers";
  if (!j.contains(key) || !j[key].is_array() || j[key].size() != 3) {
    *error = message;
    return false;
  }
  for (int r = 0; r < 3; ++r) {
    if (!j[key][r].is_array() || j[key][r].size() != 3) {
      *error = message;
      return false;
    }
    for (int c = 0; c < 3; ++c) {
      if (!j[key][r][c].is_number()) {
        *error = message;
        return false;
      }
      (*m)(r, c) = j[key][r][c].get<double>();
    }
  }
  return true;
}

}  // namespace

bool ReadCalibrationJson(const std::string& path, LoadedCalibration* calibration,
                         std::string* error) {
  std::ifstream in(path);
  if (!in) {
    *error = path + ": cannot open";
    return false;
  }
  json j;
  try {
    j = json::parse(in);
  } catch (const json::exception& e) {
    // parse_error, and out_of_range for a number beyond double (found by
    // fuzz/fuzz_calibration_json: "1e999999" aborted gravcal apply).
    *error = path + ": not valid JSON (" + e.what() + ")";
    return false;
  }
  if (!j.is_object() || !j.contains("accel") || !j["accel"].is_object()) {
    *error = path + ": key 'accel' is missing";
    return false;
  }
  LoadedCalibration out;
  Eigen::Matrix3d m;
  Eigen::Vector3d b;
  if (!ReadVector(j["accel"], "bias", path + ": accel", &b, error) ||
      !ReadMatrix(j["accel"], "matrix", path + ": accel", &m, error)) {
    return false;
  }
  AccelParameterization p = AccelParameterization::kAffine;
  if (j["accel"].contains("model") && j["accel"]["model"].is_string()) {
    FromString(j["accel"]["model"].get<std::string>(), &p);
  }
  if (!AccelModel::FromMatrix(b, m, p, &out.accel)) {
    *error = path + ": accel.matrix is singular or a reflection";
    return false;
  }
  if (j.contains("gyro") && j["gyro"].is_object()) {
    if (!ReadVector(j["gyro"], "bias", path + ": gyro", &out.gyro.bias, error) ||
        !ReadMatrix(j["gyro"], "matrix", path + ": gyro", &out.gyro.matrix, error)) {
      return false;
    }
    out.has_gyro = true;
  }
  if (j.contains("gravity") && j["gravity"].is_object() && j["gravity"].contains("value") &&
      j["gravity"]["value"].is_number()) {
    out.gravity = j["gravity"]["value"].get<double>();
  }
  *calibration = out;
  return true;
}

}  // namespace gravcal
