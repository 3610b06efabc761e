// gravcal/workflows/recorder.h: guided live calibration (gravcal record).
//
// A Recorder is fed the samples of a sensor as they arrive, one at a time.
// It finds the holds with the offline static detector itself
// (detection/static_detector.h, DetectStaticIntervals) run on the samples
// since the last captured pose (at most lookback_seconds of them), every
// detect_interval_seconds of stream time: a hold is "in progress" while the
// detector's last interval reaches the newest samples (up to the window and
// settling time it trims). So live and offline detection are one code path,
// and a hold the recorder captured is one the offline detector finds.
//
// A pose is captured when its hold has lasted long enough for its
// information, not after a fixed time. With F the Fisher information of the
// poses captured so far (estimation/experiment_design.h: the magnitude
// model at the nominal sensor, each pose's row whitened by the noise its
// own samples show, or the request's noise model) and J(T) the row of the
// held direction after T seconds, the hold needed is the shortest T in
// [min_hold, max_hold] with
//
//   phi(F + J(T)^T J(T)) <= phi(F + J(T_max)^T J(T_max)) + hold_tolerance
//                            * (phi(F) - phi(F + J(T_max)^T J(T_max))),
//
// i.e. the pose has given (1 - hold_tolerance) of what holding it to
// max_hold would, or the targets are met with it. The criterion is the
// plan's target-weighted A-optimality, regularised by a broad prior so that
// it ranks designs that do not yet determine every parameter:
//
//   phi(F) = trace(W (F + W / prior_factor^2)^-1),  W = diag(1 / target_i^2).
//
// After each pose every parameter's predicted sigma is DeterminedStd(F)
// (infinite = undetermined, with the reason), and the next pose suggested
// is the candidate direction (the request's pose set) whose row most lowers
// phi, in words a person can follow. The session is done (targets_met)
// when every target is met with at least parameters + redundancy poses.
//
// Events (one JSON object per line, docs/data_contract.md "Record events"):
// pose_captured, suggest, sigma, warning and done. The recorder never
// prints, never exits and never sleeps: it is driven by the samples'
// times, so a test drives a whole session in milliseconds.
//
// Only the accelerometer's parameters are guided; the gyroscope (when the
// config calibrates one) is calibrated from the turns the hand makes.
#ifndef GRAVCAL_WORKFLOWS_RECORDER_H_
#define GRAVCAL_WORKFLOWS_RECORDER_H_

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "gravcal/core/calibration.h"
#include "gravcal/core/imu_log.h"
#include "gravcal/workflows/config.h"
#include "gravcal/workflows/plan.h"

namespace gravcal {

struct RecorderOptions {
  // Targets, pose set, noise model (not owned) or densities, pose
  // disturbance: as for gravcal plan (workflows/plan.h). Targets are needed.
  PlanRequest request;
  // How often the detector runs, seconds of stream time.
  double detect_interval_seconds = 0.5;
  // The detector sees at most this many seconds of the newest samples.
  double lookback_seconds = 60.0;
  // Shortest and longest hold the recorder asks for, seconds kept by the
  // detector.
  double min_hold_seconds = 3.0;
  double max_hold_seconds = 40.0;
  // See the top of this file.
  double hold_tolerance = 0.1;
  double prior_factor = 100.0;
  // Poses beyond the parameter count before targets_met (as plan's
  // DesignOptions::redundancy).
  int redundancy = 3;
  // > 0: stream seconds after which the session ends (done: max_time).
  double max_time_seconds = 0.0;
  // A new hold counts as a new pose only after motion, or when its up
  // direction is this far from the last captured pose, degrees.
  double new_pose_deg = 5.0;

