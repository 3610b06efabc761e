#include "gravcal/io/calibration_uncertainty_io.h"

#include <cmath>
#include <nlohmann/json.hpp>
#include <vector>

#include "gravcal/io/files.h"

namespace gravcal {

namespace {

using json = nlohmann::json;

bool Fail(const std::string& name, const std::string& key, const std::string& what,
          std::string* error) {
  *error = name + ": key '" + key + "': " + what;
  return false;
}

// A number, or NaN for null (an undetermined standard deviation).
bool NumberOrNull(const json& v, double* out) {
  if (v.is_null()) {
    *out = NAN;
    return true;
  }
  if (!v.is_number()) return false;
  *out = v.get<double>();
  return std::isfinite(*out);
}

// sensor.std.bias [3] and sensor.std.matrix [3][3] (null allowed); absent
// keys leave NaN.
bool ReadStd(const json& sensor, const std::string& name, const std::string& prefix,
             Eigen::Vector3d* bias_std, Eigen::Matrix3d* matrix_std, std::string* error) {
  if (!sensor.contains("std")) return true;
  const json& s = sensor["std"];
  if (!s.is_object()) return Fail(name, prefix + ".std", "must be an object", error);
  if (s.contains("bias")) {
    const json& b = s["bias"];
    if (!b.is_array() || b.size() != 3) {
      return Fail(name, prefix + ".std.bias", "must be an array of 3 numbers or nulls", error);
    }
    for (int i = 0; i < 3; ++i) {
      if (!NumberOrNull(b[i], &(*bias_std)(i)) || (*bias_std)(i) < 0.0) {
        return Fail(name, prefix + ".std.bias", "must hold non-negative numbers or nulls", error);
      }
    }
  }
  if (s.contains("matrix")) {
    const json& m = s["matrix"];
    bool ok = m.is_array() && m.size() == 3;
    for (int r = 0; ok && r < 3; ++r) {
      ok = m[r].is_array() && m[r].size() == 3;
      for (int c = 0; ok && c < 3; ++c) {
        ok = NumberOrNull(m[r][c], &(*matrix_std)(r, c)) && !((*matrix_std)(r, c) < 0.0);
      }
    }
    if (!ok) {
      return Fail(name, prefix + ".std.matrix", "must be 3 rows of 3 non-negative numbers or nulls",
                  error);
    }
  }
  return true;
}

// sensor.covariance {parameters, matrix}: absent = none.
bool ReadCovariance(const json& sensor, const std::string& name, const std::string& prefix,
                    Eigen::MatrixXd* covariance, std::vector<std::string>* names,
                    std::string* error) {
  covariance->resize(0, 0);
  names->clear();
  if (!sensor.contains("covariance") || sensor["covariance"].is_null()) return true;
  const json& c = sensor["covariance"];
  const std::string key = prefix + ".covariance";
  if (!c.is_object() || !c.contains("parameters") || !c.contains("matrix")) {
    return Fail(name, key, "must be an object with 'parameters' and 'matrix'", error);
  }
  const json& p = c["parameters"];
  if (!p.is_array() || p.empty()) {
    return Fail(name, key + ".parameters", "must be a non-empty array of names", error);
  }
  for (const json& n : p) {
    if (!n.is_string()) return Fail(name, key + ".parameters", "must hold names", error);
    names->push_back(n.get<std::string>());
  }
  const int n = static_cast<int>(names->size());
  const json& m = c["matrix"];
  if (!m.is_array() || static_cast<int>(m.size()) != n) {
    return Fail(name, key + ".matrix",
                "must have one row per parameter (" + std::to_string(n) + ")", error);
  }
  covariance->resize(n, n);
  for (int r = 0; r < n; ++r) {
    if (!m[r].is_array() || static_cast<int>(m[r].size()) != n) {
      return Fail(name, key + ".matrix",
                  "row " + std::to_string(r) + " must have " + std::to_string(n) + " numbers",
                  error);
    }
    for (int k = 0; k < n; ++k) {
      if (!m[r][k].is_number() || !std::isfinite(m[r][k].get<double>())) {
        return Fail(
            name, key + ".matrix",
            "entry (" + std::to_string(r) + ", " + std::to_string(k) + ") must be a finite number",
            error);
      }
      (*covariance)(r, k) = m[r][k].get<double>();
    }
  }
  for (int r = 0; r < n; ++r) {
    if ((*covariance)(r, r) < 0.0) {
      return Fail(name, key + ".matrix", "has a negative variance on its diagonal", error);
    }
    for (int k = 0; k < r; ++k) {
      const double scale = std::sqrt((*covariance)(r, r) * (*covariance)(k, k));
      if (std::fabs((*covariance)(r, k) - (*covariance)(k, r)) > 1e-9 * scale + 1e-300) {
        return Fail(name, key + ".matrix", "is not symmetric", error);
      }
    }
  }
  return true;
}

}  // namespace

bool CalibrationUncertaintyFromJson(const std::string& text, const std::string& name,
                                    Calibration* calibration, LoadedCalibration* loaded,
                                    std::string* error) {
  LoadedCalibration models;
  if (!CalibrationFromJson(text, name, &models, error)) return false;
  // CalibrationFromJson has parsed and checked the text.
  const json j = json::parse(text);
  Calibration out;
  out.accel.model = models.corrector.accel;
  out.method = models.method;
  out.gravity = models.gravity;
  out.provenance = models.provenance;
  // The thermal model: verify takes check poses to T_ref with it, and the
  // acceptance limits read its temperature sensitivity.
  out.thermal = models.corrector.thermal;
  if (j.contains("gravity") && j["gravity"].is_object() && j["gravity"].contains("source") &&
      j["gravity"]["source"].is_string()) {
    out.gravity_source = j["gravity"]["source"].get<std::string>();
  }
  // residual.after.rms: |a| - g rms of the refined model (acceptance limits).
  if (j.contains("residual") && j["residual"].is_object() && j["residual"].contains("after") &&
      j["residual"]["after"].is_object() && j["residual"]["after"].contains("rms") &&
      j["residual"]["after"]["rms"].is_number()) {
    out.residual_refined.rms = j["residual"]["after"]["rms"].get<double>();
  } else {
    out.residual_refined.rms = NAN;
  }
  // The holds as far as acceptance limits need them (noise density,
  // temperature); CalibrationFromJson checked raw_mean, t_begin and t_end.
  if (j.contains("positions") && j["positions"].is_array()) {
    for (const json& p : j["positions"]) {
      PositionReport r;
      r.position.t_begin = p["t_begin"].get<double>();
      r.position.t_end = p["t_end"].get<double>();
      for (int i = 0; i < 3; ++i) r.position.raw_mean(i) = p["raw_mean"][i].get<double>();
      if (p.contains("samples") && p["samples"].is_number_unsigned()) {
        r.position.sample_count = p["samples"].get<size_t>();
      }
      r.raw_std.setConstant(NAN);
      if (p.contains("raw_std") && p["raw_std"].is_array() && p["raw_std"].size() == 3) {
        for (int i = 0; i < 3; ++i) {
          if (p["raw_std"][i].is_number()) r.raw_std(i) = p["raw_std"][i].get<double>();
        }
      }
      if (p.contains("gyro_std")) {
        const std::string key = "positions[" + std::to_string(out.positions.size()) + "].gyro_std";
        const json& g = p["gyro_std"];
        if (!g.is_array() || g.size() != 3) {
          return Fail(name, key, "must be an array of 3 numbers (rad/s)", error);
        }
        for (int i = 0; i < 3; ++i) {
          if (!g[i].is_number() || !(g[i].get<double>() >= 0.0)) {
            return Fail(name, key, "must hold non-negative numbers (rad/s)", error);
          }
          r.gyro_std(i) = g[i].get<double>();
        }
      }
      r.position.temperature = NAN;
      if (p.contains("temperature") && p["temperature"].is_number()) {
        r.position.temperature = p["temperature"].get<double>();
      }
      out.positions.push_back(r);
    }
  }
  const json& accel = j["accel"];
  if (!ReadStd(accel, name, "accel", &out.accel.bias_std, &out.accel.matrix_std, error) ||
      !ReadCovariance(accel, name, "accel", &out.accel.covariance, &out.accel.covariance_names,
                      error)) {
    return false;
  }
  if (models.corrector.has_gyro && j.contains("gyro")) {
    out.gyro.estimated = true;
    out.gyro.model = models.corrector.gyro;
    const json& gyro = j["gyro"];
    if (!ReadStd(gyro, name, "gyro", &out.gyro.bias_std, &out.gyro.matrix_std, error) ||
        !ReadCovariance(gyro, name, "gyro", &out.gyro.covariance, &out.gyro.covariance_names,
                        error)) {
      return false;
    }
  }
  out.success = true;
  out.message = "read from " + name;
  *calibration = std::move(out);
  if (loaded != nullptr) *loaded = std::move(models);
  return true;
}

bool ReadCalibrationUncertainty(const std::string& path, Calibration* calibration,
                                LoadedCalibration* loaded, std::string* error) {
  std::string text;
  if (!ReadFileBytes(path, &text, error)) return false;
  return CalibrationUncertaintyFromJson(text, path, calibration, loaded, error);
}

}  // namespace gravcal
