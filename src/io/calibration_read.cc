// Reading a calibration JSON: every key checked and named, and the checks of
// the models it holds. Writing is in calibration_write.cc.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <utility>

#include "gravcal/core/imu_model.h"
#include "gravcal/io/calibration_io.h"
#include "gravcal/io/files.h"
#include "gravcal/io/log_reader.h"
#include "io/json_helpers.h"
#include "io/thermal_json.h"
#include "util/error.h"
#include "util/numbers.h"

namespace gravcal {
namespace {

using nlohmann::json;

// Reading: every check names the key by its dotted path.
class JsonReader {
 public:
  JsonReader(std::string name, std::string* error) : name_(std::move(name)), error_(error) {}

  bool Fail(const std::string& key, const std::string& what) {
    *error_ = name_ + ": key '" + key + "': " + what;
    return false;
  }
  // A number; `allow_null` reads null as NaN.
  bool Number(const json& j, const std::string& key, bool allow_null, double* v) {
    if (allow_null && j.is_null()) {
      *v = NAN;
      return true;
    }
    if (!j.is_number())
      return Fail(key, allow_null ? "must be a number or null" : "must be a number");
    *v = j.get<double>();
    return true;
  }
  bool Vector(const json& parent, const std::string& field, const std::string& key,
              Eigen::Vector3d* v) {
    if (!parent.contains(field)) return Fail(key, "is missing");
    const json& j = parent[field];
    if (!j.is_array() || j.size() != 3) return Fail(key, "must be an array of 3 numbers");
    for (int i = 0; i < 3; ++i) {
      if (!j[i].is_number()) return Fail(key, "must be an array of 3 numbers");
      (*v)(i) = j[i].get<double>();
    }
    return true;
  }
  bool Matrix(const json& parent, const std::string& field, const std::string& key,
              Eigen::Matrix3d* m) {
    if (!parent.contains(field)) return Fail(key, "is missing");
    const json& j = parent[field];
    const char* what = "must be a 3x3 array of numbers";
    if (!j.is_array() || j.size() != 3) return Fail(key, what);
    for (int r = 0; r < 3; ++r) {
      if (!j[r].is_array() || j[r].size() != 3) return Fail(key, what);
      for (int c = 0; c < 3; ++c) {
        if (!j[r][c].is_number()) return Fail(key, what);
        (*m)(r, c) = j[r][c].get<double>();
      }
    }
    return true;
  }
  bool Object(const json& parent, const std::string& field, const std::string& key) {
    if (!parent.contains(field)) return Fail(key, "is missing");
    if (!parent[field].is_object()) return Fail(key, "must be an object");
    return true;
  }

 private:
  std::string name_;
  std::string* error_;
};

// True when `r` is a rotation (orthonormal, det +1); else sets `why`.
bool CheckRotation(const Eigen::Matrix3d& r, std::string* why) {
  if (!r.allFinite()) return internal::SetError(why, "is not finite");
  const double off = (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!(off <= kCalibrationRelativeTolerance)) {
    return internal::SetError(why, "is not a rotation: R^T R differs from I by " +
                                       internal::ExactNumber(off) + " (at most " +
                                       internal::ExactNumber(kCalibrationRelativeTolerance) + ")");
  }
  const double det = r.determinant();
  if (!(det > 0.0)) {
    return internal::SetError(why,
                              "is a reflection (det = " + internal::ExactNumber(det) + ", not +1)");
  }
  return true;
}

// True when `u` is upper triangular with a positive diagonal; else sets
// `why`.
bool CheckUpperTriangular(const Eigen::Matrix3d& u, std::string* why) {
  if (!u.allFinite()) return internal::SetError(why, "is not finite");
  const double scale = u.cwiseAbs().maxCoeff();
  const double lower = std::max({std::abs(u(1, 0)), std::abs(u(2, 0)), std::abs(u(2, 1))});
  if (!(lower <= kCalibrationRelativeTolerance * scale)) {
    return internal::SetError(why, "is not upper triangular (an entry below the diagonal is " +
                                       internal::ExactNumber(lower) + ")");
  }
  if (!(u.diagonal().minCoeff() > 0.0)) {
    return internal::SetError(
        why, "has a diagonal entry <= 0 (" + internal::ExactNumber(u.diagonal().minCoeff()) + ")");
  }
  return true;
}

// True when `m` has the zeros its model claims (relative to its largest
// entry): none off the diagonal (`diagonal`), else none below it; else sets
// `why`, naming the entry.
bool CheckClaimedZeros(const Eigen::Matrix3d& m, bool diagonal, std::string* why) {
  const double scale = m.cwiseAbs().maxCoeff();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      if (r == c || (!diagonal && c > r)) continue;
      if (!(std::abs(m(r, c)) <= kCalibrationRelativeTolerance * scale)) {
        return internal::SetError(why, "has (" + std::to_string(r) + "," + std::to_string(c) +
                                           ") = " + internal::ExactNumber(m(r, c)) +
                                           (diagonal ? " off" : " below") + " the diagonal");
      }
    }
  }
  return true;
}

