#include "gravcal/workflows/acceptance.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cstdio>

#include "core/enum_names.h"
#include "gravcal/estimation/calibration_comparison.h"
#include "gravcal/io/files.h"
#include "workflows/acceptance_internal.h"

namespace gravcal {

namespace {
const internal::EnumName<UncertaintySource> kUncertaintySources[] = {
    {UncertaintySource::kPlacement, "placement"},
    {UncertaintySource::kNoise, "noise"},
    {UncertaintySource::kPoseScatter, "pose scatter"},
    {UncertaintySource::kGravity, "gravity"}};
}  // namespace

GRAVCAL_ENUM_STRINGS(UncertaintySource, kUncertaintySources)

namespace internal {

std::string LimitNumber(double v) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.6g", v);
  return buffer;
}

}  // namespace internal

namespace {

using internal::LimitNumber;

bool KeyError(const std::string& name, const std::string& key, const std::string& what,
              std::string* error) {
  *error = name + ": key '" + key + "': " + what;
  return false;
}

bool ReadNumber(const YAML::Node& node, const std::string& name, const std::string& key,
                double* value, std::string* error) {
  try {
    *value = node.as<double>();
  } catch (const YAML::Exception&) {
    return KeyError(name, key, "must be a number", error);
  }
  if (!std::isfinite(*value)) return KeyError(name, key, "must be finite", error);
  return true;
}

// False with *error naming the first key given twice in any map of `node`
// (yaml-cpp keeps both, so the later one would silently win).
bool NoKeyTwice(const YAML::Node& node, const std::string& name, const std::string& prefix,
                std::string* error) {
  if (!node.IsMap()) return true;
  std::vector<std::string> seen;
  for (const auto& entry : node) {
    const std::string key = prefix + entry.first.as<std::string>();
    if (std::find(seen.begin(), seen.end(), key) != seen.end()) {
      return KeyError(name, key, "given twice (a limit may be set once)", error);
    }
    seen.push_back(key);
    if (!NoKeyTwice(entry.second, name, key + ".", error)) return false;
  }
  return true;
}

// A noise-density limit: a number (the largest axis' maximum) or a map
// with min and/or max; each positive, `unit` named in the messages.
bool ReadDensityLimit(const YAML::Node& node, const std::string& name, const std::string& key,
                      const std::string& unit, double* min, double* max, std::string* error) {
  if (node.IsMap()) {
    if (node.size() == 0) {
      return KeyError(name, key, "must be a number or a map with min and/or max (" + unit + ")",
                      error);
    }
    for (const auto& field : node) {
      const std::string f = field.first.as<std::string>();
      double* target = f == "min" ? min : f == "max" ? max : nullptr;
      if (target == nullptr) {
        return KeyError(name, key + "." + f, "unknown (min, max; " + unit + ")", error);
      }
      if (!ReadNumber(field.second, name, key + "." + f, target, error)) return false;
      if (!(*target > 0.0)) {
        return KeyError(name, key + "." + f, "must be positive (" + unit + ")", error);
      }
    }
    if (*min > *max) return KeyError(name, key, "min is above max", error);
    return true;
  }
  if (!ReadNumber(node, name, key, max, error)) return false;
  if (!(*max > 0.0)) return KeyError(name, key, "must be positive (" + unit + ")", error);
  return true;
}

// The median over the holds, per axis, of the white-noise density N_i =
// sigma_i / sqrt(f_s) from each hold's per-sample standard deviation
// sigma = per_sample(hold) (SI) and its rate f_s = (samples - 1) / T; NaN
// on an axis no hold measures.
template <typename PerSample>
Eigen::Vector3d HoldNoiseDensity(const Calibration& c, PerSample per_sample) {
  std::vector<double> per_axis[3];
  for (const PositionReport& p : c.positions) {
    const double duration = p.position.t_end - p.position.t_begin;
    if (p.position.sample_count < 2 || !(duration > 0.0)) continue;
    const Eigen::Vector3d sigma = per_sample(p);
    if (!sigma.allFinite() || !(sigma.maxCoeff() > 0.0)) continue;
    const double rate = (p.position.sample_count - 1) / duration;
    for (int i = 0; i < 3; ++i) per_axis[i].push_back(sigma(i) / std::sqrt(rate));
  }
  Eigen::Vector3d out = Eigen::Vector3d::Constant(NAN);
  for (int i = 0; i < 3; ++i) {
    std::vector<double>& v = per_axis[i];
    if (v.empty()) continue;
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    double median = v[v.size() / 2];
    if (v.size() % 2 == 0) {
      median = 0.5 * (median + *std::max_element(v.begin(), v.begin() + v.size() / 2));
    }
    out(i) = median;
  }
  return out;
}

// Whether `name` is a parameter name compare knows (model: accel. or gyro.
// followed by bias_x, u_xy, m_xy or rot_x; intrinsic: accel.sensitivity_x,
// accel.nonorth_xy, xz, yz); a limit on any other name is a typo.
bool KnownParameterName(const std::string& name) {
  const auto axis = [](char c) { return c == 'x' || c == 'y' || c == 'z'; };
  std::string rest;
  if (name.rfind("accel.", 0) == 0) {
    rest = name.substr(6);
    if (rest.size() == 13 && rest.rfind("sensitivity_", 0) == 0 && axis(rest[12])) return true;
    if (rest == "nonorth_xy" || rest == "nonorth_xz" || rest == "nonorth_yz") return true;
  } else if (name.rfind("gyro.", 0) == 0) {
    rest = name.substr(5);
  } else {
    return false;
  }
  if (rest.size() == 6 && rest.rfind("bias_", 0) == 0) return axis(rest[5]);
  if (rest.size() == 5 && rest.rfind("rot_", 0) == 0) return axis(rest[4]);
  return rest.size() == 4 && (rest[0] == 'u' || rest[0] == 'm') && rest[1] == '_' &&
         axis(rest[2]) && axis(rest[3]);
}

// The value, standard deviation and determined flag of every parameter the
// calibration has, in model and intrinsic names.
struct NamedValues {
  std::vector<std::string> names;
  std::vector<double> values, stds;
  std::vector<bool> determined;
};

NamedValues CollectValues(const Calibration& c) {
  NamedValues out;
  for (ComparisonSpace space : {ComparisonSpace::kModel, ComparisonSpace::kIntrinsic}) {
    ParameterVector p;
    std::string error;
    if (!CalibrationParameters(c, space, &p, &error)) continue;
    for (size_t i = 0; i < p.names.size(); ++i) {
      if (std::find(out.names.begin(), out.names.end(), p.names[i]) != out.names.end()) continue;
      out.names.push_back(p.names[i]);
      out.values.push_back(p.values(i));
      out.stds.push_back(p.determined[i] ? std::sqrt(std::max(0.0, p.covariance(i, i))) : NAN);
      out.determined.push_back(p.determined[i]);
    }
  }
  return out;
}

LimitCheck Range(const std::string& name, double measured, double min, double max) {
  LimitCheck c;
  c.name = name;
  c.measured = measured;
  c.min = min;
  c.max = max;
  c.pass = std::isfinite(measured) && measured >= min && measured <= max;
  if (!std::isfinite(measured)) {
    c.why = "not determined";
  } else if (measured < min) {
    c.why = LimitNumber(measured) + " below min " + LimitNumber(min);
  } else if (measured > max) {
    c.why = LimitNumber(measured) + " above max " + LimitNumber(max);
  }
  return c;
}

// The check of a measured noise density (largest axis) against [min, max].
void CheckDensity(const std::string& name, const Eigen::Vector3d& density, double min, double max,
                  const std::string& not_measured, AcceptanceResult* result) {
  if (!std::isfinite(min) && !std::isfinite(max)) return;
  result->checks.push_back(Range(name, density.allFinite() ? density.maxCoeff() : NAN,
                                 std::isfinite(min) ? min : 0.0, max));
  if (!density.allFinite()) result->checks.back().why = not_measured;
}

// The unit of a parameter (accelerometer raw unit "raw").
std::string UnitOf(const std::string& name) {
  if (name.find(".bias_") != std::string::npos) return "raw";
  if (name.find(".sensitivity_") != std::string::npos) return "raw per m/s^2";
  if (name.find(".nonorth_") != std::string::npos || name.find(".rot_") != std::string::npos) {
    return "rad";
  }
  if (name.rfind("gyro.", 0) == 0) return "rad/s per raw";
  return "m/s^2 per raw";
}

// Whether a gravity error scales the parameter (matrix entries, sensitivities).
bool ScalesWithGravity(const std::string& name) {
  return name.find(".u_") != std::string::npos || (name.rfind("accel.m_", 0) == 0) ||
         name.find(".sensitivity_") != std::string::npos;
}

double GravityStd(const std::string& source, double given) {
  if (given > 0.0) return given;
  if (source == "given") return 1e-4;
  if (source.rfind("normal gravity", 0) == 0) return 5e-3;
  return 0.03;
}

}  // namespace

