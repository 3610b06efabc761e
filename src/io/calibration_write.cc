// Writing a calibration: its JSON (with extra sections), the history CSV and
// the provenance of the log it came from. Reading and the model checks are in
// calibration_read.cc.
#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>
#include <utility>

#include "core/conditional_sigmas.h"
#include "gravcal/core/imu_model.h"
#include "gravcal/io/calibration_io.h"
#include "gravcal/io/files.h"
#include "io/json_helpers.h"
#include "io/thermal_json.h"
#include "util/content_hash.h"
#include "util/error.h"
#include "util/units.h"

namespace gravcal {
namespace {

using internal::JsonArray;
using internal::JsonMatrix;
using internal::JsonNumber;
using internal::JsonVector;
using nlohmann::json;

// accel: the model, its standard deviations and, when present, covariance,
// pose variance and placement error.
json AccelJson(const AccelCalibration& a, bool include_covariance) {
  json accel;
  accel["model"] = ToString(a.model.parameterization);
  accel["bias"] = JsonVector(a.model.bias);
  accel["matrix"] = JsonMatrix(a.model.matrix());
  accel["upper"] = JsonMatrix(a.model.upper);
  accel["rotation"] = JsonMatrix(a.model.rotation);
  accel["std"] = {{"bias", JsonVector(a.bias_std)}, {"matrix", JsonMatrix(a.matrix_std)}};
  if (include_covariance && a.covariance.size() > 0) {
    accel["covariance"] = {{"parameters", a.covariance_names},
                           {"matrix", JsonMatrix(a.covariance)}};
  }
  if (a.pose_variance.estimated) {
    // s^2 of |a| between poses beyond the white noise, its standard
    // deviation, s itself, and whether the standard deviations carry it.
    const VarianceComponent& v = a.pose_variance;
    accel["pose_variance"] = {{"value", JsonNumber(v.variance)},
                              {"std", JsonNumber(v.variance_std)},
                              {"unit", "(m/s^2)^2"},
                              {"s", JsonNumber(std::sqrt(v.variance))},
                              {"absorbed", v.absorbed},
                              {"dof", v.dof}};
  }
  if (a.model.parameterization == AccelParameterization::kAffine) {
    accel["placement_error_deg"] = JsonNumber(a.tilt_rms * internal::kRadToDeg);
  }
  return accel;
}

// gyro: the model, standard deviations, covariance, method extras and
// rotation residuals.
json GyroJson(const GyroCalibration& g, bool include_covariance) {
  json gyro;
  gyro["bias"] = JsonVector(g.model.bias);
  gyro["matrix"] = JsonMatrix(g.model.matrix);
  gyro["std"] = {{"bias", JsonVector(g.bias_std)}, {"matrix", JsonMatrix(g.matrix_std)}};
  if (include_covariance && g.covariance.size() > 0) {
    gyro["covariance"] = {{"parameters", g.covariance_names}, {"matrix", JsonMatrix(g.covariance)}};
  }
  json extra = json::object();
  for (size_t i = 0; i < g.extra_names.size(); ++i) {
    extra[g.extra_names[i]] = {{"value", JsonNumber(g.extra_values[i])},
                               {"std", JsonNumber(g.extra_std[i])}};
  }
  if (!extra.empty()) gyro["extra"] = extra;
  if (!g.rotation_residual_deg.empty()) {
    gyro["rotation_residual_deg"] = JsonArray(g.rotation_residual_deg);
  }
  return gyro;
}

// Issue 6: effects beyond the textbook model, by catalogue name.
json EffectsJson(const EffectCalibration& e) {
  json effects = {{"reference_temperature", JsonNumber(e.reference_temperature)},
                  {"reference_time", JsonNumber(e.reference_time)}};
  for (const EffectEstimate& estimate : e.estimates) {
    json values = json::array(), stds = json::array();
    for (size_t i = 0; i < estimate.values.size(); ++i) {
      values.push_back(JsonNumber(estimate.values[i]));
      stds.push_back(JsonNumber(i < estimate.std.size() ? estimate.std[i] : NAN));
    }
    effects[ToString(estimate.effect)] = {
        {"parameters", estimate.names}, {"value", values}, {"std", stds}, {"unit", estimate.unit}};
  }
  return effects;
}

json ResidualJson(const Calibration& c) {
  auto summary = [](const ResidualSummary& s) {
    return json{{"rms", JsonNumber(s.rms)}, {"max", JsonNumber(s.max)}};
  };
  return {{"unit", "m/s^2"},
          {"quantity", "|a| - g over static positions"},
          {"before", summary(c.residual_nominal)},
          {"coarse", summary(c.residual_coarse)},
          {"after", summary(c.residual_refined)}};
}

json PositionJson(const PositionReport& r) {
  json p = {{"t_begin", r.position.t_begin},
            {"t_end", r.position.t_end},
            {"samples", r.position.sample_count},
            {"raw_mean", JsonVector(r.position.raw_mean)},
            {"raw_std", JsonVector(r.raw_std)},
            {"nominal_up", NominalAxisName(r.nominal_up)},
            {"residual_before", JsonNumber(r.residual_before)},
            {"residual_after", JsonNumber(r.residual_after)},
            {"sigma", JsonNumber(r.sigma)}};
  if (std::isfinite(r.position.temperature)) p["temperature"] = r.position.temperature;
  // Issue 36: rad/s per sample, where the gyroscope's unit is known.
  if (r.gyro_std.allFinite()) p["gyro_std"] = JsonVector(r.gyro_std);
  // Only the methods that use an attitude per position have one.
  if (std::isfinite(r.roll_deg) && std::isfinite(r.pitch_deg)) {
    p["attitude_deg"] = {{"roll", r.roll_deg},
                         {"pitch", r.pitch_deg},
                         {"roll_std", JsonNumber(r.roll_std_deg)},
                         {"pitch_std", JsonNumber(r.pitch_std_deg)}};
  }
  return p;
}

json SolverJson(const Calibration& c) {
  const RefinementResult& f = c.refinement;
  return {{"method", c.solver_name},
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
}

// Issue 4: per-parameter convergence of recursive methods.
json ConvergenceJson(const ConvergenceReport& report) {
  json entries = json::object();
  for (const ConvergenceEntry& e : report.entries) {
    entries[e.name] = {{"value", JsonNumber(e.value)},
                       {"unit", e.unit},
                       {"sigma_initial", JsonNumber(e.sigma_initial)},
                       {"sigma_final", JsonNumber(e.sigma_final)},
                       {"converged", e.converged},
                       {"time_s", JsonNumber(e.time)}};
  }
  return {{"criterion", report.criterion}, {"parameters", entries}};
}

// Issue 16: the log the calibration came from, and this gravcal's version.
json ProvenanceJson(const CalibrationProvenance& p) {
  json out = {{"gravcal_version", p.gravcal_version.empty() ? GRAVCAL_VERSION : p.gravcal_version}};
  if (!p.log_file.empty()) out["log_file"] = p.log_file;
  if (!p.log_hash.empty()) out["log_hash"] = p.log_hash;
  return out;
}

}  // namespace

std::string CalibrationToJson(const Calibration& c, bool include_covariance) {
  json out;
  out["method"] = c.method;
  out["accel"] = AccelJson(c.accel, include_covariance);
  // The undetermined terms the fit held: every accelerometer standard
  // deviation is conditional on holding them (issue 33).
  const std::vector<std::string> held = internal::ConditionalOn(c.refinement);
  if (!held.empty()) out["accel"]["std"]["conditional_on"] = held;
  if (c.gyro.estimated) out["gyro"] = GyroJson(c.gyro, include_covariance);
  if (!c.effects.estimates.empty()) out["effects"] = EffectsJson(c.effects);
  if (c.thermal.active() || !c.thermal.notes.empty()) {
    out["thermal"] = internal::ThermalJson(c.thermal);
  }
  out["gravity"] = {{"value", c.gravity}, {"source", c.gravity_source}};
  out["residual"] = ResidualJson(c);
  json positions = json::array();
  for (const PositionReport& r : c.positions) positions.push_back(PositionJson(r));
  out["positions"] = positions;
  out["solver"] = SolverJson(c);
  if (!c.convergence.entries.empty()) out["convergence"] = ConvergenceJson(c.convergence);
  out["warnings"] = c.warnings;
  out["message"] = c.message;
  out["provenance"] = ProvenanceJson(c.provenance);
  return out.dump(2) + "\n";
}

bool HistoryToCsv(const Calibration& calibration, std::string* csv, std::string* error) {
  const EstimateHistory& h = calibration.history;
  if (h.rows() == 0) {
    *error = "method '" + calibration.method + "' has no time history to write";
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
  *csv = s.str();
  return true;
}

bool WriteHistoryCsv(const Calibration& calibration, const std::string& path, std::string* error) {
  std::string csv;
  if (!HistoryToCsv(calibration, &csv, error))
    return internal::SetError(error, path + ": " + *error);
  return WriteFileAtomically(path, csv, error);
}

bool WriteCalibrationJson(const Calibration& calibration, bool include_covariance,
                          const std::string& path, std::string* error) {
  return WriteFileAtomically(path, CalibrationToJson(calibration, include_covariance), error);
}

std::string CalibrationToJson(const Calibration& calibration, bool include_covariance,
                              const JsonSections& sections) {
  json out = json::parse(CalibrationToJson(calibration, include_covariance));
  for (const auto& [key, text] : sections) {
    json section = json::parse(text, nullptr, false);
    if (!section.is_discarded()) out[key] = std::move(section);
  }
  return out.dump(2) + "\n";
}

bool WriteCalibrationJson(const Calibration& calibration, bool include_covariance,
                          const JsonSections& sections, const std::string& path,
                          std::string* error) {
  return WriteFileAtomically(path, CalibrationToJson(calibration, include_covariance, sections),
                             error);
}

bool LogProvenance(const std::string& path, CalibrationProvenance* provenance, std::string* error) {
  std::string bytes;
  if (!ReadFileBytes(path, &bytes, error)) return false;
  *provenance = LogProvenanceOfBytes(path, bytes);
  return true;
}

CalibrationProvenance LogProvenanceOfBytes(const std::string& path, const std::string& bytes) {
  internal::ContentHash hash;
  hash.Add(bytes);
  return {path, hash.Hex(), GRAVCAL_VERSION};
}

}  // namespace gravcal
