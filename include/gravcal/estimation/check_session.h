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
};

// `stored` needs accel.model and accel.covariance (with names, std as read
// by io/calibration_uncertainty_io.h); gravity is stored.gravity. False
// with result->comparison.message for invalid options, no pose, or a stored
// calibration without covariance.
bool VerifyCheckSession(const std::vector<Position>& positions, const Calibration& stored,
                        const ComparisonOptions& options, CheckSessionResult* result);

}  // namespace gravcal

#endif  // GRAVCAL_ESTIMATION_CHECK_SESSION_H_