// |a - b| / |b| in the Frobenius norm (|a - b| when b is 0).
double RelativeDifference(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  const double norm = b.norm();
  return (a - b).norm() / (norm > 0.0 ? norm : 1.0);
}

// The accelerometer: accel.upper and accel.rotation are authoritative and
// accel.matrix must be their product; without them accel.matrix is.
bool ReadAccel(const json& j, JsonReader* r, AccelModel* model) {
  if (!r->Object(j, "accel", "accel")) return false;
  const json& a = j["accel"];
  Eigen::Matrix3d m;
  Eigen::Vector3d b;
  if (!r->Vector(a, "bias", "accel.bias", &b) || !r->Matrix(a, "matrix", "accel.matrix", &m)) {
    return false;
  }
  AccelParameterization p = AccelParameterization::kAffine;
  if (a.contains("model")) {
    if (!a["model"].is_string() || !FromString(a["model"].get<std::string>(), &p)) {
      return r->Fail("accel.model", "must be one of the accelerometer parameterisations");
    }
  }
  std::string why;
  if (!b.allFinite()) return r->Fail("accel.bias", "is not finite");
  if (!m.allFinite()) return r->Fail("accel.matrix", "is not finite");
  if (a.contains("upper") || a.contains("rotation")) {
    Eigen::Matrix3d upper, rotation;
    if (!r->Matrix(a, "upper", "accel.upper", &upper) ||
        !r->Matrix(a, "rotation", "accel.rotation", &rotation)) {
      return false;
    }
    if (!CheckRotation(rotation, &why)) return r->Fail("accel.rotation", why);
    if (!CheckUpperTriangular(upper, &why)) return r->Fail("accel.upper", why);
    const Eigen::Matrix3d product = rotation * upper;
    if (!product.allFinite()) return r->Fail("accel.upper", "times accel.rotation is not finite");
    const double difference = RelativeDifference(m, product);
    if (!(difference <= kCalibrationRelativeTolerance)) {
      return r->Fail("accel.matrix",
                     "disagrees with key 'accel.rotation' * 'accel.upper' (relative difference " +
                         internal::ExactNumber(difference) + ", at most " +
                         internal::ExactNumber(kCalibrationRelativeTolerance) +
                         "); upper and rotation are authoritative, matrix must be their product");
    }
    model->parameterization = p;
    model->bias = b;
    model->upper = upper;
    model->rotation = rotation;
  } else {
    if (!CheckSensorMatrix(m, &why)) return r->Fail("accel.matrix", why);
    if (!AccelModel::FromMatrix(b, m, p, model)) {
      return r->Fail("accel.matrix", "has no QR decomposition with a positive diagonal");
    }
  }
  return true;
}

bool ReadGyro(const json& j, JsonReader* r, ImuCorrector* c) {
  if (!j.contains("gyro")) return true;
  if (!r->Object(j, "gyro", "gyro")) return false;
  if (!r->Vector(j["gyro"], "bias", "gyro.bias", &c->gyro.bias) ||
      !r->Matrix(j["gyro"], "matrix", "gyro.matrix", &c->gyro.matrix)) {
    return false;
  }
  c->has_gyro = true;
  // gravcal writes no gyro.model; a file that states one is held to it.
  if (j["gyro"].contains("model")) {
    const json& m = j["gyro"]["model"];
    GyroParameterization p;
    if (!m.is_string() || !FromString(m.get<std::string>(), &p) ||
        p == GyroParameterization::kNone) {
      return r->Fail("gyro.model", "must be one of bias, scale, full");
    }
    const Eigen::Matrix3d& g = c->gyro.matrix;
    std::string why;
    if (p != GyroParameterization::kFull && !CheckClaimedZeros(g, true, &why)) {
      return r->Fail("gyro.matrix",
                     why + ", but key 'gyro.model' is '" + ToString(p) + "' (a diagonal matrix)");
    }
    if (p == GyroParameterization::kBias &&
        !(g.diagonal().maxCoeff() - g.diagonal().minCoeff() <=
          kCalibrationRelativeTolerance * g.diagonal().cwiseAbs().maxCoeff())) {
      return r->Fail("gyro.matrix",
                     "has unequal diagonal entries, but key 'gyro.model' is 'bias' (one common "
                     "scale, M_g = s I)");
    }
  }
  return true;
}

