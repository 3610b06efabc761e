// gravcal/estimation/check_session.h: does a short check session agree with
// a stored calibration? (gravcal verify; not a recalibration.)
//
// Each check pose k gives the mean raw accelerometer vector v_k with the
// covariance of that mean C_k. Under the stored calibration (b, M = R U)
//
//   r_k = |M (v_k - b)| - g,                              m/s^2,
//
// is zero up to the pose noise and the stored calibration's own error:
//
//   S = diag(u_k^T M C_k M^T u_k) + H C_p H^T,   u_k = M (v_k - b) / |M (v_k - b)|,
//
// H_kj = d r_k / d p_j (central differences) over the stored parameters p
// with covariance C_p (accel.covariance; rot_* does not change |a| and has
// no column). r and S enter the shared test of calibration_comparison.h
// (TestShifts): the joint chi-square on K poses and the largest one-term
// statistic t_j, whose parameter is named with its estimated change in
// stored sigmas, with the parameters the check cannot tell apart from it,
// and the smallest change of each parameter the check detects with the
// stated power at the stated level (its minimal detectable change).
// Parameters the stored calibration does not determine are not tested
// (listed as undetermined). Effect terms are not part of the check: the
// linear model alone is used. The gravity is the stored calibration's.
#ifndef GRAVCAL_ESTIMATION_CHECK_SESSION_H_
#define GRAVCAL_ESTIMATION_CHECK_SESSION_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "gravcal/core/calibration.h"
#include "gravcal/core/position.h"
#include "gravcal/estimation/calibration_comparison.h"

namespace gravcal {

// One check pose under the stored calibration.
struct CheckPose {
  // r_k (m/s^2), the pose noise's sigma and the total sigma sqrt(S_kk).
  double residual = 0.0;
  double noise_sigma = 0.0;
  double sigma = 0.0;
  double t_begin = 0.0;
  double t_end = 0.0;
};

struct CheckSessionResult {
  ComparisonResult comparison;
  std::vector<CheckPose> poses;
  // What the caller should hear (a check session outside the stored thermal
  // model's range, or without the temperature it needs).
  std::vector<std::string> warnings;
};

// `stored` needs accel.model and accel.covariance (with names, std as read
// by io/calibration_uncertainty_io.h); gravity is stored.gravity. False
// with result->comparison.message for invalid options, no pose, or a stored
// calibration without covariance. `extra_covariance` (K x K, may be null)
// is added to S: what the caller's own correction of the poses adds (the
// thermal coefficients' uncertainty when the poses were taken to T_ref,
// workflows/compare.h).
bool VerifyCheckSession(const std::vector<Position>& positions, const Calibration& stored,
                        const ComparisonOptions& options, CheckSessionResult* result,
                        const Eigen::MatrixXd* extra_covariance = nullptr);

// The shortest check session with a given power (plan --verify): poses
// along `directions` (body frame; default the four tetrahedral directions),
// each held `hold` seconds, white accelerometer noise of density
// `noise_density` (m/s^2/sqrt(Hz): the variance of a pose mean is N^2 / hold
// per axis). The hold is the shortest (bisection, to 1 %) at which every
// tested parameter's minimal detectable change is at most `target_sigmas`
// stored sigmas, with `comparison.power` at `comparison.level`. The stored
// calibration's own uncertainty sets a floor no hold goes below: a
// parameter that cannot reach the target within max_hold_seconds is named.
struct CheckDesignOptions {
  std::vector<Eigen::Vector3d> directions;
  double noise_density = 0.0;
  double target_sigmas = 10.0;
  double max_hold_seconds = 600.0;
  ComparisonOptions comparison;

  bool IsValid(std::string* error) const;
};

struct CheckDesign {
  bool met = false;
  double hold_seconds = NAN;
  // Per tested parameter at that hold: its minimal detectable change in
  // stored sigmas.
  std::vector<std::string> names;
  std::vector<double> mdc_sigmas;
  // Parameters that do not reach the target at max_hold_seconds.
  std::vector<std::string> short_of_target;
  std::string message;
};

bool DesignCheckSession(const Calibration& stored, const CheckDesignOptions& options,
                        CheckDesign* design);

}  // namespace gravcal

#endif  // GRAVCAL_ESTIMATION_CHECK_SESSION_H_
