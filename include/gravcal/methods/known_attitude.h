// gravcal/methods/known_attitude.h: calibration from externally known attitudes
// (config `method: known_attitude`, `--attitudes fixture.csv`).
//
// With the roll and pitch of every static position known from outside the
// sensor (a fixture's angles, an external inclinometer), the gravity vector
// in the body frame is a reference independent of the accelerometer, so all
// twelve parameters of a = M (v - b) are observable (not only the nine the
// magnitude sees). Ceres problem, one autodiff block per position k:
//
//   r_k = L_k^-1 ( M (v_k - b) - g u(roll_k, pitch_k) )            (3)
//   u(r, p) = (-sin p, sin r cos p, cos r cos p)
//
// v_k the mean raw vector, L_k the Cholesky factor of M0 C_k M0^T (C_k the
// covariance of the mean raw vector, M0 the linear initial estimate), and
// the attitude (roll_k, pitch_k) is itself a parameter held by a prior block
//
//   p_k = ( (roll_k - roll_k^fix) / s_roll,k, (pitch_k - pitch_k^fix) / s_pitch,k )   (2)
//
// so the estimate is weighted by the sensor noise and the attitude
// uncertainty together, and the covariance of (b, M) from ceres::Covariance
// includes both. Heading does not enter (gravity is vertical).
//
// With options.refinement.estimate_pose_variance (config pose_variance), one
// extra specific-force variance s^2 I per position (placement disturbances
// the samples cannot show) is estimated by REML from the whitened residuals
// of that fit, the attitude priors counted as the parameters' degrees of
// freedom (estimation/variance_component.h, the whitened form; with the
// prior pose_disturbance_prior on pose_disturbance_prior_dof), added to
// every L_k L_k^T and the fit repeated; the covariance is then multiplied by
// the Student-t factor nu / (nu - 2) of an estimated s^2, and
// calibration->accel.pose_variance reports it (as twelve_position does).
#ifndef GRAVCAL_METHODS_KNOWN_ATTITUDE_H_
#define GRAVCAL_METHODS_KNOWN_ATTITUDE_H_

#include <string>
#include <vector>

#include "gravcal/core/imu_log.h"
#include "gravcal/core/position.h"
#include "gravcal/io/attitude_fixture.h"
#include "gravcal/methods/session.h"
#include "gravcal/methods/twelve_position.h"

namespace gravcal {

// A known attitude: roll and pitch and their standard deviations, radians.
struct KnownAttitude {
  double roll = 0.0;
  double pitch = 0.0;
  double roll_std = 0.0;
  double pitch_std = 0.0;
};

// The estimate from positions with their attitudes (attitudes[k] for
// positions[k]). Fills calibration->accel (affine model, bias_std,
// matrix_std, covariance over bias_* and m_* in raw units), refinement (the
// solver's summary: iterations, chi2, dof), per-position attitude and
// residuals. `options` supplies gravity (unless calibration->gravity_source is
// already set, as CalibrateKnownAttitude leaves it), loss, loss_scale,
// covariance, max_iterations and the pose-variance keys above. Returns false on fewer than 4
// positions, invalid attitudes, a singular initial fit or no convergence.
bool CalibrateFromKnownAttitudes(const std::vector<Position>& positions,
                                 const std::vector<KnownAttitude>& attitudes,
                                 const CalibrationOptions& options, Calibration* calibration);

// From a raw log and the attitudes file: detects the static positions,
// matches the file's rows to them (attitude_fixture.h), then
// CalibrateFromKnownAttitudes. Messages name the log or the file and line.
bool CalibrateKnownAttitude(const ImuLog& log, const std::string& attitudes_path,
                            const CalibrationOptions& options, Calibration* calibration);

// Same with the file's rows already read (ReadFixtureAttitudes);
// `attitudes_name` names the file in messages.
bool CalibrateKnownAttitude(const ImuLog& log, const std::vector<FixtureAttitude>& rows,
                            const std::string& attitudes_name, const CalibrationOptions& options,
                            Calibration* calibration);

// The sections the method reads.
struct KnownAttitudeMethodOptions {
  // Gravity, detector, pose noise, and the solver settings above.
  CalibrationOptions accel;

  bool IsValid(std::string* error) const { return accel.IsValid(error); }
};

// The same on a session: the fixture's rows are session.attitudes (named
// session.attitudes_name), its static detection is used when it has one,
// its noise model (when given) for the covariance of each pose's mean.
bool CalibrateKnownAttitude(const Session& session, const KnownAttitudeMethodOptions& options,
                            Calibration* calibration);

}  // namespace gravcal

#endif  // GRAVCAL_METHODS_KNOWN_ATTITUDE_H_