// effects.accel_misalignment.value repeats accel.upper's (0,1), (0,2), (1,2).
bool CheckMisalignment(const json& values, const std::string& key, JsonReader* r,
                       const AccelModel& accel) {
  if (values.size() != 3) return r->Fail(key + ".value", "must have 3 numbers");
  const Eigen::Matrix3d& u = accel.upper;
  const double in_upper[3] = {u(0, 1), u(0, 2), u(1, 2)};
  const double scale = u.cwiseAbs().maxCoeff();
  for (int i = 0; i < 3; ++i) {
    double v = 0.0;
    if (!r->Number(values[i], key + ".value", false, &v)) return false;
    if (!(std::abs(v - in_upper[i]) <= kCalibrationRelativeTolerance * scale)) {
      return r->Fail(key + ".value", "[" + std::to_string(i) + "] = " + internal::ExactNumber(v) +
                                         " disagrees with key 'accel.upper' (" +
                                         internal::ExactNumber(in_upper[i]) +
                                         "), which is authoritative");
    }
  }
  return true;
}

// effects.<name>.value into the parameter the name stands for.
bool ReadEffect(const json& entry, Effect effect, const std::string& key, JsonReader* r,
                LoadedCalibration* out) {
  if (!entry.is_object()) return r->Fail(key, "must be an object");
  if (!entry.contains("value") || !entry["value"].is_array()) {
    return r->Fail(key + ".value", "must be an array of numbers");
  }
  const json& values = entry["value"];
  const int n = Info(effect).num_parameters;
  if (Info(effect).form == EffectForm::kInUpper) {  // lives in accel.upper
    return CheckMisalignment(values, key, r, out->corrector.accel);
  }
  if (static_cast<int>(values.size()) != n) {
    return r->Fail(key + ".value", "must have " + std::to_string(n) + " numbers");
  }
  std::vector<double> v(n);
  for (int i = 0; i < n; ++i) {
    if (!r->Number(values[i], key + ".value", true, &v[i])) return false;
    if (!std::isfinite(v[i])) {
      out->undetermined.push_back(key + "." + Info(effect).parameter_names[i]);
      v[i] = 0.0;
    }
  }
  out->corrector.effects.SetValues(effect, v);
  if (Info(effect).sensor == EffectSensor::kGyroscope && !out->corrector.has_gyro) {
    return r->Fail(key, "is a gyroscope effect but the file has no 'gyro' section");
  }
  out->corrector.active_effects.push_back(effect);
  return true;
}

bool ReadEffects(const json& j, JsonReader* r, LoadedCalibration* out) {
  if (!j.contains("effects")) return true;
  if (!r->Object(j, "effects", "effects")) return false;
  const json& e = j["effects"];
  EffectParameters& p = out->corrector.effects;
  if (!e.contains("reference_time")) return r->Fail("effects.reference_time", "is missing");
  if (!e.contains("reference_temperature")) {
    return r->Fail("effects.reference_temperature", "is missing");
  }
  if (!r->Number(e["reference_time"], "effects.reference_time", false, &p.reference_time) ||
      !r->Number(e["reference_temperature"], "effects.reference_temperature", true,
                 &p.reference_temperature)) {
    return false;
  }
  for (auto it = e.begin(); it != e.end(); ++it) {
    if (it.key() == "reference_time" || it.key() == "reference_temperature") continue;
    Effect effect;
    if (!FromString(it.key(), &effect)) {
      return r->Fail("effects." + it.key(), "is not an effect of the catalogue");
    }
    if (!ReadEffect(it.value(), effect, "effects." + it.key(), r, out)) return false;
  }
  if (out->corrector.RequiresTemperature() && !std::isfinite(p.reference_temperature)) {
    return r->Fail("effects.reference_temperature",
                   "must be a number when a temperature effect is present");
  }
  if (!std::isfinite(p.reference_temperature)) p.reference_temperature = 0.0;
  return true;
}

