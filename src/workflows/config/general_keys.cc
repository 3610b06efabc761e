// Config section "general": the method and what every method writes, and
// section "input": how the log is read (LogReaderOptions). Every method
// uses both.
#include <map>

#include "gravcal/workflows/method_registry.h"
#include "workflows/config/config_key.h"

namespace gravcal {
namespace internal {

namespace {

// The method by its name; an unknown name is refused with the available ones.
bool ReadMethod(const YAML::Node& n, CalibrationConfig* c, std::string* e) {
  std::string name;
  if (!ReadString(n, &name, e)) return false;
  if (!FromString(name, &c->method)) {
    *e = "unknown method '" + name + "' (available: " + CalibrationMethodNames() + ")";
    return false;
  }
  return true;
}

}  // namespace

SectionOf<CalibrationConfig> GeneralSection() {
  return {"general",
          ConfigSectionUse::kAllMethods,
          {
              GRAVCAL_KEY("method", "calibration method: " + CalibrationMethodsHelp(),
                          ReadMethod(n, c, e), std::string(ToString(c.method))),
              GRAVCAL_BOOL("output_covariance", output_covariance,
                           "write accel.covariance into the calibration JSON"),
          }};
}

namespace {

bool ReadRename(const YAML::Node& n, CalibrationConfig* c, std::string* e) {
  if (n.IsNull()) {
    c->input.rename.clear();
    return true;
  }
  if (!n.IsMap()) {
    *e = "must be a map, e.g. {ax: acc_x}";
    return false;
  }
  std::map<std::string, std::string> out;
  for (const auto& kv : n) {
    if (!kv.first.IsScalar() || !kv.second.IsScalar()) {
      *e = "must map names to names";
      return false;
    }
    out[kv.first.Scalar()] = kv.second.Scalar();
  }
  c->input.rename = out;
  return true;
}

std::string RenameText(const CalibrationConfig& c) {
  std::string s = "{";
  for (const auto& kv : c.input.rename) {
    s += (s.size() > 1 ? ", " : "") + kv.first + ": " + kv.second;
  }
  return s + "}";
}

}  // namespace

SectionOf<CalibrationConfig> InputSection() {
  return {
      "input",
      ConfigSectionUse::kAllMethods,
      {
          GRAVCAL_ENUM("format", input.format,
                       "log format (csv has a header row; whitespace none: give columns)"),
          GRAVCAL_KEY("columns",
                      "column names in file order (t, ax, ay, az, gx, gy, gz, temp; others "
                      "ignored)",
                      ReadStringList(n, &c->input.columns, e), ListText(c.input.columns)),
          GRAVCAL_KEY("rename",
                      "contract name -> column name in the file, e.g. {ax: acc_x, t: n_samples}",
                      ReadRename(n, c, e), RenameText(c)),
          GRAVCAL_INT("skip_lines", input.skip_lines, "metadata lines before the header"),
          GRAVCAL_DOUBLE("sample_rate", input.sample_rate,
                         "Hz; gives t = index / sample_rate when the log has no time column"),
          GRAVCAL_DOUBLE("time_scale", input.time_scale,
                         "multiplies the time column (1e-9 for nanoseconds)"),
          GRAVCAL_DOUBLE("temp_scale", input.temp_scale,
                         "degC per unit of the temp column: temp = temp_offset + temp_scale * "
                         "value (raw register counts, e.g. 1/132.48 for an ICM-42688)"),
          GRAVCAL_DOUBLE("temp_offset", input.temp_offset,
                         "degC added to the scaled temp column (25 for an ICM-42688's register)"),
          GRAVCAL_STRING("gyro_path", input.gyro_path,
                         "second whitespace file with t gx gy gz sharing the timestamps"),
          GRAVCAL_STRING("topic", input.topic,
                         "bags and MCAP: the sensor_msgs/Imu topic (empty: the only one)"),
          GRAVCAL_BOOL("record_time", input.record_time,
                       "bags and MCAP: t from the recorder's receive time, not header.stamp"),
          GRAVCAL_INT("max_log_entries", input.max_log_entries,
                      "calibrate, noise, batch: most entries of a text log held (a longer log "
                      "is read as means of 2^k rows); 0 = no limit, else >= 16"),
      }};
}

}  // namespace internal
}  // namespace gravcal
