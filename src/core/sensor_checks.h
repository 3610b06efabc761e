// Private: checks of the raw data and of fitted matrices that name a cause
// the residuals alone would only show as "far above the noise": a saturated
// (clipped) axis, and a left-handed calibration matrix (an axis with the
// opposite sign convention, or two axes swapped).
#ifndef GRAVCAL_SRC_CORE_SENSOR_CHECKS_H_
#define GRAVCAL_SRC_CORE_SENSOR_CHECKS_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "gravcal/core/imu_log.h"
#include "gravcal/core/position.h"

namespace gravcal {
namespace internal {

// One warning per saturated axis of the accelerometer and gyroscope: an
// axis whose largest (or smallest) value is taken by at least 3 samples, in
// runs of identical values, more often than all the values within 1 % of
// the axis's range below (above) it: the samples pile up at a limit instead
// of thinning out as a signal's extreme does. Names the sensor, axis, value
// and sample ranges.
std::vector<std::string> SaturationWarnings(const ImuLog& log);

// Empty when det(m) > 0 (m maps raw to SI). Otherwise a warning naming
// `sensor` and the raw axis whose sign flip, or the pair whose swap, brings m
// closest to a positive diagonal (its columns normalised).
std::string HandednessWarning(const std::string& sensor, const Eigen::Matrix3d& m);

// Empty unless the gyroscope columns of the still intervals hold what looks
// like accelerometer data: in at least 6 intervals the gyroscope means have
// one norm (within 15 % of their median), point in directions more than 60
// degrees apart, and follow the accelerometer means linearly (g_k = A a_k + c
// explains more than 99 % of their spread). A gyroscope at rest reads its
// bias (one direction), plus Earth rate and g-sensitivity (small, or not
// linear in a). Then a one-line message naming the columns.
std::string GyroLooksLikeAccelerometer(const std::vector<StaticInterval>& intervals);

// Empty unless the gyroscope's raw axes disagree with the accelerometer's
// convention: while the unit turns slowly the specific force f turns
// against the rate, df/dt = f x w (body frame), so the accelerometer alone
// says how the gyroscope must read. Over the moving samples whose |f| is
// near its median (no large linear acceleration), d = df/dt is fitted as
// k f x (M w_raw), k > 0 (any gyroscope unit), for each of the 48 signed
// axis permutations M, on means over 0.05 s of time. When the best M is not
// the identity, explains more than 30 % of |d|^2 and the columns as given
// less than half as much, a one-line message names the gyroscope axis that
// looks flipped, the pair that looks swapped or flipped, or the mapping that
// fits. The accelerometer's offset (unsigned counts) is removed by a sphere
// fit when the log covers enough directions. Needs time stamps and at least
// 2 s of turning.
std::string GyroAxisConventionWarning(const ImuLog& log);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_CORE_SENSOR_CHECKS_H_
