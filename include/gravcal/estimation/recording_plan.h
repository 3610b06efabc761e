// gravcal/estimation/recording_plan.h: a recording plan (gravcal plan) as a
// person follows it: the poses in handling order, each with a plain
// instruction, the turns between them, and the predicted standard
// deviations (experiment_design.h).
//
// Frames: `up` is the unit vector of the sensor (housing) frame that points
// up, i.e. the direction along which the accelerometer reads +g. A turn is
// a rotation of the housing about one of its own (body-frame) axes, right
// hand rule: turning by angle t about axis a takes up from u to
// R(a, -t) u.
#ifndef GRAVCAL_ESTIMATION_RECORDING_PLAN_H_
#define GRAVCAL_ESTIMATION_RECORDING_PLAN_H_

#include <Eigen/Core>
#include <cmath>
#include <string>
#include <vector>

namespace gravcal {

struct PlannedPose {
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  double hold_seconds = 0.0;
  std::string instruction;
};

// The turn from pose `from` to pose `to` (indices into the plan's poses).
struct PlannedRotation {
  int from = 0;
  int to = 0;
  // Body-frame unit axis and angle, degrees (the shortest turn, or the one
  // the gyroscope design chose).
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();
  double angle_deg = 0.0;
  // Suggested duration of the turn, seconds (0 = not planned for the
  // gyroscope).
  double seconds = 0.0;
  std::string instruction;
};

// A fixed scheme judged on the same noise and targets.
struct SchemeComparison {
  std::string name;
  int poses = 0;
  // The common hold that meets the targets (NaN when none does) and the total
  // time at it.
  double hold_seconds = 0.0;
  double total_seconds = 0.0;
  bool meets_targets = false;
  // Predicted standard deviations (calibration JSON units) at that hold, or
  // at the longest hold tried when none meets the targets; infinity =
  // undetermined.
  Eigen::VectorXd predicted_std;
};

// One sensor's predicted standard deviations in a plan: the accelerometer's
// (names and units of the calibration JSON's accel covariance: bias raw
// units, U m/s^2 per raw unit at nominal_scale; scale-free: bias m/s^2, U
// relative) or the gyroscope's (its gyro covariance: bias raw units, M_g
// rad/s per raw unit at nominal_scale; scale-free: rad/s, relative).
struct SensorPrediction {
  // Names and order of the vectors below; empty when the sensor is not
  // planned.
  std::vector<std::string> parameter_names;
  // Calibration JSON units at nominal_scale, and scale-free.
  Eigen::VectorXd predicted_std;
  Eigen::VectorXd predicted_std_scale_free;
  // Scale-free targets; `targeted` marks the ones the user set (the others
  // are the calibration's limits of a determined parameter).
  Eigen::VectorXd targets_scale_free;
  std::vector<bool> targeted;
  double nominal_scale = 1.0;
};

struct RecordingPlan {
  // The accelerometer.
  SensorPrediction accel;
  double gravity = 9.80665;
  double overhead_seconds = 0.0;
  double total_seconds = 0.0;
  bool meets_targets = false;
  std::string criterion;
  std::string pose_set;
  std::string noise_source;
  std::vector<PlannedPose> poses;
  std::vector<PlannedRotation> rotations;
  // Judged on the accelerometer (predicted_std in accel's units).
  std::vector<SchemeComparison> schemes;
  // The gyroscope (experiment_design.h), empty names when not planned, and
  // the poses appended for it alone (the last gyro_extra_poses of `poses`).
  SensorPrediction gyro;
  int gyro_extra_poses = 0;
  std::string message;
};

// What a recorded session determines (gravcal check): per parameter the
// predicted standard deviation from the poses actually recorded, what is
// undetermined or short of its target, and the extra poses that would
// help most.
struct CoverageReport {
  // The accelerometer's prediction from the poses recorded; infinity =
  // undetermined.
  SensorPrediction accel;
  int positions = 0;
  // Parameters the poses do not determine (a null direction, or a standard
  // deviation beyond the refinement's limits), and stated targets not met.
  std::vector<std::string> undetermined;
  std::vector<std::string> short_of_target;
  // The extra poses, in order, and the scale-free standard deviations with
  // them added.
  std::vector<PlannedPose> proposed;
  Eigen::VectorXd predicted_std_with_proposed;
  std::vector<std::string> undetermined_with_proposed;
  // Issue 35: what the temperature span allows the thermal method (its
  // orders, thermal_calibration.h ThermalSpanMessages) and the span itself,
  // degrees C (NaN: no temperature column, or another method).
  std::vector<std::string> temperature;
  double temperature_span = NAN;
  std::string message;
};

// The unit a person reads a parameter's scale-free standard deviation in
// (bias_*: "mg"; u_xx, u_yy, u_zz: "ppm"; other u_*: "mrad") and the factor
// from scale-free (m/s^2, relative) to it.
struct ReadableUnit {
  std::string unit;
  double factor = 1.0;
};
ReadableUnit ReadableUnitOf(const std::string& parameter);
// The same for a gyroscope parameter (scale-free rad/s, relative): bias_*
// "deg/h"; m_xx, m_yy, m_zz, scale "ppm"; other m_* "mrad".
ReadableUnit GyroReadableUnitOf(const std::string& parameter);

// The yardstick when no target is stated (scale-free): 1 mg for a bias,
// 100 ppm for a scale, 0.1 mrad for a non-orthogonality.
double ReferenceStd(const std::string& parameter);

// "x axis up", "z axis down", or each axis's angle above level.
std::string PoseInstruction(const Eigen::Vector3d& up);

// The shortest turn taking up direction `from` to `to` (about a housing axis
// when the two are opposite), with its instruction.
PlannedRotation TurnBetween(const Eigen::Vector3d& from, const Eigen::Vector3d& to);

// A turn about the body axis `axis` by angle_deg over `seconds` (0 = no
// duration stated), with its instruction.
PlannedRotation TurnAbout(const Eigen::Vector3d& axis, double angle_deg, double seconds);

// Orders poses for handling: starting from the one nearest z up, each next
// pose is the nearest remaining (smallest turn); fills plan->rotations.
void OrderForHandling(std::vector<PlannedPose> poses, RecordingPlan* plan);

}  // namespace gravcal

#endif  // GRAVCAL_ESTIMATION_RECORDING_PLAN_H_
