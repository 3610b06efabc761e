// gravcal/workflows/plan.h: planning a recording before it is made
// (gravcal plan) and saying what a recorded one lacks (gravcal check).
//
// The maths is estimation/experiment_design.h (Fisher information of the
// magnitude model at the nominal sensor, target-weighted A-optimal design);
// this layer reads the request (targets in the user's units, the candidate
// set, the noise from noise.json or datasheet densities), compares the
// seed's schemes, and orders the poses for a person to follow
// (estimation/recording_plan.h).
//
// With a gyroscope (the config's gyro_model, or gyroscope targets) the
// turns between the poses are chosen for the gyroscope-between-poses model
// by the same criterion (experiment_design.h, DesignRotations), and extra
// poses appended when its targets need them.
#ifndef GRAVCAL_WORKFLOWS_PLAN_H_
#define GRAVCAL_WORKFLOWS_PLAN_H_

#include <Eigen/Core>
#include <string>

#include "gravcal/core/imu_log.h"
#include "gravcal/core/noise_model.h"
#include "gravcal/estimation/experiment_design.h"
#include "gravcal/estimation/recording_plan.h"
#include "gravcal/methods/session.h"
#include "gravcal/workflows/config.h"

namespace gravcal {

struct PlanRequest {
  // "accel_bias=0.5mg accel_scale=50ppm accel_misalignment=0.1mrad": group
  // names (accel_bias: bias_x..z, accel_scale: u_xx u_yy u_zz,
  // accel_misalignment: u_xy u_xz u_yz) or parameter names, each with a
  // unit: mg, ug, m/s^2 for a bias; ppm, %, mrad, urad, rad, deg for U.
  // Gyroscope: gyro_bias (bias_x..z; deg/h, deg/s, rad/s), gyro_scale
  // (m_xx m_yy m_zz, or scale; ppm, %), gyro_misalignment (the other m_*;
  // mrad, urad, rad, deg), or gyro_<name> for one parameter (gyro_m_xy).
  std::string targets;
  // The candidate poses (core/types.h, experiment_design.h); written
  // faces, faces+45 or free in flags, Python and plan.json.
  PoseSet pose_set = PoseSet::kFacesAnd45;
  // Directions of the free set besides faces+45.
  int free_candidates = 500;
  // > 0: the total time may not exceed this, seconds.
  double max_time_seconds = 0.0;
  // Seconds to move and settle the housing before each pose.
  double overhead_seconds = 10.0;
  double min_hold_seconds = 5.0;
  double max_hold_seconds = 600.0;
  int max_poses = 40;
  // The noise: the model of `gravcal noise` (SI, not owned) when set, else
  // the datasheet densities below (accel_noise_density required).
  const ImuNoiseModel* noise_model = nullptr;
  // m/s^2/sqrt(Hz), m/s^2, m/s^3/sqrt(Hz) (core/noise_model.h's N, B, K).
  double accel_noise_density = 0.0;
  double accel_bias_instability = 0.0;
  double accel_random_walk = 0.0;
  // Per-pose disturbance of |a|, m/s^2 rms; 0 = none.
  double pose_disturbance = 0.0;
  // Gyroscope white-noise density, rad/s/sqrt(Hz), when no noise model
  // gives one; and its bias instability (rad/s) and random walk.
  double gyro_noise_density = 0.0;
  double gyro_bias_instability = 0.0;
  double gyro_random_walk = 0.0;
  // The known-attitude model (method known_attitude): the fixture's
  // attitude standard deviation, degrees.
  double attitude_std_deg = 0.0;
  // Seconds a half turn takes (shorter turns proportionally less, at least
  // half of it).
  double turn_seconds = 3.0;
  // Extra poses `check` proposes when every parameter is determined (as many
  // as there are undetermined directions otherwise).
  int extra_poses = 2;

  bool IsValid(std::string* error) const;
};

// Parses `text` (above) into scale-free targets per parameter of `model`
// (DesignParameterNames order; NaN = none stated) and, when gyro_targets
// is not null, of `gp` (GyroDesignParameterNames order). Errors name every
// unknown name (gyroscope names too when gyro_targets is null), or the
// entry with a bad value or unit.
bool ParsePlanTargets(const std::string& text, const DesignModel& model, Eigen::VectorXd* targets,
                      std::string* error, GyroParameterization gp = GyroParameterization::kFull,
                      Eigen::VectorXd* gyro_targets = nullptr);

// The noise of the request; *source says where it came from.
bool PlanDesignNoise(const PlanRequest& request, DesignNoise* noise, std::string* source,
                     std::string* error);

// The design model of a config: its parameterisation and gravity, the
// seconds of a hold its static detector does not keep, and the
// known-attitude model when the config's method is known_attitude.
bool PlanDesignModel(const Config& config, DesignModel* model, std::string* error);

// The plan. Returns false with *error (and *plan untouched) on bad input,
// targets that cannot be met within max_time (the message says what is
// achievable within it and how long meeting them would take), or targets no
// design within the limits meets.
bool MakeRecordingPlan(const Config& config, const PlanRequest& request, RecordingPlan* plan,
                       std::string* error);

// What `log` determines: its poses found by the config's static detector,
// each weighted by its own pose-mean covariance (or the request's noise
// model when one is given), at the nominal sensor of the data's own scale
// (g / median |raw mean|). Proposed extra poses come from the request's
// pose set, held the median recorded hold. False with *error on bad input.
bool CheckRecording(const ImuLog& log, const Config& config, const PlanRequest& request,
                    CoverageReport* report, std::string* error);

// The same on a session: its static detection when it has one (the one the
// calibration used, pipeline.h), else detected now.
bool CheckRecording(const Session& session, const Config& config, const PlanRequest& request,
                    CoverageReport* report, std::string* error);

// A few lines for a person: per parameter the predicted sigma (readable
// units), target and verdict, then the proposed poses.
std::string CoverageReportText(const CoverageReport& report);

}  // namespace gravcal

#endif  // GRAVCAL_WORKFLOWS_PLAN_H_
