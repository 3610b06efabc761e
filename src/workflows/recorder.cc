// gravcal record's core (workflows/recorder.h): the sample loop, live
// detection, capture and the events; the pose design (prediction,
// suggestion) is in recorder_design.cc, the state in recorder_state.h.
#include "gravcal/workflows/recorder.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <sstream>

#include "gravcal/detection/static_detector.h"
#include "gravcal/estimation/experiment_design.h"
#include "gravcal/io/log_reader.h"
#include "gravcal/workflows/pipeline.h"
#include "gravcal/workflows/report.h"
#include "io/json_helpers.h"
#include "util/numbers.h"
#include "util/statistics.h"
#include "util/units.h"
#include "workflows/plan_start.h"
#include "workflows/recorder_state.h"

namespace gravcal {

namespace {

using internal::JsonNumber;
using internal::JsonVector;
using internal::kDegToRad;
using internal::kInf;
using internal::kRadToDeg;
using Json = nlohmann::json;

using internal::CapturedPose;
using internal::kFaceSnapDeg;
// Warnings of one kind after which the rest are only counted.
constexpr int kMaxWarningsPerKind = 5;

std::string Num(double v, int digits = 3) {
  std::ostringstream s;
  s.precision(digits);
  s << v;
  return s.str();
}

}  // namespace

bool RecorderOptions::IsValid(std::string* error) const {
  std::string e;
  if (!request.IsValid(&e)) {
  } else if (!(detect_interval_seconds > 0.0)) {
    e = "detect_interval_seconds must be positive";
  } else if (!(lookback_seconds >= 10.0)) {
    e = "lookback_seconds must be at least 10";
  } else if (!(min_hold_seconds > 0.0) || !(max_hold_seconds >= min_hold_seconds)) {
    e = "holds: need 0 < min_hold_seconds <= max_hold_seconds";
  } else if (!(hold_tolerance > 0.0 && hold_tolerance < 1.0)) {
    e = "hold_tolerance must be in (0, 1)";
  } else if (!(prior_factor > 1.0)) {
    e = "prior_factor must be above 1";
  } else if (redundancy < 0) {
    e = "redundancy must not be negative";
  } else if (!(max_time_seconds >= 0.0)) {
    e = "max_time_seconds must not be negative";
  } else if (!(new_pose_deg > 0.0)) {
    e = "new_pose_deg must be positive";
  } else {
    return true;
  }
  if (error) *error = e;
  return false;
}

const char* RecorderEventName(RecorderEventType type) {
  switch (type) {
    case RecorderEventType::kPoseCaptured:
      return "pose_captured";
    case RecorderEventType::kSuggest:
      return "suggest";
    case RecorderEventType::kSigma:
      return "sigma";
    case RecorderEventType::kWarning:
      return "warning";
    case RecorderEventType::kDone:
      return "done";
  }
  return "warning";
}

Recorder::Recorder() : state_(new State) {}
Recorder::~Recorder() = default;

bool Recorder::Start(const Config& config, const RecorderOptions& options, std::string* error) {
  state_.reset(new State);
  State& s = *state_;
  if (!options.IsValid(error)) return false;
  if (!config.calibration.detector.IsValid(error)) return false;
  s.config = config;
  s.options = options;
  if (!internal::StartPlan(config, options.request, &s.start, error)) return false;
  if (s.start.model.known_attitude) {
    *error = std::string("record guides the magnitude model; method ") + ToString(config.method) +
             " needs fixture attitudes";
    return false;
  }
  if (std::none_of(s.start.targeted.begin(), s.start.targeted.end(), [](bool t) { return t; })) {
    *error = "record needs --target (e.g. accel_bias=0.5mg accel_scale=100ppm)";
    return false;
  }
  s.given_noise =
      options.request.noise_model != nullptr || options.request.accel_noise_density > 0.0;
  if (s.given_noise) {
    std::string source;
    if (!PlanDesignNoise(options.request, &s.noise, &source, error)) return false;
  }
  s.noise.pose_disturbance = options.request.pose_disturbance;
  CandidateDirections(options.request.pose_set, options.request.free_candidates, &s.candidates);
  s.p = static_cast<Eigen::Index>(s.start.names.size());
  s.weight = s.start.targets.cwiseInverse().cwiseAbs2();
  s.prior = (s.weight / (options.prior_factor * options.prior_factor)).asDiagonal();
  s.fisher = Eigen::MatrixXd::Zero(s.p, s.p);
  s.log.source = "record";
  s.status.names = s.start.names;
  for (Eigen::Index i = 0; i < s.p; ++i) {
    const ReadableUnit u = ReadableUnitOf(s.start.names[i]);
    s.status.units.push_back(u.unit);
    s.status.target.push_back(s.start.targeted[i] ? s.start.targets(i) * u.factor : NAN);
    s.status.sigma.push_back(kInf);
  }
  s.started = true;
  return true;
}

bool Recorder::done() const { return state_->status.done; }
const RecorderStatus& Recorder::status() const { return state_->status; }
const ImuLog& Recorder::log() const { return state_->log; }
void Recorder::CountGarbage() { ++state_->status.garbage_lines; }

namespace {

RecorderEvent MakeEvent(RecorderEventType type, double t, Json body, const std::string& text) {
  RecorderEvent e;
  e.type = type;
  e.t = t;
  Json j;
  j["event"] = RecorderEventName(type);
  j["t"] = JsonNumber(t);
  for (auto it = body.begin(); it != body.end(); ++it) j[it.key()] = it.value();
  e.json = j.dump();
  e.text = text;
  return e;
}

}  // namespace

RecorderEvent Recorder::Warn(const std::string& kind, const std::string& message) {
  State& s = *state_;
  const double t = s.log.t.empty() ? 0.0 : s.log.t.back();
  s.status.warnings.push_back(message);
  if (s.status.warnings.size() > 20) s.status.warnings.erase(s.status.warnings.begin());
  return MakeEvent(RecorderEventType::kWarning, t, {{"kind", kind}, {"message", message}},
                   "warning: " + message);
}

std::vector<RecorderEvent> Recorder::Feed(double t, const Eigen::Vector3d& accel,
                                          const Eigen::Vector3d& gyro, double temperature,
                                          bool has_gyro) {
  std::vector<RecorderEvent> events;
  State& s = *state_;
  if (!s.started || s.status.done) return events;
  ImuLog& log = s.log;
  auto warn = [&](const std::string& kind, const std::string& message) {
    if (++s.warning_counts[kind] <= kMaxWarningsPerKind) events.push_back(Warn(kind, message));
  };
  if (!std::isfinite(t) || !accel.allFinite() || (has_gyro && !gyro.allFinite())) {
    warn("bad_sample", "a sample with a value that is not finite was dropped");
    return events;
  }
  if (log.size() == 0) {
    s.has_gyro = has_gyro;
    s.has_temperature = std::isfinite(temperature);
    s.next_detect_t = t + s.options.detect_interval_seconds;
  } else if (!(t > log.t.back())) {
    warn("time", "a sample at t = " + Num(t, 10) + " s, not after the previous one (" +
                     Num(log.t.back(), 10) + " s), was dropped");
    return events;
  }
  log.t.push_back(t);
  log.accel.push_back(accel);
  s.accel_max = log.size() == 1 ? accel : s.accel_max.cwiseMax(accel);
  s.accel_min = log.size() == 1 ? accel : s.accel_min.cwiseMin(accel);
  if (s.has_gyro) log.gyro.push_back(has_gyro ? gyro : Eigen::Vector3d::Zero());
  if (s.has_temperature) log.temperature.push_back(temperature);
  RecorderStatus& st = s.status;
  st.samples = log.size();
  st.stream_seconds = t - log.t.front();
  {
    const auto it = std::lower_bound(log.t.begin(), log.t.end(), t - 1.0);
    const double span = t - *it;
    const double n = static_cast<double>(log.t.end() - it) - 1.0;
    st.sample_rate = span > 0.0 ? n / span : 0.0;
  }
  if (!s.sent_first) {
    s.sent_first = true;
    const Eigen::Vector3d unit_density = Eigen::Vector3d::Constant(0.01);
    st.suggestion = s.Suggest(unit_density);
    st.has_suggestion = true;
  }
  if (s.options.max_time_seconds > 0.0 && st.stream_seconds >= s.options.max_time_seconds) {
    st.done = true;
    st.done_reason = "max_time";
    return events;
  }
  if (t < s.next_detect_t) return events;
  s.next_detect_t = t + s.options.detect_interval_seconds;

  // The detector on the samples since the last pose (at most lookback).
  const size_t n = log.size();
  size_t from = s.detect_from;
  while (from < n && log.t[from] < t - s.options.lookback_seconds) ++from;
  const StaticDetectorOptions& detector = s.config.calibration.detector;
  if (n - from < 3 || log.t[n - 1] - log.t[from] < 2.0 * detector.window_seconds) return events;
  ImuLog tail;
  tail.source = "record";
  tail.t.assign(log.t.begin() + from, log.t.end());
  tail.accel.assign(log.accel.begin() + from, log.accel.end());
  if (s.has_gyro) tail.gyro.assign(log.gyro.begin() + from, log.gyro.end());
  StaticDetection detection;
  st.holding = false;
  if (!DetectStaticIntervals(tail, detector, &detection)) return events;
  // In progress: the last interval reaches the newest samples up to what
  // the detector trims at an end.
  const double reach = detector.window_seconds + detector.settle_seconds + 0.25;
  for (const RejectedStretch& r : detection.rejected) {
    if (r.reason == RejectionReason::kTooShort || t - r.t_end > reach) continue;
    // One warning per stretch: a stretch that began before the end of the
    // last one warned about is that one, seen again.
    const bool fresh = from + r.begin > s.moving_warned_until || s.moving_warned_until == 0;
    s.moving_warned_until = std::max(s.moving_warned_until, from + r.end);
    if (fresh) {
      warn("moving_hold", "the unit is not still (since t = " + Num(r.t_begin, 6) +
                              " s): " + r.detail + "; hold it still, or rest it on a table");
    }
  }
  if (detection.intervals.empty()) return events;
  const StaticInterval& last = detection.intervals.back();
  if (t - last.t_end > reach) return events;
  const size_t begin = from + last.begin;
  const size_t end = from + last.end;
  const Eigen::Vector3d raw_up = last.accel_mean.normalized();
  // A new pose only after motion or a new direction.
  if (!s.poses.empty()) {
    const CapturedPose& prev = s.poses.back();
    const double rate =
        static_cast<double>(last.count()) / std::max(last.t_end - last.t_begin, 1e-9);
    const bool moved = begin > prev.end + static_cast<size_t>(detector.window_seconds * rate);
    const double angle =
        std::acos(std::clamp(raw_up.dot(prev.raw_mean.normalized()), -1.0, 1.0)) * kRadToDeg;
    if (!moved && angle < s.options.new_pose_deg) return events;
  }
  if (s.refused_holds.count(begin)) return events;
  // Saturation: at least half the hold's samples of an axis sit at one
  // value, the largest (or smallest) that axis has shown in the stream: a
  // signal with noise does not pile up at its extreme, a clipped one does.
  for (int a = 0; a < 3; ++a) {
    for (const double sign : {1.0, -1.0}) {
      const double limit = sign > 0.0 ? s.accel_max(a) : s.accel_min(a);
      size_t at_limit = 0;
      for (size_t i = begin; i < end; ++i) at_limit += log.accel[i](a) == limit;
      if (at_limit < 3 || 2 * at_limit < end - begin) continue;
      s.refused_holds.insert(begin);
      static const char* kAxes = "xyz";
      warn("saturation", "the hold at t = " + Num(last.t_begin, 6) +
                             " s is not used: the accelerometer's " + kAxes[a] + " axis sits at " +
                             Num(limit, 10) + " (its " + (sign > 0.0 ? "largest" : "smallest") +
                             " value so far) in " + std::to_string(at_limit) + " of " +
                             std::to_string(end - begin) +
                             " samples: it is saturated; use a wider range or another pose");
      return events;
    }
  }
  // The hold's direction (a face within kFaceSnapDeg) and noise.
  if (!(s.scale > 0.0)) s.scale = s.start.model.gravity / last.accel_mean.norm();
  Eigen::Vector3d up = raw_up;
  Eigen::Index axis = 0;
  up.cwiseAbs().maxCoeff(&axis);
  if (std::abs(up(axis)) > std::cos(kFaceSnapDeg * kDegToRad)) {
    up = Eigen::Vector3d::Unit(axis) * (up(axis) > 0.0 ? 1.0 : -1.0);
  }
  const double kept = last.t_end - last.t_begin;
  const double dt = kept / std::max<double>(1.0, static_cast<double>(last.count()) - 1.0);
  Eigen::Vector3d density;
  for (int a = 0; a < 3; ++a) {
    density(a) = std::sqrt(std::max(last.accel_cov(a, a), 0.0) * dt) * s.scale;
  }
  // Batch means (ten batches) when they show more than white noise.
  if (last.count() >= 100) {
    const size_t batch = last.count() / 10;
    std::vector<Eigen::Vector3d> means;
    for (size_t b = 0; b < 10; ++b) {
      Eigen::Vector3d m = Eigen::Vector3d::Zero();
      for (size_t i = 0; i < batch; ++i) m += log.accel[begin + b * batch + i];
      means.push_back(m / static_cast<double>(batch));
    }
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& m : means) mean += m / 10.0;
    for (int a = 0; a < 3; ++a) {
      double v = 0.0;
      for (const Eigen::Vector3d& m : means) v += (m(a) - mean(a)) * (m(a) - mean(a)) / 9.0;
      // Variance of one batch mean times its duration.
      const double d = std::sqrt(v * static_cast<double>(batch) * dt) * s.scale;
      density(a) = std::max(density(a), d);
    }
  }
  if (!(s.plan_hold > 0.0)) {
    s.Plan(density);
    st.plan_poses = s.plan_poses;
  }
  st.holding = true;
  st.hold_seconds = kept;
  st.hold_needed_seconds = s.NeededHold(up, density);
  if (kept < st.hold_needed_seconds) return events;

