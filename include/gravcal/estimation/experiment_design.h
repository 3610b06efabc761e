// gravcal/estimation/experiment_design.h: the Fisher information of the
// magnitude model for poses not yet recorded, and the optimal design of a
// recording (which orientations, how long each).
//
// The model and its parameters are those of the refinement (refinement.h):
// r_k = |U (v_k - b)| - g, parameters (b, free entries of U). A design is
// judged at the nominal sensor, b = 0 and U = s I (s = nominal scale, m/s^2
// per raw unit), where a pose whose sensor-frame up direction is the unit
// vector n has the raw mean v = g n / s. Its whitened Jacobian row is the
// refinement's own (MagnitudeJacobian) at that mean,
//
//   J_k = [ -s n^T ,  (n_r v_c) for the free (r, c) of U ] / sigma_k,
//   sigma_k^2 = sum_i n_i^2 V_i(T_k) + d^2,
//
// V_i(T) the variance of a still mean of T seconds on axis i (core/
// noise_model.h, StillMeanVariance: the Allan variance at tau = T, white
// noise, bias instability, random walk and quantisation as the model
// shows them), T_k the part of the hold the static detector keeps, and d the
// per-pose disturbance of |a| (m/s^2 rms), 0 unless stated. The Fisher
// information is F = sum_k J_k^T J_k and the predicted covariance F^-1:
// the Cramer-Rao bound, which is also what the refinement reports
// ((J^T J)^-1 at the optimum) when the noise model is right.
//
// Designs are computed in the scale-free units of the refinement's
// normalisation (s = 1: bias in m/s^2, U relative to the scale); the
// calibration JSON's units (bias in raw units, U in m/s^2 per raw unit)
// follow by b_raw = b / s, U = s U_rel.
//
// Criterion (DesignPoses): target-weighted A-optimality,
//   phi = trace(W F^-1),  W = diag(1 / target_i^2),
// i.e. the sum of (sigma_i / target_i)^2. The user states a target per
// parameter in its own unit; D-optimality (det F) would ignore those
// targets and the parameters' units, plain A-optimality would add
// variances of different units. With targets as weights every term is
// dimensionless and the design spends its time where a target is far from
// met; feasibility is max_i sigma_i / target_i <= 1, checked after.
#ifndef GRAVCAL_ESTIMATION_EXPERIMENT_DESIGN_H_
#define GRAVCAL_ESTIMATION_EXPERIMENT_DESIGN_H_

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "gravcal/core/noise_model.h"
#include "gravcal/core/types.h"

namespace gravcal {

// The noise a design is judged against (SI): the accelerometer's, and the
// gyroscope's (rad/s) when rotations are planned.
struct DesignNoise {
  std::array<AxisNoiseModel, 3> accel;
  std::array<AxisNoiseModel, 3> gyro;
  // Per-pose disturbance of |a| the samples cannot show, m/s^2 rms. 0 = none.
  double pose_disturbance = 0.0;
};

// White noise of density N (m/s^2/sqrt(Hz)) on every axis, nothing else.
DesignNoise WhiteDesignNoise(double density);

// One pose of a design: the sensor-frame direction that points up (unit)
// and the seconds it is held still.
struct DesignPose {
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  double hold_seconds = 10.0;
};

struct DesignModel {
  AccelParameterization parameterization = AccelParameterization::kScaleMisalignment;
  // The known-attitude model instead (methods/known_attitude.h): the
  // fixture gives each pose's roll and pitch (standard deviation
  // attitude_std, rad), so gravity in the body frame, g n, is a reference and
  // every entry of a = M (v - b) is determined, parameters bias_x..z, m_xx,
  // m_xy, ..., m_zz (row-major). Linear in them given the attitudes: three
  // rows per pose, r = M (v - b) - g n, whitened by
  //   Sigma_k = diag(V_a(T_k)) + d^2 I + g^2 s^2 (A_roll A_roll^T + A_pitch A_pitch^T),
  // A = dn/d(roll), dn/d(pitch). `parameterization` is not used then.
  bool known_attitude = false;
  double attitude_std = 0.0;
  double gravity = 9.80665;
  // Seconds of each hold the static detector does not keep (its settling
  // trim and window edges); the information counts hold - trimmed.
  double trimmed_seconds = 0.0;

