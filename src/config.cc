#include "gravcal/config.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>

namespace gravcal {
namespace {

// One key: how to set it from a YAML node and how to print it.
struct KeyHandler {
  ConfigKey key;
  std::function<bool(const YAML::Node&, Config*, std::string*)> set;
  std::function<std::string(const Config&)> get;
};

std::string Fmt(double v) {
  if (std::isnan(v)) return "null";
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

bool GetDouble(const YAML::Node& n, double* v, std::string* error) {
  if (n.IsNull()) {
    *v = NAN;
    return true;
  }
  try {
    if (!n.IsScalar()) throw YAML::Exception(YAML::Mark::null_mark(), "");
    *v = n.as<double>();
  } catch (const YAML::Exception&) {
    *error = "must be a number";
    return false;
  }
  if (!std::isfinite(*v)) {
    *error = "must be finite";
    return false;
  }
  return true;
}

bool GetInt(const YAML::Node& n, int* v, std::string* error) {
  try {
    if (!n.IsScalar()) throw YAML::Exception(YAML::Mark::null_mark(), "");
    *v = n.as<int>();
  } catch (const YAML::Exception&) {
    *error = "must be an integer";
    return false;
  }
  return true;
}

bool GetBool(const YAML::Node& n, bool* v, std::string* error) {
  try {
    if (!n.IsScalar()) throw YAML::Exception(YAML::Mark::null_mark(), "");
    *v = n.as<bool>();
  } catch (const YAML::Exception&) {
    *error = "must be true or false";
    return false;
  }
  return true;
}

bool GetString(const YAML::Node& n, std::string* v, std::string* error) {
  if (!n.IsScalar()) {
    *error = "must be a string";
    return false;
  }
  *v = n.Scalar();
  return true;
}

bool GetStringList(const YAML::Node& n, std::vector<std::string>* v, std::string* error) {
  if (n.IsNull()) {
    v->clear();
    return true;
  }
  if (!n.IsSequence()) {
    *error = "must be a list, e.g. [t, ax, ay, az]";
    return false;
  }
  std::vector<std::string> out;
  for (const YAML::Node& e : n) {
    if (!e.IsScalar()) {
      *error = "must be a list of names";
      return false;
    }
    out.push_back(e.Scalar());
  }
  *v = out;
  return true;
}

std::string ListText(const std::vector<std::string>& v) {
  std::string s = "[";
  for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + v[i];
  return s + "]";
}

template <typename Enum>
bool GetEnum(const YAML::Node& n, Enum* v, const char* choices, std::string* error) {
  std::string s;
  if (!GetString(n, &s, error) || !FromString(s, v)) {
    *error = std::string("must be one of ") + choices;
    return false;
  }
  return true;
}

#define GRAVCAL_DOUBLE(name, section, field, help)                                                 \
  {                                                                                                \
    {name, section, help},                                                                         \
        [](const YAML::Node& n, Config* c, std::string* e) { return GetDouble(n, &c->field, e); }, \
        [](const Config& c) { return Fmt(c.field); }                                               \
  }
#define GRAVCAL_INT(name, section, field, help)                                                 \
  {                                                                                             \
    {name, section, help},                                                                      \
        [](const YAML::Node& n, Config* c, std::string* e) { return GetInt(n, &c->field, e); }, \
        [](const Config& c) { return std::to_string(c.field); }                                 \
  }
#define GRAVCAL_BOOL(name, section, field, help)                                                 \
  {                                                                                              \
    {name, section, help},                                                                       \
        [](const YAML::Node& n, Config* c, std::string* e) { return GetBool(n, &c->field, e); }, \
        [](const Config& c) { return std::string(c.field ? "true" : "false"); }                  \
  }
#define GRAVCAL_STRING(name, section, field, help)                                                 \
  {                                                                                                \
    {name, section, help},                                                                         \
        [](const YAML::Node& n, Config* c, std::string* e) { return GetString(n, &c->field, e); }, \
        [](const Config& c) { return c.field.empty() ? std::string("\"\"") : c.field; }            \
  }
#define GRAVCAL_ENUM(name, section, field, choices, help)              \
  {                                                                    \
    {name, section, help},                                             \
        [](const YAML::Node& n, Config* c, std::string* e) {           \
          return GetEnum(n, &c->field, choices, e);                    \
        },                                                             \
        [](const Config& c) { return std::string(ToString(c.field)); } \
  }

// Issue 6: a key holding a list of effect names; `field(config)` points at
// the list (for a Config* and a const Config*).
template <typename Field>
KeyHandler EffectListKey(const char* name, const char* help, Field field) {
  return {{name, "effects", help},
          [field](const YAML::Node& n, Config* c, std::string* e) {
            std::vector<std::string> names;
            return GetStringList(n, &names, e) && ParseEffects(names, field(c), e);
          },
          [field](const Config& c) { return ListText(EffectNames(*field(&c))); }};
}

const std::vector<KeyHandler>& Handlers() {
  static const std::vector<KeyHandler> handlers = {
      GRAVCAL_STRING("method", "general", method,
                     "calibration method: twelve_position (multi-position magnitude fit)"),
      GRAVCAL_BOOL("output_covariance", "general", output_covariance,
                   "write accel.covariance into the calibration JSON"),
      // Input.
      GRAVCAL_ENUM("format", "input", input.format, "csv, whitespace",
                   "log format: csv (header row) or whitespace (no header; give columns)"),
      {{"columns", "input",
        "column names in file order (t, ax, ay, az, gx, gy, gz, temp; others ignored)"},
       [](const YAML::Node& n, Config* c, std::string* e) {
         return GetStringList(n, &c->input.columns, e);
       },
       [](const Config& c) { return ListText(c.input.columns); }},
      {{"rename", "input",
        "contract name -> column name in the file, e.g. {ax: acc_x, t: n_samples}"},
       [](const YAML::Node& n, Config* c, std::string* e) {
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
       },
       [](const Config& c) {
         std::string s = "{";
         for (const auto& kv : c.input.rename)
           s += (s.size() > 1 ? ", " : "") + kv.first + ": " + kv.second;
         return s + "}";
       }},
      GRAVCAL_INT("skip_lines", "input", input.skip_lines, "metadata lines before the header"),
      GRAVCAL_DOUBLE("sample_rate", "input", input.sample_rate,
                     "Hz; gives t = index / sample_rate when the log has no time column"),
      GRAVCAL_DOUBLE("time_scale", "input", input.time_scale,
                     "multiplies the time column (1e-9 for nanoseconds)"),
      GRAVCAL_STRING("gyro_path", "input", input.gyro_path,
                     "second whitespace file with t gx gy gz sharing the timestamps"),
      // Gravity.
      GRAVCAL_DOUBLE("gravity", "gravity", calibration.gravity.gravity,
                     "local gravity, m/s^2 (0 = not given)"),
      GRAVCAL_DOUBLE("latitude", "gravity", calibration.gravity.latitude,
                     "geodetic latitude, degrees, for normal gravity"),
      GRAVCAL_DOUBLE("height", "gravity", calibration.gravity.height,
                     "height above the ellipsoid, m, for normal gravity"),
      // Static detection.
      GRAVCAL_DOUBLE("window", "detector", calibration.detector.window_seconds,
                     "moving variance window, s"),
      GRAVCAL_DOUBLE("noise_quantile", "detector", calibration.detector.noise_quantile,
                     "quantile of the windowed variance taken as the noise floor"),
      GRAVCAL_DOUBLE("threshold_factor", "detector", calibration.detector.threshold_factor,
                     "static when the variance is below this times the noise floor"),
      GRAVCAL_DOUBLE("min_duration", "detector", calibration.detector.min_duration_seconds,
                     "shortest static interval kept, s"),
      GRAVCAL_DOUBLE("settle", "detector", calibration.detector.settle_seconds,
                     "trimmed from each end of a static interval, s"),
      GRAVCAL_DOUBLE("gyro_threshold_factor", "detector",
                     calibration.detector.gyro_threshold_factor,
                     "gyroscope: static when its variance is below this times its floor"),
      GRAVCAL_DOUBLE("max_floor_ratio", "detector", calibration.detector.max_floor_ratio,
                     "noise floor capped at this times the sample-to-sample white noise"),
      GRAVCAL_DOUBLE("merge_gap_windows", "detector", calibration.detector.merge_gap_windows,
                     "longest gap, in windows, across which two intervals are merged"),
      GRAVCAL_BOOL("use_gyro", "detector", calibration.detector.use_gyro,
                   "use the gyroscope variance too, when present"),
      GRAVCAL_DOUBLE("merge_angle", "detector", calibration.detector.merge_angle_deg,
                     "adjacent intervals closer than this are one pose, degrees"),
      // Model and solver.
      GRAVCAL_ENUM("parameterization", "model", calibration.refinement.parameterization,
                   "scale, scale_misalignment, affine",
                   "scale (6), scale_misalignment (9, gauge-free) or affine (12)"),
      GRAVCAL_DOUBLE("axis_tolerance", "model", calibration.coarse.axis_tolerance_deg,
                     "a position within this many degrees of an axis counts as axis-aligned"),
      {{"nominal_up", "model",
        "up axis of each detected position, e.g. [+z, -z, +x, ?]; empty = automatic"},
       [](const YAML::Node& n, Config* c, std::string* e) {
         std::vector<std::string> names;
         if (!GetStringList(n, &names, e)) return false;
         std::vector<int> axes;
         for (const std::string& s : names) {
           int found = -2;
           for (int a = -1; a < 6; ++a) {
             if (s == NominalAxisName(a)) found = a;
           }
           if (found == -2) {
             *e = "entry '" + s + "' must be +x, -x, +y, -y, +z, -z or ?";
             return false;
           }
           axes.push_back(found);
         }
         c->calibration.nominal_up = axes;
         return true;
       },
       [](const Config& c) {
         std::vector<std::string> names;
         for (int a : c.calibration.nominal_up) names.push_back(NominalAxisName(a));
         return ListText(names);
       }},
      GRAVCAL_BOOL("allow_undetermined", "model", calibration.allow_undetermined,
                   "write parameters the positions do not determine as null instead of failing"),
      GRAVCAL_DOUBLE("nominal_scale", "model", calibration.nominal_scale,
                     "m/s^2 per raw unit assumed before calibration (for the 'before' residual)"),
      GRAVCAL_ENUM("solver", "solver", calibration.solver, "ceres, newton",
                   "refinement solver: ceres, or newton (the seed's hand-written iteration)"),
      GRAVCAL_ENUM("newton_residual", "solver", calibration.newton_residual,
                   "squared_magnitude, magnitude",
                   "Newton residual: squared_magnitude (seed) or magnitude (same cost as ceres)"),
      GRAVCAL_ENUM("loss", "solver", calibration.refinement.loss,
                   "none, huber, cauchy, soft_l1, arctan, tukey", "robust loss on the residuals"),
      GRAVCAL_DOUBLE("loss_scale", "solver", calibration.refinement.loss_scale,
                     "robust loss scale, in standard deviations"),
      GRAVCAL_BOOL("covariance", "solver", calibration.refinement.compute_covariance,
                   "compute the covariance (standard deviations)"),
      GRAVCAL_INT("max_iterations", "solver", calibration.refinement.max_iterations,
                  "solver iteration limit"),
      // Simulator.
      GRAVCAL_STRING("sim_scheme", "simulator", simulation.scheme, "six, twelve, ten or random:N"),
      GRAVCAL_DOUBLE("sim_hold", "simulator", simulation.hold_seconds, "hold per pose, s"),
      GRAVCAL_DOUBLE("sim_initial_still", "simulator", simulation.initial_still_seconds,
                     "initial still period, s"),
      GRAVCAL_DOUBLE("sim_rotation_time", "simulator", simulation.rotation_seconds,
                     "rotation between poses, s"),
      GRAVCAL_DOUBLE("sim_sample_rate", "simulator", simulation.sample_rate, "Hz"),
      GRAVCAL_DOUBLE("sim_gravity", "simulator", simulation.gravity, "m/s^2"),
      GRAVCAL_BOOL("sim_raw_counts", "simulator", simulation.raw_counts,
                   "raw output in counts (true) or SI units (false)"),
      GRAVCAL_DOUBLE("sim_accel_counts_per_g", "simulator", simulation.accel_counts_per_g,
                     "accelerometer counts per g"),
      GRAVCAL_DOUBLE("sim_gyro_counts_per_dps", "simulator", simulation.gyro_counts_per_dps,
                     "gyroscope counts per deg/s"),
      GRAVCAL_DOUBLE("sim_accel_noise", "simulator", simulation.accel_noise,
                     "accelerometer white noise per sample, m/s^2"),
      GRAVCAL_DOUBLE("sim_accel_bias_random_walk", "simulator", simulation.accel_bias_random_walk,
                     "m/s^2/sqrt(s)"),
      GRAVCAL_DOUBLE("sim_gyro_noise", "simulator", simulation.gyro_noise,
                     "gyroscope white noise per sample, rad/s"),
      GRAVCAL_DOUBLE("sim_gyro_bias_random_walk", "simulator", simulation.gyro_bias_random_walk,
                     "rad/s/sqrt(s)"),
      GRAVCAL_DOUBLE("sim_accel_bias", "simulator", simulation.accel_bias_std,
                     "truth accelerometer bias spread, m/s^2"),
      GRAVCAL_DOUBLE("sim_accel_scale", "simulator", simulation.accel_scale_std,
                     "truth accelerometer scale error spread (fraction)"),
      GRAVCAL_DOUBLE("sim_accel_misalignment", "simulator", simulation.accel_misalignment_std,
                     "truth accelerometer misalignment spread, rad"),
      GRAVCAL_DOUBLE("sim_gyro_bias", "simulator", simulation.gyro_bias_std,
                     "truth gyroscope bias spread, rad/s"),
      GRAVCAL_DOUBLE("sim_gyro_scale", "simulator", simulation.gyro_scale_std,
                     "truth gyroscope scale error spread (fraction)"),
      GRAVCAL_DOUBLE("sim_gyro_misalignment", "simulator", simulation.gyro_misalignment_std,
                     "truth gyroscope misalignment spread, rad"),
      GRAVCAL_DOUBLE("sim_placement_error", "simulator", simulation.placement_error_deg,
                     "placement error per pose, degrees"),
      GRAVCAL_DOUBLE("sim_tremor", "simulator", simulation.tremor,
                     "hand tremor while still, m/s^2 rms (0 = table)"),
      GRAVCAL_DOUBLE("sim_temperature_start", "simulator", simulation.temperature_start, "deg C"),
      GRAVCAL_DOUBLE("sim_temperature_end", "simulator", simulation.temperature_end, "deg C"),
      GRAVCAL_DOUBLE("sim_temperature_tau", "simulator", simulation.temperature_tau,
                     "warm-up time constant, s"),
      // Issue 6: model effects and the discovery workflow.
      EffectListKey("effects",
                    "effects added to the model by name (README: effect catalogue), e.g. "
                    "[accel_temperature_bias]",
                    [](auto* c) { return &c->effects; }),
      EffectListKey("discovery_candidates", "effects discover tries; empty = the whole catalogue",
                    [](auto* c) { return &c->discovery.candidates; }),
      GRAVCAL_DOUBLE("discovery_significance", "effects", discovery.significance,
                     "family-wise significance level of one discovery step"),
      GRAVCAL_DOUBLE("discovery_min_bic_gain", "effects", discovery.min_bic_gain,
                     "BIC decrease a candidate must bring (10 = very strong evidence)"),
      GRAVCAL_DOUBLE("discovery_ambiguity_bic", "effects", discovery.ambiguity_bic,
                     "candidates within this delta BIC of the best are reported as ambiguous"),
      GRAVCAL_INT("discovery_max_steps", "effects", discovery.max_steps,
                  "most effects discover adds"),
      GRAVCAL_INT("discovery_min_dof", "effects", discovery.min_dof,
                  "residual dof an extended model must keep"),
      GRAVCAL_DOUBLE("discovery_min_temperature_range", "effects", discovery.min_temperature_range,
                     "degC the positions must span for temperature effects to be tried"),
      GRAVCAL_DOUBLE("sim_accel_quadratic", "simulator", simulation.accel_quadratic_std,
                     "truth k2 spread per axis, 1/(m/s^2)"),
      GRAVCAL_DOUBLE("sim_accel_temperature_bias", "simulator",
                     simulation.accel_temperature_bias_std,
                     "truth accelerometer bias tempco spread, m/s^2/degC"),
      GRAVCAL_DOUBLE("sim_accel_temperature_scale", "simulator",
                     simulation.accel_temperature_scale_std,
                     "truth accelerometer scale tempco spread, 1/degC"),
      GRAVCAL_DOUBLE("sim_accel_bias_drift", "simulator", simulation.accel_bias_drift_std,
                     "truth accelerometer bias drift spread, m/s^2/s"),
      GRAVCAL_DOUBLE("sim_gyro_g_sensitivity", "simulator", simulation.gyro_g_sensitivity_std,
                     "truth gyroscope g-sensitivity spread per element, rad/s per m/s^2"),
      GRAVCAL_DOUBLE("sim_gyro_temperature_bias", "simulator", simulation.gyro_temperature_bias_std,
                     "truth gyroscope bias tempco spread, rad/s/degC"),
      GRAVCAL_DOUBLE("sim_gyro_bias_drift", "simulator", simulation.gyro_bias_drift_std,
                     "truth gyroscope bias drift spread, rad/s/s"),
      GRAVCAL_DOUBLE("sim_effect_reference_temperature", "simulator",
                     simulation.effect_reference_temperature,
                     "temperature at which the simulated temperature terms are zero, degC"),
  };
  return handlers;
}

const KeyHandler* Find(const std::string& name) {
  for (const KeyHandler& h : Handlers()) {
    if (h.key.name == name) return &h;
  }
  return nullptr;
}

bool SetNode(const std::string& key, const YAML::Node& node, Config* config, std::string* error) {
  const KeyHandler* h = Find(key);
  if (h == nullptr) {
    *error = "unknown key '" + key + "' (gravcal help lists the keys)";
    return false;
  }
  std::string what;
  if (!h->set(node, config, &what)) {
    *error = "key '" + key + "': " + what;
    return false;
  }
  return true;
}

}  // namespace

bool Config::IsValid(std::string* error) const {
  if (method != "twelve_position") {
    *error = "key 'method': unknown method '" + method + "' (available: twelve_position)";
    return false;
  }
  std::string what;
  if (!input.IsValid(&what)) {
    *error = "input: " + what;
    return false;
  }
  if (!calibration.IsValid(&what)) {
    *error = what;
    return false;
  }
  if (!discovery.IsValid(&what)) {
    *error = what;
    return false;
  }
  return true;
}

const std::vector<ConfigKey>& ConfigKeys() {
  static const std::vector<ConfigKey> keys = [] {
    std::vector<ConfigKey> k;
    for (const KeyHandler& h : Handlers()) k.push_back(h.key);
    return k;
  }();
  return keys;
}

bool IsConfigKey(const std::string& name) { return Find(name) != nullptr; }

std::string ConfigValueText(const Config& config, const std::string& key) {
  const KeyHandler* h = Find(key);
  return h == nullptr ? "" : h->get(config);
}

bool LoadConfigText(const std::string& text, const std::string& name, Config* config,
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
  if (root.IsNull()) return true;
  if (!root.IsMap()) {
    *error = name + ": the top level must be a map of keys";
    return false;
  }
  Config updated = *config;
  for (const auto& kv : root) {
    std::string what;
    const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : "?";
    if (!SetNode(key, kv.second, &updated, &what)) {
      std::ostringstream s;
      s << name << ":" << kv.first.Mark().line + 1 << ": " << what;
      *error = s.str();
      return false;
    }
  }
  *config = updated;
  return true;
}

bool LoadConfigFile(const std::string& path, Config* config, std::string* error) {
  std::ifstream in(path);
  if (!in) {
    *error = path + ": cannot open the config file";
    return false;
  }
  std::stringstream buffer;
  buffer << in.rdbuf();
  return LoadConfigText(buffer.str(), path, config, error);
}

bool SetConfigValue(const std::string& key, const std::string& value, Config* config,
                    std::string* error) {
  YAML::Node node;
  try {
    node = YAML::Load(value);
  } catch (const YAML::Exception&) {
    node = YAML::Node(value);
  }
  if (!Find(key)) {
    *error = "unknown key '" + key + "' (gravcal help lists the keys)";
    return false;
  }
  return SetNode(key, node, config, error);
}

}  // namespace gravcal
