#include "gravcal/workflows/config.h"

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
      GRAVCAL_STRING(
          "method", "general", method,
          "calibration method: twelve_position (multi-position magnitude fit), ten_position "
          "(patent, self-aligned), known_attitude (fixture attitudes, --attitudes), "
          "handheld_kalman (21-state Kalman filter on a handheld log)"),
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
      GRAVCAL_INT("max_iterations", "solver", calibration.refinement.solver.max_iterations,
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
      // Issue 5: gyroscope calibration from the rotations between static poses.
      GRAVCAL_ENUM("gyro_model", "gyro", gyro.parameterization, "none, bias, scale, full",
                   "gyroscope from the rotations between poses: none, bias (+ common scale), "
                   "scale (diagonal) or full (scale and misalignment)"),
      GRAVCAL_BOOL("gyro_g_sensitivity", "gyro", gyro.g_sensitivity,
                   "also estimate the gyroscope g-sensitivity G (rad/s per m/s^2)"),
      GRAVCAL_BOOL("gyro_joint", "gyro", gyro.joint,
                   "refine the accelerometer's bias and U together with the gyroscope"),
      GRAVCAL_ENUM("gyro_loss", "gyro", gyro.loss, "none, huber, cauchy, soft_l1, arctan, tukey",
                   "robust loss on the gyroscope residuals"),
      GRAVCAL_DOUBLE("gyro_loss_scale", "gyro", gyro.loss_scale,
                     "gyroscope robust loss scale, in standard deviations"),
      GRAVCAL_DOUBLE("gyro_edge", "gyro", gyro.edge_seconds,
                     "seconds at each end of a static interval integrated with the rotations"),
      GRAVCAL_DOUBLE("gyro_max_rotation", "gyro", gyro.max_rotation_seconds,
                     "longest gap between poses used as a rotation, s"),
      GRAVCAL_STRING("sim_rotation_profile", "simulator", simulation.rotation_profile,
                     "rotations between poses: smooth (fixed axis) or hand (1-4 s, irregular)"),
      GRAVCAL_DOUBLE("sim_hand_min_rotation", "simulator", simulation.hand_min_seconds,
                     "hand profile: shortest rotation, s"),
      GRAVCAL_DOUBLE("sim_hand_max_rotation", "simulator", simulation.hand_max_seconds,
                     "hand profile: longest rotation, s"),
      GRAVCAL_DOUBLE("sim_hand_wobble", "simulator", simulation.hand_wobble_deg,
                     "hand profile: axis wobble, degrees (standard deviation)"),
      GRAVCAL_DOUBLE("sim_gyro_g_sensitivity", "simulator", simulation.gyro_g_sensitivity_std,
                     "truth gyroscope g-sensitivity spread, rad/s per m/s^2"),
      // Issue 3: ten-position (static alignment) and known-attitude methods.
      GRAVCAL_DOUBLE("align_accel_bias_std", "alignment", ten_position.alignment.accel_bias_std,
                     "prior of the accelerometer bias the static base cannot see, m/s^2"),
      GRAVCAL_DOUBLE("align_accel_matrix_std", "alignment", ten_position.alignment.accel_matrix_std,
                     "prior of each scale/misalignment error entry (seen as a bias dM f)"),
      GRAVCAL_DOUBLE("align_gyro_bias_std", "alignment", ten_position.alignment.gyro_bias_std,
                     "prior of the gyroscope bias, rad/s (decides gyrocompassing)"),
      GRAVCAL_DOUBLE("align_max_heading_std", "alignment",
                     ten_position.alignment.max_heading_std_deg,
                     "gyrocompass only when heading would be better than this, degrees"),
      GRAVCAL_DOUBLE("align_coarse_seconds", "alignment", ten_position.alignment.coarse_seconds,
                     "coarse alignment window at the start of each position, s"),
      GRAVCAL_DOUBLE("align_zero_velocity_std", "alignment",
                     ten_position.alignment.zero_velocity_std,
                     "zero-velocity measurement standard deviation, m/s"),
      GRAVCAL_BOOL("align_use_gyro", "alignment", ten_position.alignment.use_gyro,
                   "use the gyroscope in the alignment when the log has one"),
      GRAVCAL_DOUBLE("sim_latitude", "simulator", simulation.latitude_deg,
                     "the gyroscope senses Earth rate at this latitude, degrees (null = off)"),
      GRAVCAL_DOUBLE("sim_attitude_noise", "simulator", simulation.fixture_attitude_noise_deg,
                     "noise of the fixture attitudes simulate writes (attitudes.csv), degrees"),
      // Issue 4: handheld Kalman calibration and motion simulator.
      {{"gyro_nominal_scale", "gyro",
        "rad/s per raw gyroscope unit before calibration (1 = rad/s, 0.0174533 = deg/s), "
        "for the alignment and the handheld Kalman filter"},
       [](const YAML::Node& n, Config* c, std::string* e) {
         double v = 0.0;
         if (!GetDouble(n, &v, e)) return false;
         c->ten_position.gyro_nominal_scale = v;
         c->handheld.gyro_nominal_scale = v;
         return true;
       },
       [](const Config& c) { return Fmt(c.handheld.gyro_nominal_scale); }},
      GRAVCAL_DOUBLE("hk_still_seconds", "handheld_kalman", handheld.still_seconds,
                     "initial still period for roll and pitch, s"),
      GRAVCAL_INT("hk_passes", "handheld_kalman", handheld.passes,
                  "passes over the log; later ones start from the previous estimates"),
      GRAVCAL_DOUBLE("hk_update_interval", "handheld_kalman", handheld.update_interval,
                     "time between zero-velocity/position updates, s (~ hand motion correlation)"),
      GRAVCAL_DOUBLE("hk_velocity_noise", "handheld_kalman", handheld.velocity_noise,
                     "how fast the hand moves the unit, m/s (zero-velocity measurement noise)"),
      GRAVCAL_DOUBLE("hk_position_noise", "handheld_kalman", handheld.position_noise,
                     "how far the hand moves the unit, m (zero-position measurement noise)"),
      GRAVCAL_DOUBLE("hk_accel_noise_density", "handheld_kalman", handheld.accel_noise_density,
                     "accelerometer noise density, m/s^2/sqrt(Hz) (Allan deviation at 1 s)"),
      GRAVCAL_DOUBLE("hk_gyro_noise_density", "handheld_kalman", handheld.gyro_noise_density,
                     "gyroscope noise density, rad/s/sqrt(Hz) (Allan deviation at 1 s)"),
      GRAVCAL_DOUBLE("hk_accel_bias_walk", "handheld_kalman", handheld.accel_bias_walk,
                     "accelerometer bias random walk, m/s^2/sqrt(s) (0 = constant)"),
      GRAVCAL_DOUBLE("hk_gyro_bias_walk", "handheld_kalman", handheld.gyro_bias_walk,
                     "gyroscope bias random walk, rad/s/sqrt(s) (0 = constant)"),
      GRAVCAL_DOUBLE("hk_accel_bias_std", "handheld_kalman", handheld.accel_bias_std,
                     "prior accelerometer bias, m/s^2"),
      GRAVCAL_DOUBLE("hk_accel_scale_std", "handheld_kalman", handheld.accel_scale_std,
                     "prior accelerometer scale-factor error (fraction)"),
      GRAVCAL_DOUBLE("hk_gyro_bias_std", "handheld_kalman", handheld.gyro_bias_std,
                     "prior gyroscope bias, rad/s"),
      GRAVCAL_DOUBLE("hk_gyro_scale_std", "handheld_kalman", handheld.gyro_scale_std,
                     "prior gyroscope scale-factor error (fraction)"),
      {{"hk_cross_axis", "handheld_kalman",
        "also estimate cross-axis terms (accelerometer upper-triangular, gyroscope full)"},
       [](const YAML::Node& n, Config* c, std::string* e) {
         bool on = false;
         if (!GetBool(n, &on, e)) return false;
         c->handheld.accel_terms =
             on ? SensorErrorTerms::ScaleAndUpperCrossAxis() : SensorErrorTerms::ScaleOnly();
         c->handheld.gyro_terms =
             on ? SensorErrorTerms::ScaleAndCrossAxis() : SensorErrorTerms::ScaleOnly();
         return true;
       },
       [](const Config& c) {
         return std::string(c.handheld.gyro_terms.matrix_entries.size() > 3 ? "true" : "false");
       }},
      GRAVCAL_DOUBLE("hk_cross_axis_std", "handheld_kalman", handheld.cross_axis_std,
                     "prior cross-axis term (with hk_cross_axis), rad"),
      GRAVCAL_BOOL("hk_lever_arm", "handheld_kalman", handheld.estimate_lever_arm,
                   "also estimate the sensor's offset from the point the hand turns about"),
      GRAVCAL_DOUBLE("hk_lever_arm_std", "handheld_kalman", handheld.lever_arm_std,
                     "prior lever arm (with hk_lever_arm), m"),
      GRAVCAL_DOUBLE("hk_initial_attitude_std", "handheld_kalman", handheld.initial_attitude_std,
                     "initial roll/pitch error beyond the accelerometer's, rad"),
      GRAVCAL_BOOL("hk_earth_rate", "handheld_kalman", handheld.earth_rate,
                   "include the Earth rate (needs latitude)"),
      GRAVCAL_DOUBLE("hk_convergence_fraction", "handheld_kalman", handheld.convergence_fraction,
                     "converged once estimate (vs final) and sigma stay below this x prior sigma; "
                     "not determined when the final sigma is above it"),
      GRAVCAL_STRING("sim_motion", "motion simulator", sim_motion,
                     "simulate: handheld, turntable, vertical or rate_table (empty = sim_scheme)"),
      GRAVCAL_DOUBLE("hh_initial_still", "motion simulator", motion.initial_still_seconds,
                     "still at the start, s"),
      GRAVCAL_DOUBLE("hh_final_still", "motion simulator", motion.final_still_seconds,
                     "still at the end, s"),
      GRAVCAL_DOUBLE("hh_seconds_per_axis", "motion simulator", motion.seconds_per_axis,
                     "turning time per axis (rate table: per direction), s"),
      GRAVCAL_DOUBLE("hh_rate", "motion simulator", motion.rate_dps, "mean turning rate, deg/s"),
      GRAVCAL_DOUBLE("hh_rate_variation", "motion simulator", motion.rate_variation,
                     "handheld: relative variation of the hand's rate"),
      GRAVCAL_DOUBLE("hh_axis_wobble", "motion simulator", motion.axis_wobble_deg,
                     "handheld: rms wobble of the turning axis, deg"),
      GRAVCAL_DOUBLE("hh_sway", "motion simulator", motion.sway, "hand sway, m rms per axis"),
      GRAVCAL_DOUBLE("hh_sway_hz", "motion simulator", motion.sway_hz,
                     "highest hand sway frequency, Hz"),
      GRAVCAL_DOUBLE("hh_tremor", "motion simulator", motion.tremor,
                     "hand tremor (8-12 Hz), m/s^2 rms per axis"),
      GRAVCAL_DOUBLE("hh_angular_tremor", "motion simulator", motion.angular_tremor,
                     "hand tremor (8-12 Hz), rad/s rms per axis"),
      GRAVCAL_INT("hh_rounds", "motion simulator", motion.rounds,
                  "times through the x, y, z turns"),
      GRAVCAL_DOUBLE("hh_lever_arm", "motion simulator", motion.lever_arm,
                     "sensor distance from the point the hand turns about, m"),
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
  if (method != "twelve_position" && method != "ten_position" && method != "known_attitude" &&
      method != "handheld_kalman") {
    *error = "key 'method': unknown method '" + method +
             "' (available: twelve_position, ten_position, known_attitude, handheld_kalman)";
    return false;
  }
  std::string what;
  if (method == "handheld_kalman") {
    HandheldKalmanOptions h = handheld;
    h.gravity = calibration.gravity;
    h.accel_nominal_scale = calibration.nominal_scale;
    if (!h.IsValid(error)) return false;
  }
  MotionProfile profile;
  if (!sim_motion.empty() && !FromString(sim_motion, &profile)) {
    *error = "key 'sim_motion': must be empty, handheld, turntable, vertical or rate_table";
    return false;
  }
  if (!motion.IsValid(error)) return false;
  if (!input.IsValid(&what)) {
    *error = "input: " + what;
    return false;
  }
  if (!calibration.IsValid(&what)) {
    *error = what;
    return false;
  }
  if (!gyro.IsValid(&what)) {
    *error = what;
    return false;
  }
  if (method == "ten_position" && !ten_position.IsValid(&what)) {
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