  bool IsValid(std::string* error) const;
};

// The parameter names of the model (MagnitudeParameterNames, or bias_x..z,
// m_xx..m_zz for the known-attitude model) and their count.
std::vector<std::string> DesignParameterNames(const DesignModel& model);

// sigma_k^2 above, (m/s^2)^2; infinite when the usable hold is not positive
// or the noise model cannot give the variance.
double PoseMagnitudeVariance(const DesignNoise& noise, const DesignModel& model,
                             const Eigen::Vector3d& up, double hold_seconds);

// Whitened Jacobian rows (one per pose; three for the known-attitude model)
// in scale-free units; columns named by DesignParameterNames(model).
Eigen::MatrixXd DesignJacobian(const std::vector<DesignPose>& poses, const DesignModel& model,
                               const DesignNoise& noise);

// The predicted standard deviation of every parameter from a Fisher
// information (scale-free units): sqrt of the diagonal of F^-1; infinity
// for a parameter F does not determine (a null direction of F involves it).
Eigen::VectorXd PredictedStd(const Eigen::MatrixXd& fisher);

// The standard deviations a fit can report without holding anything: each
// parameter's marginal sigma (PredictedStd, every other parameter free),
// infinity when that exceeds its limit (scale-free, e.g. the refinement's
// max_bias_std and max_matrix_std) or F does not determine it. A parameter
// whose sigma is small only while another, undetermined one is held (a bias
// against the scale of an axis seen from one side) is undetermined too.
Eigen::VectorXd DeterminedStd(const Eigen::MatrixXd& fisher, const Eigen::VectorXd& limits);

// Converts scale-free standard deviations to the calibration JSON's units
// at nominal scale s: bias / s, U entries * s.
Eigen::VectorXd StdInRawUnits(const Eigen::VectorXd& scale_free_std, double nominal_scale);

// Candidate up directions: faces (the six axis directions), faces+45
// (plus the twelve 45-degree directions between two axes), free (those 18
// and `count` directions spread evenly over the sphere, a Fibonacci
// lattice). False for free with count < 1.
bool CandidateDirections(PoseSet pose_set, int count, std::vector<Eigen::Vector3d>* directions);

struct DesignOptions {
  // Per parameter (scale-free units: m/s^2 for the bias, relative for U), in
  // MagnitudeParameterNames order; every entry positive and finite.
  Eigen::VectorXd targets;
  // Seconds to move and settle the housing before each pose.
  double overhead_seconds = 10.0;
  // Shortest and longest hold of one pose, seconds.
  double min_hold_seconds = 5.0;
  double max_hold_seconds = 600.0;
  // Poses closer than this, degrees, are one pose (held their summed time):
  // the static detector merges neighbouring poses within 3 degrees, and a
  // placement error of a few degrees makes closer ones indistinguishable.
  double min_separation_deg = 10.0;
  // At least (parameters + this) poses: degrees of freedom left for the
  // fit's own chi-square check, and robustness to the placement error (a
  // design with as many poses as parameters is exactly determined, and its
  // sigmas came out 6-20 % above the prediction over 400 simulated seeds
  // with 2 degrees of placement error).
  int redundancy = 3;
  // At most this many poses.
  int max_poses = 40;
  // > 0: the total time (poses and overhead) may not exceed this; the design
  // is then the best (smallest max sigma / target) within it.
  double max_time_seconds = 0.0;
  // Fixed designs the search also considers (the seed's schemes): the
  // result is never worse than the best of them that is allowed.
  std::vector<std::vector<Eigen::Vector3d>> reference_designs;

