// gravcal/methods/twelve_position.h: the multi-position accelerometer
// calibration, end to end: static detection -> positions -> coarse fit ->
// refinement (Ceres or the Newton baseline) -> housing rotation (affine) ->
// uncertainty.
//
// Where each parameter comes from:
// - b and U (bias, scale, non-orthogonality) from the gravity magnitude, the
//   fine step: independent of how well the poses were placed;
// - R (affine only) from the nominal axes of the axis-aligned positions: its
//   accuracy is that of the placement, and its uncertainty is estimated from
//   the placement errors the positions show.
#ifndef GRAVCAL_METHODS_TWELVE_POSITION_H_
#define GRAVCAL_METHODS_TWELVE_POSITION_H_

#include <string>
#include <vector>

#include "gravcal/core/calibration.h"
#include "gravcal/core/gravity.h"
#include "gravcal/core/imu_log.h"
#include "gravcal/core/position.h"
#include "gravcal/core/types.h"
#include "gravcal/detection/static_detector.h"
#include "gravcal/estimation/coarse_fit.h"
#include "gravcal/estimation/pose_mean_covariance.h"
#include "gravcal/estimation/refinement.h"

namespace gravcal {

struct CalibrationOptions {
  StaticDetectorOptions detector;
  GravityOptions gravity;
  CoarseFitOptions coarse;
  // The parameterisation, loss and covariance settings live here.
  RefinementOptions refinement;
  RefinementSolver solver = RefinementSolver::kCeres;
  // Only for solver = kNewton.
  NewtonResidual newton_residual = NewtonResidual::kSquaredMagnitude;
  // Raw units -> m/s^2 assumed before calibration (9.80665 / 16384 for a
  // +-2 g 16-bit accelerometer, 1 for data already in m/s^2); only used to
  // report the residual before calibration.
  double nominal_scale = 1.0;
  // The nominal up axis of each detected position in order ("+x", "-z",
  // "?"); empty = assign automatically.
  std::vector<int> nominal_up;
  // When the positions do not determine some parameter: false = fail with a
  // message naming it; true = succeed, report it without a standard
  // deviation and say so in the warnings.
  bool allow_undetermined = false;
  // The covariance of each pose's mean (pose_mean_covariance.h): white
  // (sample covariance / n), batch means, or a noise model when one is set.
  PoseNoiseOptions pose_noise;

  bool IsValid(std::string* error) const;
};

// From a raw log: detects the static positions, then CalibrateFromPositions.
// `intervals`, when given, receives the detected static intervals, so that
// later steps on the same log (gyroscope, effects) need not detect again.
bool CalibrateAccelerometer(const ImuLog& log, const CalibrationOptions& options,
                            Calibration* calibration,
                            std::vector<StaticInterval>* intervals = nullptr);

// From positions already extracted. Returns false with a one-line message
// on invalid options, too few positions (how many found, how many needed),
// no coarse fit, parameters the positions do not determine (unless
// allow_undetermined), or a refinement that did not converge (the coarse result
// is then in calibration->accel.model).
bool CalibrateFromPositions(const std::vector<Position>& positions,
                            const CalibrationOptions& options, Calibration* calibration);

}  // namespace gravcal

#endif  // GRAVCAL_METHODS_TWELVE_POSITION_H_
