// gravcal/ceres.h: gravcal's Ceres cost functors, for an estimator that builds
// its own ceres::Problem from gravcal's measurement models (as Sophus keeps
// its Ceres manifold apart from the Lie groups). Each residual's header gives
// its equation, frames and units. This header, unlike gravcal/gravcal.h,
// needs Ceres: link the CMake target gravcal::ceres, which is gravcal::gravcal
// plus Ceres.
#ifndef GRAVCAL_CERES_H_
#define GRAVCAL_CERES_H_

#include "gravcal/residuals/accel_rotation_residual.h"
#include "gravcal/residuals/accel_trend_residual.h"
#include "gravcal/residuals/gravity_magnitude_residual.h"
#include "gravcal/residuals/gyro_rotation_residual.h"
#include "gravcal/residuals/gyro_static_residual.h"

#endif  // GRAVCAL_CERES_H_