bool AcceptanceLimitsFromYaml(const std::string& text, const std::string& name,
                              AcceptanceLimits* limits, std::string* error) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    *error = name + ": line " + std::to_string(e.mark.line + 1) + ": not valid YAML";
    return false;
  }
  if (!root.IsMap()) {
    *error = name +
             ": must be a map with 'parameters', 'residual_rms', 'gravity_std', "
             "'accel_noise_density', 'gyro_noise_density', 'temperature', "
             "'temperature_sensitivity'";
    return false;
  }
  if (!NoKeyTwice(root, name, "", error)) return false;
  AcceptanceLimits out;
  for (const auto& entry : root) {
    const std::string key = entry.first.as<std::string>();
    if (key == "residual_rms") {
      if (!ReadNumber(entry.second, name, key, &out.max_residual_rms, error)) return false;
    } else if (key == "gravity_std") {
      if (!ReadNumber(entry.second, name, key, &out.gravity_std, error)) return false;
      if (!(out.gravity_std > 0.0)) return KeyError(name, key, "must be positive", error);
    } else if (key == "accel_noise_density") {
      if (!ReadDensityLimit(entry.second, name, key, "m/s^2/sqrt(Hz)", &out.min_accel_noise_density,
                            &out.max_accel_noise_density, error)) {
        return false;
      }
    } else if (key == "gyro_noise_density") {
      if (!ReadDensityLimit(entry.second, name, key, "rad/s/sqrt(Hz)", &out.min_gyro_noise_density,
                            &out.max_gyro_noise_density, error)) {
        return false;
      }
    } else if (key == "temperature") {
      if (!entry.second.IsMap() || entry.second.size() == 0) {
        return KeyError(name, key, "must be a map with min and/or max (degC)", error);
      }
      for (const auto& field : entry.second) {
        const std::string f = field.first.as<std::string>();
        double* target = f == "min"   ? &out.min_temperature
                         : f == "max" ? &out.max_temperature
                                      : nullptr;
        if (target == nullptr) return KeyError(name, key + "." + f, "unknown (min, max)", error);
        if (!ReadNumber(field.second, name, key + "." + f, target, error)) return false;
      }
      if (out.min_temperature > out.max_temperature) {
        return KeyError(name, key, "min is above max", error);
      }
    } else if (key == "temperature_sensitivity") {
      if (!entry.second.IsMap() || entry.second.size() == 0) {
        return KeyError(name, key,
                        "must be a map with accel_bias (mg/K) and/or gyro_bias (deg/s/K)", error);
      }
      for (const auto& field : entry.second) {
        const std::string f = field.first.as<std::string>();
        double* target = f == "accel_bias"  ? &out.max_accel_bias_tempco
                         : f == "gyro_bias" ? &out.max_gyro_bias_tempco
                                            : nullptr;
        if (target == nullptr) {
          return KeyError(name, key + "." + f, "unknown (accel_bias, gyro_bias)", error);
        }
        if (!ReadNumber(field.second, name, key + "." + f, target, error)) return false;
        if (!(*target > 0.0)) return KeyError(name, key + "." + f, "must be positive", error);
      }
    } else if (key == "parameters") {
      if (!entry.second.IsMap()) return KeyError(name, key, "must be a map of parameters", error);
      for (const auto& p : entry.second) {
        ParameterLimit limit;
        limit.name = p.first.as<std::string>();
        const std::string base = "parameters." + limit.name;
        if (!KnownParameterName(limit.name)) {
          return KeyError(name, base,
                          "not a parameter name (accel.bias_x, accel.u_xy, accel.m_xy, "
                          "accel.rot_x, accel.sensitivity_x, accel.nonorth_xy, gyro.bias_x, "
                          "gyro.m_xy)",
                          error);
        }
        if (!p.second.IsMap() || p.second.size() == 0) {
          return KeyError(name, base, "must be a map with min, max and/or max_std", error);
        }
        for (const auto& field : p.second) {
          const std::string f = field.first.as<std::string>();
          double* target = f == "min"       ? &limit.min
                           : f == "max"     ? &limit.max
                           : f == "max_std" ? &limit.max_std
                                            : nullptr;
          if (target == nullptr) {
            return KeyError(name, base + "." + f, "unknown (min, max, max_std)", error);
          }
          if (!ReadNumber(field.second, name, base + "." + f, target, error)) return false;
        }
        if (limit.min > limit.max) return KeyError(name, base, "min is above max", error);
        if (!(limit.max_std > 0.0))
          return KeyError(name, base + ".max_std", "must be positive", error);
        out.parameters.push_back(limit);
      }
    } else {
      return KeyError(name, key,
                      "unknown (parameters, residual_rms, gravity_std, accel_noise_density, "
                      "gyro_noise_density, temperature, temperature_sensitivity)",
                      error);
    }
  }
  *limits = out;
  return true;
}

