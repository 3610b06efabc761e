#include "gravcal/estimation/noise_characterisation.h"

#include <Eigen/Geometry>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <thread>
#include <vector>

#include "util/source_prefix.h"
#include "util/thread_pool.h"

namespace gravcal {
namespace internal {
namespace {

// Still intervals of this many samples or more have their axes worked on
// every core (a long log's noise model: about 1 s of CPU per axis for 2^21
// samples); shorter ones on the calling thread.
constexpr size_t kParallelNoiseSamples = size_t{1} << 20;

// Allan curve and fit of one axis of `samples` (already SI) over the still
// interval.
bool CharacteriseAxis(const std::vector<double>& samples, const ImuNoiseModel& where,
                      const NoiseOptions& options, const std::string& name, AllanDeviation* curve,
                      AxisNoiseModel* axis, std::vector<SpectralLine>* lines, std::string* error) {
  AllanDeviation raw;
  if (!ComputeAllanDeviation(samples, 0, samples.size(), where.rate_hz, options.allan, &raw)) {
    *error = name + ": " + raw.message;
    return false;
  }
  *lines = FindSpectralLines(samples, 0, samples.size(), where.rate_hz);
  NoiseFit fit;
  if (!FitNoiseTerms(raw, options.fit, *lines, &fit)) {
    *error = name + ": " + fit.message;
    return false;
  }
  *curve = fit.curve;
  *axis = fit.model;
  return true;
}

// Whether the log turns (find_still false): the largest angle between the
// mean accelerometer vector of one tenth of samples [begin, end) and that of
// all of them, degrees.
double LargestTilt(const ImuLog& log, size_t begin, size_t end, size_t* where) {
  const size_t parts = 10;
  const size_t n = end - begin;
  Eigen::Vector3d all = Eigen::Vector3d::Zero();
  for (size_t i = begin; i < end; ++i) all += log.accel[i];
  double worst = 0.0;
  for (size_t p = 0; p < parts && n >= parts; ++p) {
    const size_t b = begin + p * n / parts;
    const size_t e = begin + (p + 1) * n / parts;
    Eigen::Vector3d part = Eigen::Vector3d::Zero();
    for (size_t i = b; i < e; ++i) part += log.accel[i];
    const double angle =
        std::atan2(part.cross(all).norm(), part.dot(all)) * 180.0 / 3.14159265358979323846;
    if (angle > worst) {
      worst = angle;
      *where = b;
    }
  }
  return worst;
}

// The samples the noise model is taken from: the longest still interval
// (find_still) or the whole log, which must then be still. False with a
// message naming the log.
bool ChooseStillRange(const ImuLog& log, const NoiseOptions& options, size_t* begin, size_t* end,
                      std::string* message) {
  *begin = 0;
  *end = log.size();
  if (options.find_still) {
    StaticDetection detection;
    // The bias's wander over a long still log is what the noise model
    // measures, not a change of pose or a turn: no level checks.
    StaticDetectorOptions detector = options.detector;
    detector.spread_factor = 0.0;
    detector.trend_factor = 0.0;
    detector.step_factor = 0.0;
    if (!DetectStaticIntervals(log, detector, &detection)) {
      *message = internal::PrefixSource(log.source, detection.message);
      return false;
    }
    if (detection.intervals.empty()) {
      *message = log.source +
                 ": no still interval: the static detector found none (the noise model "
                 "needs the sensor at rest)";
      return false;
    }
    const StaticInterval* longest = &detection.intervals.front();
    for (const StaticInterval& s : detection.intervals) {
      if (s.count() > longest->count()) longest = &s;
    }
    *begin = longest->begin;
    *end = longest->end;
  } else {
    size_t where = 0;
    const double tilt = LargestTilt(log, *begin, *end, &where);
    if (tilt > options.max_tilt_deg) {
      std::ostringstream s;
      s.precision(3);
      s << log.source << ": the log moves: gravity turns by " << tilt
        << " degrees (near t = " << log.t[where]
        << " s), and noise_find_still is false (the whole log must be still; "
        << "set it true to use the longest still interval)";
      *message = s.str();
      return false;
    }
  }
  return true;
}

}  // namespace
}  // namespace internal

bool NoiseOptions::IsValid(std::string* error) const {
  if (!(accel_scale > 0.0) || !std::isfinite(accel_scale) || !(gyro_scale > 0.0) ||
      !std::isfinite(gyro_scale)) {
    *error = "noise accel_scale and gyro_scale must be finite and > 0";
    return false;
  }
  if (!(max_tilt_deg > 0.0)) {
    *error = "noise max_tilt_deg must be > 0";
    return false;
  }
  if (!(rate_hz >= 0.0) || !std::isfinite(rate_hz) || !accel_offset.allFinite()) {
    *error = "noise rate must be >= 0 Hz and the accelerometer offset finite";
    return false;
  }
  if (!(max_time_bias > 0.0 && max_time_bias < 1.0)) {
    *error = "noise max_time_bias must be in (0, 1)";
    return false;
  }
  return (!find_still || detector.IsValid(error)) && allan.IsValid(error) && fit.IsValid(error);
}

bool CharacteriseNoise(const ImuLog& log, const NoiseOptions& options, ImuNoise* result) {
  *result = ImuNoise();
  std::string error;
  if (!options.IsValid(&error) || !log.Validate(&error)) {
    result->message = error;
    return false;
  }
  ImuNoiseModel& model = result->model;
  size_t begin = 0, end = log.size();
  if (!internal::ChooseStillRange(log, options, &begin, &end, &result->message)) return false;
  model.still_begin = begin;
  model.still_end = end;
  model.still_t_begin = log.t[begin];
  model.still_t_end = log.t[end - 1];
  const double span = log.t[end - 1] - log.t[begin];
  const double longest_tau =
      options.allan.max_tau > 0.0 ? options.allan.max_tau : options.allan.max_tau_fraction * span;
  if (!ResolveSampleTiming(log.t, begin, end, options.rate_hz, options.allan.time_step_tolerance,
                           options.max_time_bias, longest_tau, &result->timing, &error)) {
    result->message = log.source + ": " + error;
    return false;
  }
  model.rate_hz = result->timing.rate_hz;
  result->accel_scale = options.accel_scale;
  result->gyro_scale = options.gyro_scale;
  result->accel_offset = options.accel_offset;
  const double seconds = (end - begin) / model.rate_hz;
  if (options.allan.max_tau > 0.0 &&
      seconds * options.allan.max_tau_fraction < options.allan.max_tau) {
    std::ostringstream s;
    s.precision(4);
    s << log.source << ": the longest still interval (t = " << std::fixed << std::setprecision(2)
      << model.still_t_begin << " to " << model.still_t_end << " s) lasts " << std::defaultfloat
      << std::setprecision(4) << seconds << " s, too short for tau up to " << options.allan.max_tau
      << " s: that needs at least " << options.allan.max_tau / options.allan.max_tau_fraction
      << " s of rest";
    result->message = s.str();
    return false;
  }

  const char* axes = "xyz";
  // The axes (accelerometer x, y, z, then gyroscope x, y, z) are
  // independent: for a long interval on every core, each with its own
  // samples (the same results); the first failure in that order is the one
  // reported, as on one thread.
  const size_t sensors = log.has_gyro() ? 2 : 1;
  std::vector<std::string> errors(3 * sensors);
  std::vector<char> ok(3 * sensors, 0);
  const int threads = end - begin >= internal::kParallelNoiseSamples
                          ? static_cast<int>(std::max(1u, std::thread::hardware_concurrency()))
                          : 1;
  internal::ParallelFor(3 * sensors, threads, [&](size_t k) {
    const int a = static_cast<int>(k % 3);
    const bool gyro = k >= 3;
    const std::vector<Eigen::Vector3d>& x = gyro ? log.gyro : log.accel;
    const double scale = gyro ? options.gyro_scale : options.accel_scale;
    std::vector<double> samples(end - begin);
    for (size_t i = begin; i < end; ++i) samples[i - begin] = scale * x[i](a);
    ok[k] = internal::CharacteriseAxis(
        samples, model, options, std::string(gyro ? "gyro " : "accel ") + axes[a],
        gyro ? &result->gyro_curves[a] : &result->accel_curves[a],
        gyro ? &model.gyro[a] : &model.accel[a],
        gyro ? &result->gyro_lines[a] : &result->accel_lines[a], &errors[k]);
  });
  for (size_t k = 0; k < ok.size(); ++k) {
    if (!ok[k]) {
      result->message = log.source + ": " + errors[k];
      return false;
    }
  }
  if (!log.has_gyro()) {
    NoiseTerm missing;
    missing.reason = "the log has no gyroscope";
    for (int a = 0; a < 3; ++a) model.gyro[a] = {missing, missing, missing, missing};
  }
  std::vector<double> samples(end - begin);
  if (log.has_temperature()) {
    for (size_t i = begin; i < end; ++i) samples[i - begin] = log.temperature[i];
    if (!ComputeAllanDeviation(samples, 0, samples.size(), model.rate_hz, options.allan,
                               &result->temperature_curve)) {
      result->message = log.source + ": temperature: " + result->temperature_curve.message;
      return false;
    }
  }
  std::ostringstream s;
  s.precision(4);
  s << "noise from " << seconds << " s of rest (t = " << std::fixed << std::setprecision(2)
    << model.still_t_begin << " to " << model.still_t_end << " s) at " << model.rate_hz << " Hz";
  if (!result->timing.rate_source.empty() && result->timing.unbiased_tau > 0.0) {
    s << " (" << result->timing.message << ")";
  }
  for (int sensor = 0; sensor < 2; ++sensor) {
    for (int a = 0; a < 3; ++a) {
      const std::vector<SpectralLine>& lines =
          sensor == 0 ? result->accel_lines[a] : result->gyro_lines[a];
      if (lines.empty()) continue;
      s << "; " << (sensor == 0 ? "accel " : "gyro ") << axes[a] << " spectral line"
        << (lines.size() > 1 ? "s" : "") << " at";
      for (const SpectralLine& line : lines) s << " " << LineText(line);
    }
  }
  result->message = s.str();
  return true;
}

}  // namespace gravcal