  // Capture.
  CapturedPose pose;
  pose.up = up;
  pose.raw_mean = last.accel_mean;
  pose.kept_seconds = kept;
  pose.begin = begin;
  pose.end = end;
  pose.density = density;
  const Eigen::RowVectorXd row = s.Row(up, kept, density);
  s.fisher += row.transpose() * row;
  s.poses.push_back(pose);
  s.detect_from = end;
  st.holding = false;
  st.poses.push_back(up);
  const PoseSuggestion words = DescribeUp(raw_up);
  events.push_back(MakeEvent(RecorderEventType::kPoseCaptured, t,
                             {{"index", s.poses.size() - 1},
                              {"up", JsonVector(raw_up)},
                              {"up_words", words.instruction},
                              {"t_begin", JsonNumber(last.t_begin)},
                              {"duration", JsonNumber(kept)},
                              {"samples", last.count()}},
                             "pose " + std::to_string(s.poses.size()) +
                                 " captured: " + words.instruction + ", " + Num(kept) + " s, " +
                                 std::to_string(last.count()) + " samples"));

  // Sigmas.
  const Eigen::VectorXd std = DeterminedStd(s.fisher, s.start.limits);
  const std::map<std::string, std::string> reasons = s.Reasons(std);
  Json params = Json::array();
  std::vector<std::string> short_of_target;
  for (Eigen::Index i = 0; i < s.p; ++i) {
    const std::string& name = s.start.names[i];
    const ReadableUnit u = ReadableUnitOf(name);
    st.sigma[i] = std(i) * u.factor;
    Json j = {
        {"name", name},
        {"unit", u.unit},
        {"sigma", JsonNumber(std(i) * u.factor)},
        {"target", s.start.targeted[i] ? JsonNumber(s.start.targets(i) * u.factor) : Json(nullptr)},
        {"determined", std::isfinite(std(i))}};
    if (reasons.count(name)) j["reason"] = reasons.at(name);
    if (s.start.targeted[i] && !(std(i) <= s.start.targets(i))) short_of_target.push_back(name);
    params.push_back(j);
  }
  const bool met = s.TargetsMet(s.fisher, static_cast<int>(s.poses.size()));
  std::string text = "sigma: " + std::to_string(reasons.size()) + " undetermined, " +
                     std::to_string(short_of_target.size()) + " short of target";
  if (!met && short_of_target.empty()) {
    text += " (" + std::to_string(s.p + s.options.redundancy - s.poses.size()) +
            " more pose(s) for redundancy)";
  }
  events.push_back(MakeEvent(RecorderEventType::kSigma, t,
                             {{"poses", s.poses.size()},
                              {"plan_poses", s.plan_poses},
                              {"parameters", params},
                              {"undetermined", reasons.size()},
                              {"short_of_target", short_of_target},
                              {"targets_met", met}},
                             text));
  if (met) {
    st.done = true;
    st.done_reason = "targets_met";
    st.has_suggestion = false;
    return events;
  }
  const PoseSuggestion next = s.Suggest(s.TypicalDensity(density));
  st.suggestion = next;
  st.has_suggestion = true;
  events.push_back(
      MakeEvent(RecorderEventType::kSuggest, t,
                {{"up", JsonVector(next.up)},
                 {"face", next.face},
                 {"tilt_deg", JsonNumber(next.tilt_deg)},
                 {"toward", next.toward},
                 {"hold_seconds", JsonNumber(next.hold_seconds)},
                 {"expected_gain", JsonNumber(next.expected_gain)},
                 {"instruction", next.instruction}},
                "next: " + next.instruction + ", hold " + Num(next.hold_seconds, 2) + " s"));
  return events;
}

