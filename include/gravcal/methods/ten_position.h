// gravcal/methods/ten_position.h: the ten-position calibration of patent
// CN101907638B, from static alignment (config `method: ten_position`).
//
// Model (claim 1): g_a = K (g_m - g_0), g_m the raw accelerometer reading,
// g_0 its zero bias (raw units), K the 3x3 coupling of installation error and
// scale factor (m/s^2 per raw unit), g_a gravity projected into the body
// frame (m/s^2). Steps, per detected static position k:
//   1-2. coarse alignment and Kalman fine alignment on the static base
//        (static_alignment.h) give roll, pitch and g_a,k = C_k^T (0, 0, g);
//   3.   repeated over the (ten) positions;
//   4.   nonlinear least squares (Ceres, one autodiff residual per position,
//        refinement.h with the diagonal `scale` model) for g_0, from
//          r_k = ( |diag(k) (g_m,k - g_0)| - |g_a,k| ) / sigma_k;
//   5.   with g_0 known, the alignment is repeated on the corrected specific
//        force diag(k) (g_m - g_0) and K follows from linear least squares
//        (normal equations): K^T = (sum d_k d_k^T)^-1 sum d_k g_a,k^T,
//        d_k = g_m,k - g_0.
//
// What it can determine. The reference g_a is computed from this very
// accelerometer, so it inherits its errors: its direction is the sensor's own
// (biased, skewed) axes, and only its magnitude, g, is independent of the
// sensor. Step 4 therefore uses |g_a| only, and recovers the bias and the
// scale factors; in step 5 the off-diagonal terms of K (non-orthogonality
// and installation misalignment, six numbers) come out near zero whatever
// the truth is. They are reported with a null standard deviation and a
// warning; use known_attitude (all twelve) or twelve_position
// (non-orthogonality) for them. docs/methods/ten_position.md has the
// measured comparison.
#ifndef GRAVCAL_METHODS_TEN_POSITION_H_
#define GRAVCAL_METHODS_TEN_POSITION_H_

#include <string>

#include "gravcal/core/imu_log.h"
#include "gravcal/estimation/static_alignment.h"
#include "gravcal/methods/session.h"
#include "gravcal/methods/twelve_position.h"

namespace gravcal {

struct TenPositionOptions {
  // The alignment's priors and settings (its gravity is replaced by the
  // resolved local gravity, its latitude by the gravity options' latitude
  // when not given).
  StaticAlignmentOptions alignment;
  // Raw gyroscope units -> rad/s, for the alignment (1 = already rad/s;
  // pi / 180 / 131 for a +-250 deg/s 16-bit part).
  double gyro_nominal_scale = 1.0;
  // Fewer positions than this gives a warning (the patent's ten).
  int recommended_positions = 10;

  bool IsValid(std::string* error) const;
};

// Runs the five steps on a raw log (accelerometer; gyroscope optional, used
// by the alignment). `options` supplies detection, gravity, the step-4 solver
// settings (loss, loss_scale, covariance, max_iterations) and
// allow_undetermined (for step 4's bias and scale). Returns false with a
// one-line message on invalid options or log, fewer than 6 static positions,
// a position the alignment rejects, or a step 4 that does not converge.
bool CalibrateTenPosition(const ImuLog& log, const CalibrationOptions& options,
                          const TenPositionOptions& ten, Calibration* calibration);

// The sections the method reads.
struct TenPositionMethodOptions {
  // Gravity, detector, pose noise, and the step-4 settings above.
  CalibrationOptions accel;
  // The static alignment (steps 1-3 and 5).
  TenPositionOptions alignment;

  bool IsValid(std::string* error) const;
};

// The same on a session: its static detection when it has one, its noise
// model (when given) for the covariance of each pose's mean.
bool CalibrateTenPosition(const Session& session, const TenPositionMethodOptions& options,
                          Calibration* calibration);

}  // namespace gravcal

#endif  // GRAVCAL_METHODS_TEN_POSITION_H_
