#include "gravcal/io/noise_io.h"

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <string>

#include "gravcal/io/log_reader.h"
#include "io/json_helpers.h"

namespace gravcal {
namespace internal {
namespace {

using nlohmann::json;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

json Number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

// The largest value a noise.json number may have (a term, a rate, a tau):
// its square stays within double arithmetic.
constexpr double kMaxNoiseValue = 1e150;

// The rule a value read must meet, for Checked.
enum class Range { kPositive, kNonNegative, kFinite, kProbability };

// `v` checked against `range`, or a runtime_error naming `where` (the key's
// path in the file, e.g. accel.x.white_noise.value) and the value.
double Checked(double v, Range range, const std::string& where) {
  // Beyond kMaxNoiseValue a variance (the square) leaves double arithmetic.
  const bool ok = std::isfinite(v) && (range == Range::kFinite || std::abs(v) <= kMaxNoiseValue) &&
                  (range == Range::kFinite || (range == Range::kPositive && v > 0.0) ||
                   (range == Range::kNonNegative && v >= 0.0) ||
                   (range == Range::kProbability && v > 0.0 && v < 1.0));
  if (ok) return v;
  const char* rule = range == Range::kPositive      ? "a positive number up to 1e150"
                     : range == Range::kNonNegative ? "a number >= 0, up to 1e150"
                     : range == Range::kProbability ? "a number between 0 and 1"
                                                    : "a finite number";
  std::ostringstream s;
  s.precision(9);
  s << where << " must be " << rule << " (it is " << v << ")";
  throw std::runtime_error(s.str());
}

// A number of `j` (null = NaN, not shown) checked against `range`.
double NumberAt(const json& j, const std::string& where, Range range) {
  if (j.is_null()) return kNaN;
  if (!j.is_number()) throw std::runtime_error(where + " must be a number or null");
  return Checked(j.get<double>(), range, where);
}

// The member `key` of the object `j`, at path `where` (its parent's path):
// a runtime_error naming the path when `j` is no object or has no `key`.
const json& Member(const json& j, const char* key, const std::string& where) {
  const std::string path = where.empty() ? std::string(key) : where + "." + key;
  if (!j.is_object())
    throw std::runtime_error((where.empty() ? "the file" : where) + " must be an object");
  if (!j.contains(key)) throw std::runtime_error(path + " is missing");
  return j.at(key);
}

// A number that must be there: `key` of `j`, at path `where`.
double Required(const json& j, const char* key, const std::string& where, Range range) {
  if (!j.contains(key)) throw std::runtime_error(where + " is missing");
  const double v = NumberAt(j.at(key), where, range);
  if (std::isnan(v)) throw std::runtime_error(where + " must be a number");
  return v;
}

double NumberOr(const json& j, const char* key, const std::string& where, Range range) {
  if (!j.contains(key)) return kNaN;
  return NumberAt(j.at(key), where + "." + key, range);
}

struct TermKey {
  const char* name;
  NoiseTerm AxisNoiseModel::*term;
};
constexpr TermKey kTermKeys[] = {{"white_noise", &AxisNoiseModel::white_noise},
                                 {"bias_instability", &AxisNoiseModel::bias_instability},
                                 {"random_walk", &AxisNoiseModel::random_walk},
                                 {"quantisation", &AxisNoiseModel::quantisation}};
constexpr const char* kAxes[] = {"x", "y", "z"};

json TermJson(const NoiseTerm& t) {
  json j = {{"value", Number(t.value)},
            {"std", Number(t.std)},
            {"tau", Number(t.tau)},
            {"tau_range", json::array({Number(t.tau_min), Number(t.tau_max)})}};
  if (!t.reason.empty()) j["reason"] = t.reason;
  if (std::isfinite(t.upper_bound)) j["upper_bound"] = t.upper_bound;
  return j;
}

// One term; `where` is its path (accel.x.white_noise). Every coefficient
// is a positive density or level, or null where the log does not show it.
NoiseTerm TermFromJson(const json& j, const std::string& where) {
  NoiseTerm t;
  t.value = NumberOr(j, "value", where, Range::kPositive);
  t.std = NumberOr(j, "std", where, Range::kNonNegative);
  t.tau = NumberOr(j, "tau", where, Range::kPositive);
  const json& range = j.at("tau_range");
  if (!range.is_array() || range.size() != 2) {
    throw std::runtime_error(where + ".tau_range must be [min, max]");
  }
  t.tau_min = NumberAt(range.at(0), where + ".tau_range[0]", Range::kPositive);
  t.tau_max = NumberAt(range.at(1), where + ".tau_range[1]", Range::kPositive);
  if (t.tau_max < t.tau_min) throw std::runtime_error(where + ".tau_range: max is below min");
  if (j.contains("reason")) t.reason = j.at("reason").get<std::string>();
  t.upper_bound = NumberOr(j, "upper_bound", where, Range::kPositive);
  return t;
}

json CurveJson(const AllanDeviation& c) {
  json tau = json::array(), adev = json::array(), lo = json::array(), hi = json::array(),
       edf = json::array();
  for (const AllanPoint& p : c.points) {
    tau.push_back(p.tau);
    adev.push_back(p.adev);
    lo.push_back(p.lo);
    hi.push_back(p.hi);
    edf.push_back(p.edf);
  }
  return {{"tau", tau}, {"adev", adev}, {"lo", lo}, {"hi", hi}, {"edf", edf}};
}

// An Allan curve; `where` is its path (accel.x.allan): increasing positive
// taus, deviations and bounds >= 0 with lo <= adev <= hi, positive edf.
AllanDeviation CurveFromJson(const json& j, double rate_hz, size_t samples, double confidence,
                             const std::string& where) {
  AllanDeviation c;
  c.rate_hz = rate_hz;
  c.samples = samples;
  c.confidence = confidence;
  const json& tau = j.at("tau");
  for (const char* key : {"tau", "adev", "lo", "hi", "edf"}) {
    if (j.contains(key) && (!j.at(key).is_array() || j.at(key).size() != tau.size())) {
      throw std::runtime_error(where + "." + key + " must be an array as long as " + where +
                               ".tau");
    }
  }
  for (size_t i = 0; i < tau.size(); ++i) {
    const std::string at = "[" + std::to_string(i) + "]";
    const auto number = [&](const char* key, Range range) {
      const std::string path = where + "." + key + at;
      if (!j.at(key).at(i).is_number()) throw std::runtime_error(path + " must be a number");
      return Checked(j.at(key).at(i).get<double>(), range, path);
    };
    AllanPoint p;
    p.tau = number("tau", Range::kPositive);
    if (!c.points.empty() && !(p.tau > c.points.back().tau)) {
      throw std::runtime_error(where + ".tau" + at + " must be larger than the tau before it");
    }
    p.m = static_cast<size_t>(std::llround(p.tau * rate_hz));
    p.adev = number("adev", Range::kNonNegative);
    p.lo = number("lo", Range::kNonNegative);
    p.hi = number("hi", Range::kNonNegative);
    if (!(p.lo <= p.adev && p.adev <= p.hi)) {
      throw std::runtime_error(where + at + ": lo <= adev <= hi does not hold");
    }
    if (j.contains("edf")) p.edf = number("edf", Range::kPositive);
    c.points.push_back(p);
  }
  c.message = "read from noise.json";
  return c;
}

json SensorJson(const std::array<AxisNoiseModel, 3>& axes,
                const std::array<AllanDeviation, 3>& curves,
                const std::array<std::vector<SpectralLine>, 3>& lines) {
  json sensor;
  for (int a = 0; a < 3; ++a) {
    json axis;
    for (const TermKey& k : kTermKeys) axis[k.name] = TermJson(axes[a].*(k.term));
    json named = json::array();
    for (const SpectralLine& line : lines[a]) {
      named.push_back({{"frequency_hz", line.frequency_hz},
                       {"amplitude", line.amplitude},
                       {"prominence", line.prominence}});
    }
    axis["lines"] = named;
    axis["allan"] = CurveJson(curves[a]);
    sensor[kAxes[a]] = axis;
  }
  return sensor;
}

void SensorFromJson(const json& sensor, const std::string& name, double rate_hz, size_t samples,
                    double confidence, std::array<AxisNoiseModel, 3>* axes,
                    std::array<AllanDeviation, 3>* curves,
                    std::array<std::vector<SpectralLine>, 3>* lines) {
  for (int a = 0; a < 3; ++a) {
    const json& axis = Member(sensor, kAxes[a], name);
    const std::string where = name + "." + kAxes[a];
    if (axis.contains("lines")) {
      for (const json& l : axis.at("lines")) {
        const std::string at = where + ".lines";
        SpectralLine line;
        line.frequency_hz = Required(l, "frequency_hz", at + ".frequency_hz", Range::kPositive);
        line.amplitude = Required(l, "amplitude", at + ".amplitude", Range::kNonNegative);
        line.prominence = l.contains("prominence")
                              ? Required(l, "prominence", at + ".prominence", Range::kNonNegative)
                              : 0.0;
        (*lines)[a].push_back(line);
      }
    }
    for (const TermKey& k : kTermKeys) {
      if (axis.contains(k.name)) {
        (*axes)[a].*(k.term) = TermFromJson(axis.at(k.name), where + "." + k.name);
      }
    }
    if (axis.contains("allan")) {
      (*curves)[a] =
          CurveFromJson(axis.at("allan"), rate_hz, samples, confidence, where + ".allan");
    }
  }
}

std::string Format(double v) {
  std::ostringstream s;
  s.precision(9);
  s << v;
  return s.str();
}

// still.<key>, a sample index: a non-negative integer. A float (9e99) or a
// negative number is refused here, before any conversion to size_t.
size_t StillIndex(const json& still, const char* key) {
  const json& v = still.at(key);
  if (!v.is_number_unsigned()) {
    throw std::runtime_error(std::string("still.") + key +
                             " is not a sample index (a non-negative integer)");
  }
  return v.get<size_t>();
}

}  // namespace
}  // namespace internal

double AxisMaximum(const std::array<AxisNoiseModel, 3>& axes, NoiseTerm AxisNoiseModel::*term) {
  double largest = internal::kNaN;
  for (const AxisNoiseModel& axis : axes) {
    const double v = (axis.*term).value;
    if (std::isfinite(v) && !(v <= largest)) largest = v;
  }
  return largest;
}

std::string NoiseToJson(const ImuNoise& noise) {
  using internal::json;
  const ImuNoiseModel& m = noise.model;
  json out;
  out["rate_hz"] = m.rate_hz;
  out["still"] = {{"begin", m.still_begin},
                  {"end", m.still_end},
                  {"t_begin", m.still_t_begin},
                  {"t_end", m.still_t_end}};
  out["confidence"] = noise.accel_curves[0].confidence;
  // Every choice `gravcal noise` made: how the samples were placed in time,
  // the raw units and how the accelerometer's unit was checked.
  const SampleTiming& t = noise.timing;
  out["choices"] = {
      {"timing",
       {{"rate_source", t.rate_source},
        {"median_step", t.median_step},
        {"largest_step", t.largest_step},
        {"largest_departure", t.largest_departure},
        {"unbiased_tau", t.unbiased_tau},
        {"text", t.message}}},
      {"units",
       {{"accel_scale", noise.accel_scale},
        {"gyro_scale", noise.gyro_scale},
        {"accel_offset",
         json::array({noise.accel_offset.x(), noise.accel_offset.y(), noise.accel_offset.z()})},
        {"mean_removed", true},
        {"unit_check", noise.unit_check}}},
      {"fit",
       {{"readings",
         "white noise and random walk where they dominate the curve with the smallest predicted "
         "uncertainty, bias instability at the curve's measured floor, random walk on a rise "
         "near +1/2; the spectral lines' Allan variance subtracted and the taus a line "
         "dominates left out; sigmas inflated by the readings' scatter over each term's range"}}}};
  out["accel"] = internal::SensorJson(m.accel, noise.accel_curves, noise.accel_lines);
  if (!noise.gyro_curves[0].points.empty()) {
    out["gyro"] = internal::SensorJson(m.gyro, noise.gyro_curves, noise.gyro_lines);
  }
  if (!noise.temperature_curve.points.empty()) {
    out["temperature"] = {{"allan", internal::CurveJson(noise.temperature_curve)}};
  }
  return out.dump(2) + "\n";
}

bool NoiseFromJson(const std::string& text, const std::string& name, ImuNoise* noise,
                   std::string* error) {
  using internal::json;
  ImuNoise parsed;
  try {
    const json in = json::parse(text);
    if (const std::string twice = internal::DuplicateJsonKey(text); !twice.empty()) {
      throw std::runtime_error("key '" + twice + "' appears twice (a key may be set once)");
    }
    ImuNoiseModel& m = parsed.model;
    using internal::Range;
    using internal::Required;
    m.rate_hz = Required(in, "rate_hz", "rate_hz", Range::kPositive);
    const json& still = internal::Member(in, "still", "");
    m.still_begin = internal::StillIndex(still, "begin");
    m.still_end = internal::StillIndex(still, "end");
    if (m.still_end < m.still_begin) {
      throw std::runtime_error("still.end is before still.begin");
    }
    m.still_t_begin = Required(still, "t_begin", "still.t_begin", Range::kFinite);
    m.still_t_end = Required(still, "t_end", "still.t_end", Range::kFinite);
    if (m.still_t_end < m.still_t_begin) {
      throw std::runtime_error("still.t_end is before still.t_begin");
    }
    const double confidence = in.contains("confidence")
                                  ? Required(in, "confidence", "confidence", Range::kProbability)
                                  : 0.683;
    const size_t samples = m.still_end - m.still_begin;
    internal::SensorFromJson(internal::Member(in, "accel", ""), "accel", m.rate_hz, samples,
                             confidence, &m.accel, &parsed.accel_curves, &parsed.accel_lines);
    if (in.contains("gyro")) {
      internal::SensorFromJson(in.at("gyro"), "gyro", m.rate_hz, samples, confidence, &m.gyro,
                               &parsed.gyro_curves, &parsed.gyro_lines);
    } else {
      NoiseTerm missing;
      missing.reason = "the log has no gyroscope";
      for (AxisNoiseModel& axis : m.gyro) axis = {missing, missing, missing, missing};
    }
    if (in.contains("choices")) {
      const json& choices = in.at("choices");
      if (choices.contains("timing")) {
        const json& t = choices.at("timing");
        SampleTiming& timing = parsed.timing;
        timing.rate_hz = m.rate_hz;
        timing.rate_source = t.value("rate_source", std::string());
        timing.median_step = t.value("median_step", 0.0);
        timing.largest_step = t.value("largest_step", 0.0);
        timing.largest_departure = t.value("largest_departure", 0.0);
        timing.unbiased_tau = t.value("unbiased_tau", 0.0);
        timing.message = t.value("text", std::string());
      }
      if (choices.contains("units")) {
        const json& u = choices.at("units");
        parsed.accel_scale = u.value("accel_scale", 1.0);
        parsed.gyro_scale = u.value("gyro_scale", 1.0);
        if (u.contains("accel_offset")) {
          for (int a = 0; a < 3; ++a)
            parsed.accel_offset(a) = u.at("accel_offset").at(a).get<double>();
        }
        parsed.unit_check = u.value("unit_check", std::string());
      }
    }
    if (in.contains("temperature")) {
      parsed.temperature_curve = internal::CurveFromJson(
          in.at("temperature").at("allan"), m.rate_hz, samples, confidence, "temperature.allan");
    }
  } catch (const std::exception& e) {
    *error = name + ": not a noise.json: " + e.what();
    return false;
  }
  parsed.message = "read from " + name;
  *noise = std::move(parsed);
  return true;
}

bool WriteNoiseJson(const ImuNoise& noise, const std::string& path, std::string* error) {
  return WriteFileAtomically(path, NoiseToJson(noise), error);
}

bool ReadNoiseJson(const std::string& path, ImuNoise* noise, std::string* error) {
  std::string text;
  return ReadFileBytes(path, &text, error) && NoiseFromJson(text, path, noise, error);
}

bool NoiseToKalibrYaml(const ImuNoiseModel& model, std::string* yaml, std::string* error) {
  const double values[4] = {AxisMaximum(model.accel, &AxisNoiseModel::white_noise),
                            AxisMaximum(model.accel, &AxisNoiseModel::random_walk),
                            AxisMaximum(model.gyro, &AxisNoiseModel::white_noise),
                            AxisMaximum(model.gyro, &AxisNoiseModel::random_walk)};
  const char* keys[4] = {"accelerometer_noise_density", "accelerometer_random_walk",
                         "gyroscope_noise_density", "gyroscope_random_walk"};
  for (int i = 0; i < 4; ++i) {
    if (!std::isfinite(values[i])) {
      *error = std::string("Kalibr needs ") + keys[i] +
               ", which no axis of the log shows (record a longer still log)";
      return false;
    }
  }
  std::ostringstream s;
  s << "# Kalibr imu.yaml from gravcal's Allan deviation fit: continuous-time densities\n"
    << "# (Kalibr wiki, \"IMU Noise Model\"), the largest of the three axes.\n"
    << "accelerometer_noise_density: " << internal::Format(values[0]) << "  # m/s^2/sqrt(Hz)\n"
    << "accelerometer_random_walk: " << internal::Format(values[1]) << "  # m/s^3/sqrt(Hz)\n"
    << "gyroscope_noise_density: " << internal::Format(values[2]) << "  # rad/s/sqrt(Hz)\n"
    << "gyroscope_random_walk: " << internal::Format(values[3]) << "  # rad/s^2/sqrt(Hz)\n"
    << "update_rate: " << internal::Format(model.rate_hz) << "  # Hz\n";
  *yaml = s.str();
  return true;
}

bool WriteKalibrImuYaml(const ImuNoiseModel& model, const std::string& path, std::string* error) {
  std::string yaml;
  return NoiseToKalibrYaml(model, &yaml, error) && WriteFileAtomically(path, yaml, error);
}

std::string NoiseToHandheldYaml(const ImuNoiseModel& model) {
  struct Key {
    const char* name;
    const std::array<AxisNoiseModel, 3>* axes;
    NoiseTerm AxisNoiseModel::*term;
    const char* unit;
  };
  const Key keys[] = {
      {"hk_accel_noise_density", &model.accel, &AxisNoiseModel::white_noise, "m/s^2/sqrt(Hz)"},
      {"hk_gyro_noise_density", &model.gyro, &AxisNoiseModel::white_noise, "rad/s/sqrt(Hz)"},
      {"hk_accel_bias_walk", &model.accel, &AxisNoiseModel::random_walk, "m/s^2/sqrt(s)"},
      {"hk_gyro_bias_walk", &model.gyro, &AxisNoiseModel::random_walk, "rad/s/sqrt(s)"}};
  std::ostringstream s;
  s << "# Handheld Kalman filter noise from gravcal's Allan deviation fit (largest axis).\n";
  for (const Key& k : keys) {
    const double v = AxisMaximum(*k.axes, k.term);
    if (std::isfinite(v)) {
      s << k.name << ": " << internal::Format(v) << "  # " << k.unit << "\n";
    } else {
      const std::string& reason = ((*k.axes)[0].*(k.term)).reason;
      s << "# " << k.name << " left at its default: " << (reason.empty() ? "not shown" : reason)
        << "\n";
    }
  }
  return s.str();
}

}  // namespace gravcal
