// gravcal/estimation/fit_settings.h: the settings the accelerometer's fits
// share, as sections that each fit's options struct embeds
// (RefinementOptions, EffectFitOptions). A method hands a section from one
// fit to the next whole, so a setting added here reaches every fit that
// embeds it and none is copied field by field (or dropped) at a seam.
#ifndef GRAVCAL_ESTIMATION_FIT_SETTINGS_H_
#define GRAVCAL_ESTIMATION_FIT_SETTINGS_H_

#include "gravcal/core/types.h"

namespace gravcal {

// The robust loss rho on each whitened residual block, and its scale in
// standard deviations (> 0). A fit with a loss is graduated: it starts with
// a scale holding every initial residual and comes down to loss_scale.
// kNone = least squares.
struct RobustLossOptions {
  LossType loss = LossType::kNone;
  double loss_scale = 3.0;
};

// The per-pose variance the samples cannot show (bias wander from pose to
// pose, placement): estimated by REML when estimate_pose_variance, with an
// optional prior on it, the typical pose-to-pose scatter s0 (m/s^2, >= 0)
// on pose_disturbance_prior_dof (>= 0) degrees of freedom (0 = none, REML
// alone; estimation/variance_component.h).
struct PoseVarianceOptions {
  bool estimate_pose_variance = false;
  double pose_disturbance_prior = 0.0;
  double pose_disturbance_prior_dof = 0.0;
};

// What every fit of the accelerometer reads from the config's model and
// solver sections: the baseline parameterisation, the robust loss, the pose
// variance and whether a covariance is computed.
struct AccelFitSettings : RobustLossOptions, PoseVarianceOptions {
  AccelParameterization parameterization = AccelParameterization::kScaleMisalignment;
  bool compute_covariance = true;
};

}  // namespace gravcal

#endif  // GRAVCAL_ESTIMATION_FIT_SETTINGS_H_
