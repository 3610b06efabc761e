// The multi-IMU config (io/multi_imu_log.h): configs/multi_imu.yaml.
#include <yaml-cpp/yaml.h>

#include <Eigen/LU>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "core/enum_names.h"
#include "gravcal/core/gravity.h"
#include "gravcal/workflows/multi_imu_log.h"
#include "util/units.h"

namespace gravcal {
namespace {

using internal::kDegToRad;

std::string At(const std::string& name, const YAML::Node& node) {
  std::ostringstream s;
  s << name << ":" << node.Mark().line + 1 << ": ";
  return s.str();
}

bool Number(const std::string& name, const std::string& key, const YAML::Node& node, double* value,
            std::string* error) {
  try {
    *value = node.as<double>();
  } catch (const YAML::Exception&) {
    *error = At(name, node) + "key '" + key + "' must be a number";
    return false;
  }
  if (!std::isfinite(*value)) {
    *error = At(name, node) + "key '" + key + "' must be finite";
    return false;
  }
  return true;
}

bool Text(const std::string& name, const std::string& key, const YAML::Node& node,
          std::string* value, std::string* error) {
  if (!node.IsScalar()) {
    *error = At(name, node) + "key '" + key + "' must be a text value";
    return false;
  }
  *value = node.Scalar();
  return true;
}

// The raw units of accel_units and gyro_units, from their tables.
enum class AccelUnit { kMetresPerSecond2, kG, kCounts };
enum class GyroUnit { kRadiansPerSecond, kDegreesPerSecond, kCounts };
const internal::EnumName<AccelUnit> kAccelUnits[] = {{AccelUnit::kMetresPerSecond2, "m/s^2"},
                                                     {AccelUnit::kMetresPerSecond2, "m/s2"},
                                                     {AccelUnit::kG, "g"},
                                                     {AccelUnit::kCounts, "counts"}};
const internal::EnumName<GyroUnit> kGyroUnits[] = {{GyroUnit::kRadiansPerSecond, "rad/s"},
                                                   {GyroUnit::kDegreesPerSecond, "deg/s"},
                                                   {GyroUnit::kCounts, "counts"}};
GRAVCAL_ENUM_STRINGS(AccelUnit, kAccelUnits)
GRAVCAL_ENUM_STRINGS(GyroUnit, kGyroUnits)

// A unit key's value by its table; false with the line, the key and the
// accepted names.
template <typename Unit>
bool UnitValue(const std::string& name, const std::string& key, const YAML::Node& v, Unit* unit,
               std::string* error) {
  std::string text;
  if (!Text(name, key, v, &text, error)) return false;
  if (ParseName(key, text, unit, error)) return true;
  *error = At(name, v) + *error;
  return false;
}

// The unit keys, at the top level (every IMU's default) or per IMU.
struct Units {
  AccelUnit accel_units = AccelUnit::kMetresPerSecond2;
  GyroUnit gyro_units = GyroUnit::kRadiansPerSecond;
  double counts_per_g = 16384.0, counts_per_dps = 131.0;
  double accel_scale = 0.0, gyro_scale = 0.0;
};

// A unit key into *units; false (no error) when `key` is not one.
bool UnitKey(const std::string& name, const std::string& key, const YAML::Node& v, Units* units,
             bool* ok, std::string* error) {
  if (key == "accel_units") {
    *ok = UnitValue(name, key, v, &units->accel_units, error);
  } else if (key == "gyro_units") {
    *ok = UnitValue(name, key, v, &units->gyro_units, error);
  } else if (key == "accel_counts_per_g") {
    *ok = Number(name, key, v, &units->counts_per_g, error);
  } else if (key == "gyro_counts_per_dps") {
    *ok = Number(name, key, v, &units->counts_per_dps, error);
  } else if (key == "accel_scale") {
    *ok = Number(name, key, v, &units->accel_scale, error);
  } else if (key == "gyro_scale") {
    *ok = Number(name, key, v, &units->gyro_scale, error);
  } else {
    return false;
  }
  return true;
}

// SI per raw unit from the unit keys; false with the reason.
bool Scales(const Units& u, double* accel_scale, double* gyro_scale, std::string* error) {
  if (u.accel_scale > 0.0) {
    *accel_scale = u.accel_scale;
  } else if (u.accel_units == AccelUnit::kMetresPerSecond2) {
    *accel_scale = 1.0;
  } else if (u.accel_units == AccelUnit::kG) {
    *accel_scale = kStandardGravity;
  } else if (u.accel_units == AccelUnit::kCounts && u.counts_per_g > 0.0) {
    *accel_scale = kStandardGravity / u.counts_per_g;
  } else {
    *error = "accel_units counts needs accel_counts_per_g > 0 (or give accel_scale > 0)";
    return false;
  }
  if (u.gyro_scale > 0.0) {
    *gyro_scale = u.gyro_scale;
  } else if (u.gyro_units == GyroUnit::kRadiansPerSecond) {
    *gyro_scale = 1.0;
  } else if (u.gyro_units == GyroUnit::kDegreesPerSecond) {
    *gyro_scale = kDegToRad;
  } else if (u.gyro_units == GyroUnit::kCounts && u.counts_per_dps > 0.0) {
    *gyro_scale = kDegToRad / u.counts_per_dps;
  } else {
    *error = "gyro_units counts needs gyro_counts_per_dps > 0 (or give gyro_scale > 0)";
    return false;
  }
  return true;
}

// One entry of `imus`.
bool ParseImu(const std::string& name, const YAML::Node& node, size_t index, const Units& defaults,
              MultiImuLogSpec* imu, std::string* error) {
  const std::string where = "imus[" + std::to_string(index) + "]: ";
  if (!node.IsMap()) {
    *error = At(name, node) + where + "each IMU is a map with at least 'name'";
    return false;
  }
  Units units = defaults;
  for (const auto& kv : node) {
    const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : "?";
    const YAML::Node& v = kv.second;
    bool ok = true;
    if (key == "name") {
      ok = Text(name, key, v, &imu->name, error);
    } else if (key == "columns") {
      if (!v.IsSequence() || (v.size() != 3 && v.size() != 6)) {
        *error = At(name, v) + where +
                 "'columns' lists 3 (ax ay az) or 6 (ax ay az gx gy gz) column names";
        return false;
      }
      imu->columns.clear();
      for (const YAML::Node& c : v) imu->columns.push_back(c.IsScalar() ? c.Scalar() : "");
    } else if (UnitKey(name, key, v, &units, &ok, error)) {
    } else if (key == "input") {
      ok = Text(name, key, v, &imu->input, error);
    } else if (key == "topic") {
      ok = Text(name, key, v, &imu->topic, error);
    } else if (key == "update_rate") {
      ok = Number(name, key, v, &imu->update_rate, error);
    } else if (key == "rotation") {
      bool shape = v.IsSequence() && v.size() == 3;
      for (size_t r = 0; shape && r < 3; ++r) shape = v[r].IsSequence() && v[r].size() == 3;
      if (!shape) {
        *error = At(name, v) + where + "'rotation' is a 3x3 matrix: [[r00, r01, r02], ...]";
        return false;
      }
      for (int r = 0; r < 3 && ok; ++r) {
        for (int c = 0; c < 3 && ok; ++c)
          ok = Number(name, key, v[r][c], &imu->rotation(r, c), error);
      }
      if (!ok) return false;
      if (!(imu->rotation.transpose() * imu->rotation)
               .isApprox(Eigen::Matrix3d::Identity(), 1e-3) ||
          imu->rotation.determinant() < 0.0) {
        *error = At(name, v) + where + "'rotation' is not a rotation (orthonormal, det +1)";
        return false;
      }
    } else {
      *error = At(name, kv.first) + where + "unknown key '" + key +
               "' (name, columns, accel_units, gyro_units, accel_counts_per_g, "
               "gyro_counts_per_dps, accel_scale, gyro_scale, input, topic, rotation, "
               "update_rate)";
      return false;
    }
    if (!ok) return false;
  }
  if (imu->name.empty()) {
    *error = At(name, node) + where + "'name' is missing";
    return false;
  }
  if (imu->columns.empty()) {
    for (const char* c : {"ax", "ay", "az", "gx", "gy", "gz"}) {
      imu->columns.push_back(imu->input.empty() ? imu->name + "." + c : c);
    }
  }
  std::string why;
  if (!Scales(units, &imu->accel_scale, &imu->gyro_scale, &why)) {
    *error = At(name, node) + where + why;
    return false;
  }
  return true;
}

// A sim_* key into the plate simulator's options; false with the line.
bool SimKey(const std::string& name, const std::string& key, const YAML::Node& v,
            PlateSimulatorOptions* sim, std::string* error) {
  double x = 0.0;
  if (key == "sim_mounting") {
    std::string text;
    if (!Text(name, key, v, &text, error)) return false;
    if (!ParseName(key, text, &sim->mounting, error)) {
      *error = At(name, v) + *error;
      return false;
    }
    return true;
  }
  if (!Number(name, key, v, &x, error)) return false;
  const bool whole = x == std::floor(x);
  auto index = [&](int* out, int low) {
    if (!whole || x < low || x > 64) {
      *error = At(name, v) + "key '" + key + "' must be a whole number from " +
               std::to_string(low) + " to 64";
      return false;
    }
    *out = static_cast<int>(x);
    return true;
  };
  auto positive = [&](double* out, bool zero_ok) {
    if (zero_ok ? !(x >= 0.0) : !(x > 0.0)) {
      *error = At(name, v) + "key '" + key + "' must be " + (zero_ok ? ">= 0" : "> 0");
      return false;
    }
    *out = x;
    return true;
  };
  if (key == "sim_imus") return index(&sim->imus, 1);
  if (key == "sim_permuted_imu") return index(&sim->permuted_imu, -1);
  if (key == "sim_flipped_imu") return index(&sim->flipped_imu, -1);
  if (key == "sim_slip_imu") return index(&sim->slip_imu, -1);
  if (key == "sim_max_clock_offset") return positive(&sim->max_clock_offset, true);
  if (key == "sim_clock_drift_std") return positive(&sim->clock_drift_std, true);
  if (key == "sim_hold") return positive(&sim->imu.hold_seconds, false);
  if (key == "sim_turn") return positive(&sim->imu.rotation_seconds, false);
  if (key == "sim_rate") return positive(&sim->imu.sample_rate, false);
  *error = At(name, v) + "unknown key '" + key +
           "' (the simulator's keys: sim_imus, sim_mounting, sim_permuted_imu, "
           "sim_flipped_imu, sim_slip_imu, sim_max_clock_offset, sim_clock_drift_std, "
           "sim_hold, sim_turn, sim_rate)";
  return false;
}

}  // namespace

bool IsMultiImuConfigFile(const std::string& path) {
  if (path.empty()) return false;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return false;
  try {
    const YAML::Node root = YAML::LoadFile(path);
    return root.IsMap() && root["imus"].IsDefined();
  } catch (const YAML::Exception&) {
    return false;
  }
}

bool ParseMultiImuConfig(const std::string& text, const std::string& name, MultiImuConfig* config,
                         std::string* error) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    std::ostringstream s;
    s << name << ":" << e.mark.line + 1 << ": not valid YAML: " << e.msg;
    *error = s.str();
    return false;
  }
  if (!root.IsMap()) {
    *error = name + ": the top level must be a map of keys";
    return false;
  }
  MultiImuConfig c;
  // The simulated plate: aligned units (the shipped config states no
  // mountings), holds and turns of a bench session.
  c.simulation.mounting = PlateMounting::kAligned;
  c.simulation.imu.hold_seconds = 4.0;
  c.simulation.imu.initial_still_seconds = 4.0;
  c.simulation.imu.rotation_seconds = 2.0;
  c.simulation.oversample = 2;
  // The unit defaults first: the IMUs start from them.
  Units defaults;
  for (const auto& kv : root) {
    const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : "?";
    bool ok = true;
    if (!kv.second.IsNull() && UnitKey(name, key, kv.second, &defaults, &ok, error) && !ok) {
      return false;
    }
  }
  {
    std::string why;
    if (!Scales(defaults, &c.default_accel_scale, &c.default_gyro_scale, &why)) {
      *error = name + ": " + why;
      return false;
    }
  }
  std::set<std::string> seen;
  for (const auto& kv : root) {
    const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : "?";
    const YAML::Node& v = kv.second;
    if (!seen.insert(key).second) {
      *error = At(name, kv.first) + "key '" + key + "' is given twice";
      return false;
    }
    if (v.IsNull()) {
      *error = At(name, kv.first) + "key '" + key + "' has no value (give one, or remove the line)";
      return false;
    }
    bool ok = true;
    double x = 0.0;
    std::string s;
    if (key == "method") {
      ok = Text(name, key, v, &s, error);
      if (ok && s != "multi_imu") {
        *error = At(name, v) + "a config with 'imus' has method: multi_imu";
        return false;
      }
    } else if (key == "format") {
      ok = Text(name, key, v, &s, error);
      if (ok && s != "csv") {
        *error = At(name, v) +
                 "format: the multi-IMU table is csv (bags and MCAP are recognised "
                 "from their bytes)";
        return false;
      }
    } else if (UnitKey(name, key, v, &defaults, &ok, error)) {
      // Read above.
    } else if (key == "imus" && v.IsScalar() && v.Scalar() == "auto") {
      c.auto_imus = true;
    } else if (key == "imus") {
      if (!v.IsSequence() || v.size() == 0) {
        *error = At(name, v) + "'imus' lists the IMUs (- name: imu0 ...) or is auto";
        return false;
      }
      std::set<std::string> names;
      for (size_t i = 0; i < v.size(); ++i) {
        MultiImuLogSpec imu;
        if (!ParseImu(name, v[i], i, defaults, &imu, error)) return false;
        if (!names.insert(imu.name).second) {
          *error = At(name, v[i]) + "IMU name '" + imu.name + "' is given twice";
          return false;
        }
        c.imus.push_back(imu);
      }
    } else if (key == "reference") {
      ok = Text(name, key, v, &c.reference, error);
    } else if (key == "time_column") {
      ok = Text(name, key, v, &c.time_column, error);
    } else if (key == "time_scale") {
      ok = Number(name, key, v, &c.time_scale, error);
    } else if (key == "gravity") {
      ok = Number(name, key, v, &x, error);
      if (ok && x > 0.0) c.options.gravity = x;
    } else if (key == "window") {
      ok = Number(name, key, v, &c.options.detector.window_seconds, error);
    } else if (key == "threshold_factor") {
      ok = Number(name, key, v, &c.options.detector.threshold_factor, error);
    } else if (key == "min_duration") {
      ok = Number(name, key, v, &c.options.detector.min_duration_seconds, error);
    } else if (key == "settle") {
      ok = Number(name, key, v, &c.options.detector.settle_seconds, error);
    } else if (key == "max_time_offset") {
      ok = Number(name, key, v, &c.options.max_time_offset, error);
    } else if (key == "permutation_tolerance") {
      ok = Number(name, key, v, &c.options.permutation_tolerance_deg, error);
    } else if (key.compare(0, 4, "sim_") == 0) {
      if (!SimKey(name, key, v, &c.simulation, error)) return false;
    } else if (key == "separate") {
      try {
        c.options.separate = v.as<bool>();
      } catch (const YAML::Exception&) {
        *error = At(name, v) + "key 'separate' must be true or false";
        return false;
      }
    } else {
      *error = At(name, kv.first) + "unknown key '" + key +
               "' (method, format, imus, reference, time_column, time_scale, gravity, window, "
               "threshold_factor, min_duration, settle, max_time_offset, "
               "permutation_tolerance, separate, the unit keys accel_units, gyro_units, "
               "accel_counts_per_g, gyro_counts_per_dps, accel_scale, gyro_scale, and the "
               "simulator's sim_imus, sim_mounting, sim_permuted_imu, sim_flipped_imu, "
               "sim_slip_imu, sim_max_clock_offset, sim_clock_drift_std, sim_hold, sim_turn, "
               "sim_rate)";
      return false;
    }
    if (!ok) return false;
  }
  if (c.imus.empty() && !c.auto_imus) {
    *error = name + ": no 'imus' (a multi-IMU config lists them, or says imus: auto)";
    return false;
  }
  int reference = 0;
  if (!c.reference.empty() && !c.auto_imus) {
    reference = -1;
    for (size_t i = 0; i < c.imus.size(); ++i) {
      if (c.imus[i].name == c.reference) reference = static_cast<int>(i);
    }
    if (reference < 0) {
      *error = name + ": reference '" + c.reference + "' is not one of the imus";
      return false;
    }
  }
  c.options.reference = reference;
  if (!c.options.IsValid(error)) {
    *error = name + ": " + *error;
    return false;
  }
  // The simulated table is written in the top-level units: raw counts or
  // SI.
  if (defaults.accel_units == AccelUnit::kCounts && defaults.gyro_units == GyroUnit::kCounts) {
    c.simulation.imu.raw_counts = true;
    c.simulation.imu.accel_counts_per_g = defaults.counts_per_g;
    c.simulation.imu.gyro_counts_per_dps = defaults.counts_per_dps;
  } else {
    c.simulation.imu.raw_counts = false;
  }
  if (!c.simulation.IsValid(error)) {
    *error = name + ": " + *error;
    return false;
  }
  if (!(c.time_scale > 0.0)) {
    *error = name + ": time_scale must be > 0";
    return false;
  }
  *config = c;
  return true;
}

bool LoadMultiImuConfig(const std::string& path, MultiImuConfig* config, std::string* error) {
  std::ifstream in(path);
  if (!in) {
    *error = path + ": cannot open the config file";
    return false;
  }
  std::stringstream buffer;
  buffer << in.rdbuf();
  return ParseMultiImuConfig(buffer.str(), path, config, error);
}

}  // namespace gravcal
