// Private: the part of the gyroscope bias's error that every static pose
// shares. The bias is not constant over a session: bias instability
// (flicker) and rate random walk move it, and the calibrated b_g is, in
// effect, the bias averaged over the session's static poses. What the poses
// show of that wander is their scatter about the common value (the REML
// variance of the static mean rates, gyro_rotations.cc); what they cannot
// show is how far the common value itself is from the bias: a constant
// offset d of every raw rate is absorbed by b_g exactly (w = M_g (u - b_g)
// - G f is unchanged when u and b_g move by d together), so it moves b_g
// and nothing else, and its covariance W adds to b_g's block of the
// covariance and to nothing else:
//
//   Cov(b_g) += W.
//
// W per axis, in rad/s squared, then into raw units through M_g^-1:
//
// - From the noise model (`calibrate --noise noise.json`):
//     W = B^2 + K^2 T / 3,
//   T the session's span. K^2 T / 3 is exact for the rate random walk: the
//   variance of a T-long mean about the bias at the session's start (it is
//   also the random walk's Allan variance at T). For the bias instability
//   the Allan variance at T, (2 ln 2 / pi) B^2 = 0.44 B^2, is not enough: it
//   is the variance of the difference of adjacent T-long means and leaves
//   out the flicker slower than the session, which moves both alike and
//   which the Allan curve shows as the floor staying flat beyond T. B^2,
//   the bias instability coefficient read as the rms of the bias's wander
//   about its long-run level, counts it: for the simulator's flicker (flat
//   over 1-100 s, Gauss-Markov terms up to 1000 s) the variance of a
//   117-s session's mean is 1.18 B^2 (computed from its terms), and the
//   measured error / sigma rms of the bias is 0.98-1.05 with B^2 against
//   1.16-1.26 with 0.44 B^2 (tests/property/hand_placed_test.cc). A B
//   read at the Allan curve's floor (noise.json, with its tau) still holds
//   the white noise's and the random walk's variance there; that share is
//   taken off (AxisNoiseModel::FlickerAllanVariance) so that K is not
//   counted twice. A B without a tau (a datasheet's) is all flicker.
// - Otherwise, from the poses' own scatter s^2 (REML, when
//   estimate_static_variance finds one), by the random walk's ratio: a
//   random walk over T scatters the poses about their mean by K^2 T / 6 and
//   moves the mean by K^2 T / 3, so W = kWanderPerScatter s^2 with
//   kWanderPerScatter = 2. This is a partial answer: where the white noise
//   of a pose's mean exceeds the scatter (hand_placed.yaml: 8e-9 against
//   1e-9 (rad/s)^2) one session sizes s^2 to about +-200 %, often 0, and
//   the bias's error / sigma rms stays 1.1-1.3 (1.6-1.7 without it); a
//   noise model measured on a long still log is what sizes W well. So
//   whenever the poses' scatter is estimated (pose_variance, the
//   hand-placed configs) and no model is given, a kNoiseModel warning says
//   that the gyroscope's sigmas assume white noise and how the wander was
//   (or was not) counted, rather than leaving it silent.
#ifndef GRAVCAL_SRC_METHODS_GYRO_BIAS_WANDER_H_
#define GRAVCAL_SRC_METHODS_GYRO_BIAS_WANDER_H_

#include <Eigen/Core>
#include <string>

#include "gravcal/methods/gyro_calibration.h"
#include "methods/gyro_rotations.h"

namespace gravcal {
namespace internal {

constexpr double kWanderPerScatter = 2.0;

// W in raw units (above) for the gyroscope matrix M_g (rad/s per raw unit);
// false when neither a noise model nor a scatter is available (*note says
// why). *note names the source and the numbers.
bool SessionBiasWander(const GyroPrepared& prep, const GyroCalibrationOptions& options,
                       const Eigen::Matrix3d& matrix, Eigen::Matrix3d* wander, std::string* note);

// Adds W to the bias rows and columns of result->covariance and to
// result->bias_std, and fills result->bias_wander_std and bias_wander_note;
// adds the warning above to result->warnings. Nothing when no covariance is
// available; no W when SessionBiasWander has none.
void AddSessionBiasWander(const GyroPrepared& prep, const GyroCalibrationOptions& options,
                          GyroCalibrationResult* result);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_METHODS_GYRO_BIAS_WANDER_H_