bool Recorder::Finish(const std::string& reason, const std::vector<std::string>& files,
                      RecorderResult* result, std::string* error) {
  State& s = *state_;
  if (s.log.size() == 0) {
    *error = "record: no sample was received";
    return false;
  }
  RecorderResult out;
  if (!ImuLogToCsv(s.log, &out.log_csv, error)) return false;
  // The calibration of the CSV read back, with the contract layout: what
  // calibrate gives on the written log.
  Config config = s.config;
  config.input = LogReaderOptions();
  Session session;
  if (!ParseImuLog(out.log_csv, "record.csv", config.input, &session.log, error)) return false;
  out.ok = RunCalibration(config, SessionFiles(), &session, &out.calibration);
  out.report_html =
      !out.calibration.positions.empty() && session.detection_ok
          ? CalibrationToHtml(out.calibration, session.log, "record.csv", session.detection)
          : CalibrationToHtml(out.calibration, session.log, "record.csv");
  const Eigen::VectorXd std = DeterminedStd(s.fisher, s.start.limits);
  const std::map<std::string, std::string> reasons = s.Reasons(std);
  Json undetermined = Json::array();
  for (const auto& [name, why] : reasons) undetermined.push_back({{"name", name}, {"reason", why}});
  Json body = {{"reason", reason},
               {"files", files},
               {"poses", s.poses.size()},
               {"samples", s.log.size()},
               {"garbage_lines", s.status.garbage_lines},
               {"undetermined", undetermined},
               {"calibration_ok", out.ok},
               {"calibration_message", out.calibration.message}};
  std::string text = "done: " + reason + "; " + std::to_string(s.poses.size()) + " poses, " +
                     std::to_string(s.log.size()) + " samples";
  if (!reasons.empty())
    text += "; " + std::to_string(reasons.size()) + " parameter(s) undetermined";
  s.done_body = body;
  s.done_text = text;
  out.done = MakeEvent(RecorderEventType::kDone, s.log.t.back(), body, text);
  s.status.done = true;
  s.status.done_reason = reason;
  *result = std::move(out);
  return true;
}

RecorderEvent Recorder::DoneEvent(const std::vector<std::string>& files) const {
  const State& s = *state_;
  Json body = s.done_body;
  body["files"] = files;
  return MakeEvent(RecorderEventType::kDone, s.log.t.empty() ? 0.0 : s.log.t.back(), body,
                   s.done_text);
}

}  // namespace gravcal
