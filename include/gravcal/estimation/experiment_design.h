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

// The accelerometer noise a design is judged against (SI).
struct DesignNoise {
  std::array<AxisNoiseModel, 3> accel;
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
  double gravity = 9.80665;
  // Seconds of each hold the static detector does not keep (its settling
  // trim and window edges); the information counts hold - trimmed.
  double trimmed_seconds = 0.0;

  bool IsValid(std::string* error) const;
};

// sigma_k^2 above, (m/s^2)^2; infinite when the usable hold is not positive
// or the noise model cannot give the variance.
double PoseMagnitudeVariance(const DesignNoise& noise, const DesignModel& model,
                             const Eigen::Vector3d& up, double hold_seconds);

// Whitened Jacobian rows (one per pose) in scale-free units; columns named by
// MagnitudeParameterNames(model.parameterization).
Eigen::MatrixXd DesignJacobian(const std::vector<DesignPose>& poses, const DesignModel& model,
                               const DesignNoise& noise);

// The predicted standard deviation of every parameter from a Fisher
// information (scale-free units): sqrt of the diagonal of F^-1; infinity
// for a parameter F does not determine (a null direction of F involves it).
Eigen::VectorXd PredictedStd(const Eigen::MatrixXd& fisher);

// The standard deviations a fit reports when it holds what the data do not
// determine (as the refinement holds weak parameters at their start): while
// the information of the free parameters is singular, or some sigma exceeds
// its limit (scale-free, e.g. the refinement's max_bias_std and
// max_matrix_std), the parameter that moves most relative to its limit
// along the weakest direction is held (infinity) and the rest recomputed,
// conditional on the held ones.
Eigen::VectorXd DeterminedStd(const Eigen::MatrixXd& fisher, const Eigen::VectorXd& limits);

// Converts scale-free standard deviations to the calibration JSON's units
// at nominal scale s: bias / s, U entries * s.
Eigen::VectorXd StdInRawUnits(const Eigen::VectorXd& scale_free_std, double nominal_scale);

// Candidate up directions: "faces" (the six axis directions), "faces+45"
// (plus the twelve 45-degree directions between two axes), "free" (those 18
// and `count` directions spread evenly over the sphere, a Fibonacci
// lattice). False for another name.
bool CandidateDirections(const std::string& pose_set, int count,
                         std::vector<Eigen::Vector3d>* directions);

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
// closer than min_separation_deg merged into one longer pose. Returns
// false (result->message) on invalid options; a design that cannot meet the
// targets returns true with meets_targets false and the best it found.
bool DesignPoses(const std::vector<Eigen::Vector3d>& candidates, const DesignModel& model,
                 const DesignNoise& noise, const DesignOptions& options, DesignResult* result);

}  // namespace gravcal

#endif  // GRAVCAL_ESTIMATION_EXPERIMENT_DESIGN_H_