bool ReadPositions(const json& j, JsonReader* r, std::vector<RecordedPosition>* positions) {
  if (!j.contains("positions")) return true;
  if (!j["positions"].is_array()) return r->Fail("positions", "must be an array");
  for (size_t k = 0; k < j["positions"].size(); ++k) {
    const json& p = j["positions"][k];
    const std::string key = "positions[" + std::to_string(k) + "]";
    if (!p.is_object()) return r->Fail(key, "must be an object");
    RecordedPosition out;
    double t_begin = 0.0, t_end = 0.0;
    if (!r->Vector(p, "raw_mean", key + ".raw_mean", &out.raw_mean)) return false;
    for (const char* field : {"t_begin", "t_end"}) {
      if (!p.contains(field)) return r->Fail(key + "." + field, "is missing");
    }
    if (!r->Number(p["t_begin"], key + ".t_begin", false, &t_begin) ||
        !r->Number(p["t_end"], key + ".t_end", false, &t_end)) {
      return false;
    }
    out.time = 0.5 * (t_begin + t_end);
    if (p.contains("temperature") &&
        !r->Number(p["temperature"], key + ".temperature", true, &out.temperature)) {
      return false;
    }
    positions->push_back(out);
  }
  return true;
}

bool ReadProvenance(const json& j, JsonReader* r, CalibrationProvenance* provenance) {
  if (!j.contains("provenance")) return true;
  if (!r->Object(j, "provenance", "provenance")) return false;
  const json& p = j["provenance"];
  const std::pair<const char*, std::string*> fields[] = {
      {"log_file", &provenance->log_file},
      {"log_hash", &provenance->log_hash},
      {"gravcal_version", &provenance->gravcal_version}};
  for (const auto& [field, value] : fields) {
    if (!p.contains(field)) continue;
    if (!p[field].is_string())
      return r->Fail(std::string("provenance.") + field, "must be a string");
    *value = p[field].get<std::string>();
  }
  return true;
}

}  // namespace

bool CalibrationFromJson(const std::string& text, const std::string& name,
                         LoadedCalibration* calibration, std::string* error) {
  json j;
  try {
    j = json::parse(text);
  } catch (const json::exception& e) {
    // parse_error, and out_of_range for a number beyond double (found by
    // fuzz/fuzz_calibration_json: "1e999999" aborted gravcal apply).
    *error = name + ": not valid JSON (" + e.what() + ")";
    return false;
  }
  if (const std::string twice = internal::DuplicateJsonKey(text); !twice.empty()) {
    *error = name + ": key '" + twice + "' appears twice (a key may be set once)";
    return false;
  }
  JsonReader r(name, error);
  if (!j.is_object()) return r.Fail("accel", "is missing (the file is not a JSON object)");
  LoadedCalibration out;
  if (!ReadAccel(j, &r, &out.corrector.accel) || !ReadGyro(j, &r, &out.corrector) ||
      !ReadEffects(j, &r, &out) || !ReadPositions(j, &r, &out.positions) ||
      !ReadProvenance(j, &r, &out.provenance)) {
    return false;
  }
  if (j.contains("gravity")) {
    if (!r.Object(j, "gravity", "gravity")) return false;
    if (!j["gravity"].contains("value")) return r.Fail("gravity.value", "is missing");
    if (!r.Number(j["gravity"]["value"], "gravity.value", false, &out.gravity)) return false;
    if (!(out.gravity > 0.0)) return r.Fail("gravity.value", "must be positive");
  }
  if (j.contains("thermal") &&
      !internal::ThermalFromJson(j["thermal"], name, &out.corrector.thermal, error)) {
    return false;
  }
  if (out.corrector.thermal.gyro.active() && !out.corrector.has_gyro) {
    return r.Fail("thermal.gyro", "is a gyroscope thermal model but there is no gyroscope model");
  }
  if (j.contains("method") && j["method"].is_string()) out.method = j["method"].get<std::string>();
  if (!CheckCalibrationModels(out, name, error)) return false;
  *calibration = std::move(out);
  return true;
}