  bool IsValid(const DesignModel& model, std::string* error) const;
};

struct DesignResult {
  // The poses (up, hold) in the order chosen (not yet ordered for handling).
  std::vector<DesignPose> poses;
  // Scale-free predicted standard deviations.
  Eigen::VectorXd predicted_std;
  // max_i predicted_std_i / target_i (<= 1: every target met).
  double worst_ratio = 0.0;
  // Sum of holds and overheads, seconds.
  double total_seconds = 0.0;
  bool meets_targets = false;
  std::string message = "DesignPoses was not called";
};

// Total time of a design: sum of holds + overhead per pose.
double DesignSeconds(const std::vector<DesignPose>& poses, double overhead_seconds);

// Evaluates fixed poses: predicted_std, worst_ratio, total time.
DesignResult EvaluateDesign(const std::vector<DesignPose>& poses, const DesignModel& model,
                            const DesignNoise& noise, const DesignOptions& options);

// The shortest common hold (within [min_hold, max_hold]) at which the poses
// meet every target; false when even max_hold does not.
bool ShortestHold(const std::vector<Eigen::Vector3d>& ups, const DesignModel& model,
                  const DesignNoise& noise, const DesignOptions& options, DesignResult* result);

// The design over `candidates` (unit up vectors): without max_time, the
// least total time that meets every target; with it, the best worst_ratio
// within max_time. Greedy selection with Fedorov exchange on the criterion
// above for each pose count, the common hold found by bisection, directions
// closer than min_separation_deg merged into one longer pose. For the
// known-attitude model (three rows per pose) the search is over the
// reference designs and the six faces recorded as often as max_poses
// allows: its
// information is the linear regression's, sum_k [1, v_k^T; v_k, v_k v_k^T]
// (x) Sigma_k^-1, whose A-optimal designs are the balanced ones (sum v_k = 0,
// sum v_k v_k^T proportional to I), as the six faces are. Returns
// false (result->message) on invalid options; a design that cannot meet the
// targets returns true with meets_targets false and the best it found.
bool DesignPoses(const std::vector<Eigen::Vector3d>& candidates, const DesignModel& model,
                 const DesignNoise& noise, const DesignOptions& options, DesignResult* result);

// ---------------------------------------------------------------------------
// The gyroscope between poses (methods/gyro_calibration.h).
//
// The model is the calibration's own: static pose k ties the bias by
// r_k = W_k M_g (u_k - b_g) (GyroStaticResidual), rotation k turns the
// gravity direction the accelerometer sees in one pose into the next one's
// by the integrated gyroscope, r_k = W_k E_k (R(dq)^T d_s - d_e)
// (GyroRotationResidual). A design is judged at the nominal sensor in
// scale-free units: raw gyroscope in rad/s (M_g = I, b_g = 0), accelerometer
// as above (s = 1). A planned turn about the body axis a by the angle t over
// T seconds is synthesised as the minimum-jerk rate a t s'(x) / T (x = time
// / T) sampled at 100 Hz, with edge_seconds of stillness at both ends (the
// calibration integrates the ends of the poses with the rotations), and its
// Jacobian is the residual's, evaluated by Ceres (joint form, so the
// accelerometer's columns are there too). The weights are the calibration's:
//
//   Cov(e) = C(d_e) + R^T C(d_s) R + [d^]x Sigma_phi [d^]x^T,
//   C(d) = P diag(V_a(T_pose)) P / g^2,  P = I - d d^T,
//   Sigma_phi = sum_i c_i^2 R_i diag(N_g^2 f) R_i^T   (in the end frame),
//
// c_i the trapezoid share of sample i, N_g the gyroscope's white-noise
// density, f the sample rate; a static pose of T seconds informs the bias by
// diag(V_g(T))^-1 (StillMeanVariance, the gyroscope's noise model). The
// calibration holds the accelerometer at its own estimate, so the predicted
// covariance is the one of that two-step estimate:
//
//   C_g = A + S C_a S^T,  A = (J_g^T J_g)^-1,  S = -A J_g^T J_a,
//
// J_g the gyroscope's columns of all rows, J_a the accelerometer's, C_a the
// accelerometer design's covariance (the magnitude model above). The
// criterion is the same target-weighted A-optimality, sum_i (sigma_i /
// target_i)^2 over the gyroscope's parameters.

// The gyroscope's parameters: bias_x..z (rad/s scale-free, raw units in the
// calibration JSON) and the free entries of M_g (m_xx, m_xy, ..., m_zz for
// full; m_xx, m_yy, m_zz for scale; "scale" for bias, the common scale),
// the names of the calibration JSON's gyro covariance.
std::vector<std::string> GyroDesignParameterNames(GyroParameterization p);

struct GyroDesignModel {
  GyroParameterization parameterization = GyroParameterization::kFull;
  // Seconds at each end of a pose integrated with the rotations
  // (GyroCalibrationOptions::edge_seconds).
  double edge_seconds = 0.5;
  // Sample rate of the synthesised turns, Hz (the information hardly
  // depends on it: the integrated noise is N_g^2 T).
  double sample_rate = 100.0;