Eigen::Vector3d MeasuredAccelNoiseDensity(const Calibration& c) {
  const Eigen::Matrix3d m = c.accel.model.matrix();
  return HoldNoiseDensity(c, [&m](const PositionReport& p) -> Eigen::Vector3d {
    const Eigen::Matrix3d cov =
        m * p.raw_std.array().square().matrix().asDiagonal() * m.transpose();
    return cov.diagonal().cwiseMax(0.0).cwiseSqrt();
  });
}

Eigen::Vector3d MeasuredGyroNoiseDensity(const Calibration& c) {
  return HoldNoiseDensity(c, [](const PositionReport& p) { return p.gyro_std; });
}

bool ReadAcceptanceLimits(const std::string& path, AcceptanceLimits* limits, std::string* error) {
  std::string text;
  if (!ReadFileBytes(path, &text, error)) return false;
  return AcceptanceLimitsFromYaml(text, path, limits, error);
}

void CheckAcceptance(const Calibration& calibration, const AcceptanceLimits& limits,
                     AcceptanceResult* result) {
  *result = AcceptanceResult();
  if (!calibration.success) {
    LimitCheck c;
    c.name = "calibration";
    c.why = "failed: " + calibration.message;
    result->checks.push_back(c);
  }
  const NamedValues values = CollectValues(calibration);
  for (const ParameterLimit& limit : limits.parameters) {
    const auto it = std::find(values.names.begin(), values.names.end(), limit.name);
    if (it == values.names.end()) {
      LimitCheck c;
      c.name = limit.name;
      c.why = "not estimated by this calibration (or no covariance)";
      result->checks.push_back(c);
      continue;
    }
    const size_t i = it - values.names.begin();
    if (std::isfinite(limit.min) || std::isfinite(limit.max)) {
      result->checks.push_back(
          Range(limit.name + " value", values.values[i], limit.min, limit.max));
    }
    if (std::isfinite(limit.max_std)) {
      result->checks.push_back(Range(limit.name + " std", values.stds[i], 0.0, limit.max_std));
    }
  }
  if (std::isfinite(limits.max_residual_rms)) {
    result->checks.push_back(
        Range("residual_rms", calibration.residual_refined.rms, 0.0, limits.max_residual_rms));
  }
  CheckDensity("accel_noise_density", MeasuredAccelNoiseDensity(calibration),
               limits.min_accel_noise_density, limits.max_accel_noise_density,
               "not measured (no hold with samples)", result);
  CheckDensity("gyro_noise_density", MeasuredGyroNoiseDensity(calibration),
               limits.min_gyro_noise_density, limits.max_gyro_noise_density,
               "not measured (no hold with gyroscope samples in a known unit: the log has no "
               "gyroscope, or the calibration no gyroscope model and the config no "
               "gyro_nominal_scale)",
               result);
  if (std::isfinite(limits.min_temperature) || std::isfinite(limits.max_temperature)) {
    // The hold farthest outside [min, max] (or the coldest when all inside).
    double coldest = NAN, hottest = NAN;
    for (const PositionReport& p : calibration.positions) {
      const double t = p.position.temperature;
      if (!std::isfinite(t)) continue;
      coldest = std::isfinite(coldest) ? std::min(coldest, t) : t;
      hottest = std::isfinite(hottest) ? std::max(hottest, t) : t;
    }
    if (!std::isfinite(coldest)) {
      LimitCheck c;
      c.name = "temperature";
      c.min = limits.min_temperature;
      c.max = limits.max_temperature;
      c.pass = true;
      c.checked = false;
      c.why = "not checked: the log has no temperature";
      result->checks.push_back(c);
    } else {
      const bool too_hot = hottest > limits.max_temperature;
      result->checks.push_back(Range("temperature", too_hot ? hottest : coldest,
                                     limits.min_temperature, limits.max_temperature));
    }
  }
  const std::pair<ThermalSensor, double> tempcos[] = {
      {ThermalSensor::kAccel, limits.max_accel_bias_tempco},
      {ThermalSensor::kGyro, limits.max_gyro_bias_tempco}};
  for (const auto& [sensor, limit] : tempcos) {
    if (!std::isfinite(limit)) continue;
    const std::string what = std::string("temperature_sensitivity.") + ToString(sensor) + "_bias";
    const double s = ThermalSensitivity(calibration, sensor);
    if (std::isfinite(s)) {
      result->checks.push_back(Range(what, s, 0.0, limit));
      continue;
    }
    LimitCheck c;
    c.name = what;
    c.max = limit;
    c.pass = true;
    c.checked = false;
    c.why = "not checked: the calibration has no thermal model (method thermal)";
    result->checks.push_back(c);
  }
  std::string failed;
  for (const LimitCheck& c : result->checks) {
    if (c.pass) continue;
    result->pass = false;
    failed += (failed.empty() ? "" : "; ") + c.name + " " + c.why;
  }
  size_t unchecked = 0;
  for (const LimitCheck& c : result->checks) unchecked += c.checked ? 0 : 1;
  result->message =
      result->pass
          ? "pass (" + std::to_string(result->checks.size() - unchecked) + " limits" +
                (unchecked > 0 ? ", " + std::to_string(unchecked) + " not checked" : "") + ")"
          : "fail: " + failed;
}

