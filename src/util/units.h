// util/units.h: unit conversions used across the library.
#ifndef GRAVCAL_SRC_UTIL_UNITS_H_
#define GRAVCAL_SRC_UTIL_UNITS_H_

#include <cmath>

namespace gravcal {
namespace internal {

constexpr double kDegToRad = M_PI / 180.0;
constexpr double kRadToDeg = 180.0 / M_PI;

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_UTIL_UNITS_H_