  bool IsValid(std::string* error) const;
};

// One turn of a design between two up directions: the body axis (unit), the
// angle (degrees, 0..180, right hand rule: up' = R(axis, -angle) up) and its
// duration, seconds.
struct DesignTurn {
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();
  double angle_deg = 0.0;
  double seconds = 3.0;
};

// The turns that take up direction `from` to `to` about one fixed body
// axis, with angles in (0, 180]: the axes a with a.from = a.to. The
// shortest turn (about to x from) and the housing axes among them (what a
// person can follow); with `free_axes` > 0 also the half turn about
// (from + to) and `free_axes` more axes spread over the family. `seconds_per_180` is the duration
// of a half turn (shorter turns take proportionally less, at least half of it).
std::vector<DesignTurn> CandidateTurns(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                                       int free_axes, double seconds_per_180);

// The design's gyroscope information: the poses in handling order and the
// turn between each consecutive pair (turns.size() = poses.size() - 1).
struct GyroDesignResult {
  std::vector<std::string> parameter_names;
  std::vector<DesignTurn> turns;
  // Extra poses appended after the accelerometer's to meet the gyroscope
  // targets (also in `poses`).
  int extra_poses = 0;
  std::vector<DesignPose> poses;
  // Scale-free standard deviations (rad/s; relative), infinity =
  // undetermined; and the same without the accelerometer's contribution.
  Eigen::VectorXd predicted_std;
  Eigen::VectorXd predicted_std_gyro_only;
  double worst_ratio = 0.0;
  bool meets_targets = false;
  std::string message = "DesignRotations was not called";
};

// Evaluates fixed poses and turns (C_g above, scale-free).
GyroDesignResult EvaluateRotations(const std::vector<DesignPose>& poses,
                                   const std::vector<DesignTurn>& turns, const DesignModel& model,
                                   const GyroDesignModel& gyro_model, const DesignNoise& noise,
                                   const Eigen::VectorXd& gyro_targets);

struct RotationDesignOptions {
  // Per gyroscope parameter (GyroDesignParameterNames order), scale-free,
  // positive.
  Eigen::VectorXd targets;
  // Extra axes per turn beyond the shortest, the half turn and the housing
  // axes (0 for a person following housing axes).
  int free_axes = 0;
  double seconds_per_180 = 3.0;
  // Up directions of extra poses, held extra_hold_seconds each, appended
  // (with their turns) while the gyroscope's targets are not met, at most
  // max_extra_poses.
  std::vector<Eigen::Vector3d> extra_candidates;
  double extra_hold_seconds = 10.0;
  int max_extra_poses = 12;

  bool IsValid(const GyroDesignModel& model, std::string* error) const;
};

// Chooses the turn between each consecutive pair of `poses` (in handling
// order): coordinate descent over the pairs, each turn the candidate that
// lowers sum_i (sigma_i / target_i)^2 of the gyroscope most given the
// others, until no turn changes; then, while a target is not met, appends
// the extra pose and turn that lower it most. False (result->message) on
// invalid options or without gyroscope white noise.
bool DesignRotations(const std::vector<DesignPose>& poses, const DesignModel& model,
                     const GyroDesignModel& gyro_model, const DesignNoise& noise,
                     const RotationDesignOptions& options, GyroDesignResult* result);

}  // namespace gravcal

#endif  // GRAVCAL_ESTIMATION_EXPERIMENT_DESIGN_H_