double ThermalSensitivity(const Calibration& calibration, ThermalSensor sensor) {
  const ThermalModel& th = calibration.thermal;
  const bool gyro = sensor == ThermalSensor::kGyro;
  if (!th.active() || (gyro && !calibration.gyro.estimated)) return NAN;
  const ThermalPolynomial& p = th.Sensor(sensor).bias;
  if (!p.active()) return 0.0;
  const Eigen::Matrix3d m = gyro ? calibration.gyro.model.matrix : calibration.accel.model.matrix();
  const double lo =
      std::isfinite(th.min_temperature) ? th.min_temperature : th.reference_temperature;
  const double hi =
      std::isfinite(th.max_temperature) ? th.max_temperature : th.reference_temperature;
  constexpr int kGrid = 64;
  double worst = 0.0;
  for (int g = 0; g <= kGrid; ++g) {
    const double x = lo + (hi - lo) * g / kGrid - th.reference_temperature;
    // d p_i / dx = sum_k k c_ik x^(k-1), raw units per K.
    Eigen::Vector3d slope = Eigen::Vector3d::Zero();
    for (int i = 0; i < 3; ++i) {
      for (int k = p.order; k >= 1; --k) slope(i) = slope(i) * x + k * p.coefficients(i, k - 1);
    }
    worst = std::max(worst, (m * slope).cwiseAbs().maxCoeff());
  }
  return gyro ? worst * 180.0 / M_PI : worst / (9.80665e-3);
}