  bool IsValid(std::string* error) const;
};

enum class RecorderEventType { kPoseCaptured, kSuggest, kSigma, kWarning, kDone };
// "pose_captured", "suggest", ...
const char* RecorderEventName(RecorderEventType type);

struct RecorderEvent {
  RecorderEventType type = RecorderEventType::kWarning;
  // Stream time of the sample that caused it, seconds.
  double t = 0.0;
  // The event as one line of JSON (no line end).
  std::string json;
  // The same in a sentence for a person.
  std::string text;
};

// A suggested next pose.
struct PoseSuggestion {
  // Sensor-frame direction to point up (unit), and the same in words: the
  // nearest face ("+Y") and a tilt toward another axis.
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  std::string face;
  double tilt_deg = 0.0;
  std::string toward;
  std::string instruction;
  double hold_seconds = 0.0;
  // Relative decrease of phi the pose brings (0..1).
  double expected_gain = 0.0;
};

// What a display shows (the terminal UI reads it after each Feed).
struct RecorderStatus {
  size_t samples = 0;
  // Samples per second over the last second of stream time.
  double sample_rate = 0.0;
  double stream_seconds = 0.0;
  bool holding = false;
  // The current hold: kept seconds so far and seconds needed.
  double hold_seconds = 0.0;
  double hold_needed_seconds = 0.0;
  // Up directions of the captured poses (sensor frame, unit).
  std::vector<Eigen::Vector3d> poses;
  std::vector<std::string> names;
  // Predicted sigma and target per parameter in readable units (mg, ppm,
  // mrad: ReadableUnitOf); sigma infinite = undetermined; target NaN = none.
  std::vector<double> sigma;
  std::vector<double> target;
  std::vector<std::string> units;
  PoseSuggestion suggestion;
  bool has_suggestion = false;
  std::vector<std::string> warnings;
  // Poses the offline plan (gravcal plan) takes for these targets at the
  // noise of the first hold; 0 until planned.
  int plan_poses = 0;
  // Lines that were not samples (the caller counts them, CountGarbage).
  size_t garbage_lines = 0;
  bool done = false;
  std::string done_reason;
};

// What Finish gives.
struct RecorderResult {
  // The recorded log as contract CSV (io/log_reader.h ImuLogToCsv).
  std::string log_csv;
  // RunCalibration on that CSV read back with the contract layout: exactly
  // what `gravcal calibrate` gives on the written log with the same
  // calibration keys. ok = it succeeded (calibration.message otherwise).
  bool ok = false;
  Calibration calibration;
  // The report of that calibration (workflows/report.h), HTML.
  std::string report_html;
  // The done event.
  RecorderEvent done;
};

class Recorder {
 public:
  Recorder();
  ~Recorder();
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  // Checks the config (its calibration and detector keys; its input layout
  // is the caller's) and the options; false with *error otherwise. The
  // first events (sigma, suggest) follow from the first Feed.
  bool Start(const Config& config, const RecorderOptions& options, std::string* error);

  // One sample: time in seconds (strictly increasing; a sample that is not
  // is dropped with a warning), raw accelerometer, raw gyroscope (has_gyro
  // false when the stream has none) and temperature (NaN = none). Returns
  // the events it caused (most samples cause none).
  std::vector<RecorderEvent> Feed(double t, const Eigen::Vector3d& accel,
                                  const Eigen::Vector3d& gyro, double temperature = NAN,
                                  bool has_gyro = true);

  // A warning from the caller (a garbage line, a stall) as an event.
  RecorderEvent Warn(const std::string& kind, const std::string& message);
  void CountGarbage();

  bool done() const;
  const RecorderStatus& status() const;
  // The samples so far.
  const ImuLog& log() const;

  // Ends the session: `reason` (targets_met when done, else end_of_input,
  // interrupted, max_time, ...), and the files it gives (named in the done
  // event as `files`). False only when there is nothing to write (no
  // sample); a failed calibration is result->ok = false with the log still
  // written.
  bool Finish(const std::string& reason, const std::vector<std::string>& files,
              RecorderResult* result, std::string* error);
  // The done event of the last Finish with other files (those actually
  // written, known only after it).
  RecorderEvent DoneEvent(const std::vector<std::string>& files) const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// The words for an up direction: "+Y up, then tilt about 45 degrees toward
// +X" (a face when within 2 degrees of one).
PoseSuggestion DescribeUp(const Eigen::Vector3d& up);

}  // namespace gravcal

#endif  // GRAVCAL_WORKFLOWS_RECORDER_H_
