// workflows/recorder_state.h (private): the state of gravcal record's
// Recorder (workflows/recorder.h) between samples. Its design methods (the
// information of a pose, the next pose and its hold, why a parameter is
// undetermined) are in recorder_design.cc; the sample loop, capture and
// events in recorder.cc.
#ifndef GRAVCAL_SRC_WORKFLOWS_RECORDER_STATE_H_
#define GRAVCAL_SRC_WORKFLOWS_RECORDER_STATE_H_

#include <Eigen/Core>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "gravcal/estimation/experiment_design.h"
#include "gravcal/workflows/recorder.h"
#include "workflows/plan_start.h"

namespace gravcal {
namespace internal {

// One captured hold.
struct CapturedPose {
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d raw_mean = Eigen::Vector3d::Zero();
  double kept_seconds = 0.0;
  size_t begin = 0;
  size_t end = 0;
  // Scale-free white-noise density per axis, m/s^2/sqrt(Hz).
  Eigen::Vector3d density = Eigen::Vector3d::Zero();
};

}  // namespace internal

struct Recorder::State {
  Config config;
  RecorderOptions options;
  internal::PlanStart start;
  // Parameters, weights W = 1 / target^2 and the prior information.
  Eigen::Index p = 0;
  Eigen::VectorXd weight;
  Eigen::MatrixXd prior;
  std::vector<Eigen::Vector3d> candidates;
  // The request's noise (noise model or densities) when it gives one.
  bool given_noise = false;
  DesignNoise noise;

  ImuLog log;
  bool started = false;
  bool has_gyro = false;
  bool has_temperature = false;
  double next_detect_t = 0.0;
  // Detection starts here (the end of the last captured pose).
  size_t detect_from = 0;
  // Nominal scale (m/s^2 per raw unit), from the first hold.
  double scale = 0.0;
  std::vector<internal::CapturedPose> poses;
  Eigen::MatrixXd fisher;
  // The largest and smallest raw accelerometer values so far.
  Eigen::Vector3d accel_max = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_min = Eigen::Vector3d::Zero();
  // Holds not captured (saturated), by their first sample.
  std::set<size_t> refused_holds;
  std::map<std::string, int> warning_counts;
  // The end (sample index) of the last moving stretch warned about.
  size_t moving_warned_until = 0;
  RecorderStatus status;
  bool sent_first = false;
  // The offline plan's typical kept hold (for the measured noise), the
  // shortest hold asked for while a parameter is undetermined; 0 = not
  // planned yet.
  double plan_hold = 0.0;
  int plan_poses = 0;
  // The done event's body and sentence (Finish).
  nlohmann::json done_body;
  std::string done_text;

  // Rows of the information.
  Eigen::RowVectorXd Row(const Eigen::Vector3d& up, double kept_seconds,
                         const Eigen::Vector3d& density) const;
  // The design criterion: the weighted trace of the covariance of the
  // information f with the prior.
  double Phi(const Eigen::MatrixXd& f) const;
  // True when `pose_count` poses (at least p + redundancy) give every
  // targeted parameter its target with the information f.
  bool TargetsMet(const Eigen::MatrixXd& f, int pose_count) const;
  // The typical density of the poses so far (median per axis), or of
  // `fallback` before any.
  Eigen::Vector3d TypicalDensity(const Eigen::Vector3d& fallback) const;
  // The shortest kept hold of `up` that gives (1 - hold_tolerance) of what
  // max_hold would, or meets the targets.
  double NeededHold(const Eigen::Vector3d& up, const Eigen::Vector3d& density) const;
  // The candidate that lowers phi most (ties: the nearest +Z up).
  PoseSuggestion Suggest(const Eigen::Vector3d& density) const;
  // The offline plan for the noise of the first hold (or the request's):
  // its median hold, less what the detector trims.
  void Plan(const Eigen::Vector3d& density);
  // Why each undetermined parameter is: the parameters a null direction of
  // the information mixes it with, and the up directions seen so far.
  std::map<std::string, std::string> Reasons(const Eigen::VectorXd& std) const;
};

}  // namespace gravcal

#endif  // GRAVCAL_SRC_WORKFLOWS_RECORDER_STATE_H_