bool CheckSensorMatrix(const Eigen::Matrix3d& m, std::string* why) {
  using internal::ExactNumber;
  using internal::SetError;
  if (!m.allFinite()) return SetError(why, "is not finite");
  // m / max|m_ij|: its determinant and singular values neither overflow
  // (1e300 entries) nor underflow (det(1e-120 I) = 1e-360 is 0 in double).
  const double scale = m.cwiseAbs().maxCoeff();
  if (!(scale > 0.0)) return SetError(why, "is all zeros");
  const double det = (m / scale).determinant();
  if (det < 0.0) return SetError(why, "is a reflection (det < 0: the axes would be mirrored)");
  const Eigen::Vector3d s = Eigen::JacobiSVD<Eigen::Matrix3d>(m / scale).singularValues();
  const double largest = s(0) * scale, smallest = s(2) * scale;
  if (!(largest <= kCalibrationMaxSingularValue) || !(smallest >= kCalibrationMinSingularValue)) {
    return SetError(why, "has singular values from " + ExactNumber(smallest) + " to " +
                             ExactNumber(largest) + ", outside [" +
                             ExactNumber(kCalibrationMinSingularValue) + ", " +
                             ExactNumber(kCalibrationMaxSingularValue) +
                             "] (singular, or beyond double arithmetic)");
  }
  const double condition = s(0) / s(2);
  if (!(condition <= kCalibrationMaxConditionNumber)) {
    return SetError(why, "is ill-conditioned: condition number " + ExactNumber(condition) + " > " +
                             ExactNumber(kCalibrationMaxConditionNumber));
  }
  if (!(det > 0.0)) return SetError(why, "is singular");
  return true;
}

bool CheckCalibrationModels(const LoadedCalibration& c, const std::string& name,
                            std::string* error) {
  auto fail = [&](const std::string& key, const std::string& what) {
    return internal::SetError(error, name + ": key '" + key + "': " + what);
  };
  std::string why;
  const AccelModel& accel = c.corrector.accel;
  if (!accel.bias.allFinite()) return fail("accel.bias", "is not finite");
  if (!CheckRotation(accel.rotation, &why)) return fail("accel.rotation", why);
  if (!CheckUpperTriangular(accel.upper, &why)) return fail("accel.upper", why);
  if (!CheckSensorMatrix(accel.matrix(), &why)) return fail("accel.matrix", why);
  // scale and scale_misalignment hold R = I: the matrix is upper triangular
  // (diagonal for scale), as the model says.
  const AccelParameterization p = accel.parameterization;
  if (p != AccelParameterization::kAffine &&
      !CheckClaimedZeros(accel.matrix(), p == AccelParameterization::kScale, &why)) {
    return fail("accel.matrix",
                why + ", but key 'accel.model' is '" + ToString(p) + "' (" +
                    (p == AccelParameterization::kScale ? "a diagonal matrix)"
                                                        : "R = I, an upper-triangular matrix)"));
  }
  if (c.corrector.has_gyro) {
    if (!c.corrector.gyro.bias.allFinite()) return fail("gyro.bias", "is not finite");
    if (!CheckSensorMatrix(c.corrector.gyro.matrix, &why)) return fail("gyro.matrix", why);
  }
  const EffectParameters& e = c.corrector.effects;
  for (const EffectInfo& info : EffectCatalogue()) {
    const std::vector<double> v = e.Values(info.effect);
    if (!std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); })) {
      return fail(std::string("effects.") + info.name, "is not finite");
    }
  }
  if (!std::isfinite(e.reference_time)) return fail("effects.reference_time", "is not finite");
  if (!std::isfinite(e.reference_temperature)) {
    return fail("effects.reference_temperature", "is not finite");
  }
  if (!(c.gravity > 0.0) || !std::isfinite(c.gravity)) {
    return fail("gravity.value", "must be positive and finite");
  }
  return true;
}

bool ReadCalibrationJson(const std::string& path, LoadedCalibration* calibration,
                         std::string* error) {
  std::string text;
  if (!ReadFileBytes(path, &text, error)) return false;
  return CalibrationFromJson(text, path, calibration, error);
}

}  // namespace gravcal