bool MakeCertificate(const Calibration& c, const CertificateInfo& info,
                     const AcceptanceLimits* limits, Certificate* certificate, std::string* error) {
  if (!c.success) {
    *error = "no certificate for a failed calibration: " + c.message;
    return false;
  }
  Certificate out;
  out.info = info;
  out.gravity = c.gravity;
  out.gravity_source = c.gravity_source;
  out.gravity_std = GravityStd(c.gravity_source, limits != nullptr ? limits->gravity_std : 0.0);
  out.method = c.method;
  out.residual_rms = c.residual_refined.rms;
  out.accel_noise_density = MeasuredAccelNoiseDensity(c);
  out.gyro_noise_density = MeasuredGyroNoiseDensity(c);
  for (const PositionReport& p : c.positions) {
    const double t = p.position.temperature;
    if (!std::isfinite(t)) continue;
    out.temperature_min = std::isfinite(out.temperature_min) ? std::min(out.temperature_min, t) : t;
    out.temperature_max = std::isfinite(out.temperature_max) ? std::max(out.temperature_max, t) : t;
  }
  // The split of the fit variance between noise of the mean and pose scatter.
  double noise = 0.0;
  int poses = 0;
  const Eigen::Matrix3d m = c.accel.model.matrix();
  for (const PositionReport& p : c.positions) {
    const Eigen::Vector3d u = (m * (p.position.raw_mean - c.accel.model.bias)).normalized();
    noise += u.dot(m * p.position.raw_mean_cov * m.transpose() * u);
    ++poses;
  }
  const double scatter = c.accel.pose_variance.absorbed ? c.accel.pose_variance.variance : 0.0;
  const double noise_share =
      poses > 0 && noise + poses * scatter > 0.0 ? noise / (noise + poses * scatter) : 1.0;
  out.notes.push_back(
      "fit variance split between noise and pose scatter in proportion of their "
      "mean per-pose variances (noise share " +
      LimitNumber(noise_share) + ")");
  out.notes.push_back(c.effects.estimates.empty()
                          ? "temperature: not modelled by this calibration (no temperature term "
                            "fitted); not part of the budget"
                          : "temperature: the fitted effect terms are part of the fit variance");
  out.notes.push_back("gravity " + LimitNumber(c.gravity) + " m/s^2 (" + c.gravity_source +
                      "), standard uncertainty " + LimitNumber(out.gravity_std) + " m/s^2");
  const NamedValues values = CollectValues(c);
  if (values.names.empty()) {
    *error = "no certificate: the calibration has no covariance (output_covariance: true)";
    return false;
  }
  for (size_t i = 0; i < values.names.size(); ++i) {
    CertificateEntry e;
    e.name = values.names[i];
    e.unit = UnitOf(e.name);
    e.value = values.values[i];
    if (values.determined[i]) {
      const double fit = values.stds[i];
      const bool placement = e.name.find(".rot_") != std::string::npos;
      if (placement) {
        e.budget.emplace_back(UncertaintySource::kPlacement, fit);
      } else {
        e.budget.emplace_back(UncertaintySource::kNoise, fit * std::sqrt(noise_share));
        e.budget.emplace_back(UncertaintySource::kPoseScatter, fit * std::sqrt(1.0 - noise_share));
      }
      e.budget.emplace_back(
          UncertaintySource::kGravity,
          ScalesWithGravity(e.name) ? std::fabs(e.value) * out.gravity_std / c.gravity : 0.0);
      double sum = 0.0;
      for (const auto& [source, u] : e.budget) sum += u * u;
      e.standard_uncertainty = std::sqrt(sum);
      e.expanded_uncertainty = info.coverage_factor * e.standard_uncertainty;
    }
    out.parameters.push_back(e);
  }
  if (limits != nullptr) {
    out.has_limits = true;
    CheckAcceptance(c, *limits, &out.acceptance);
  }
  *certificate = out;
  return true;
}

}  // namespace gravcal
