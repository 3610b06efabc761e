// gravcal/core/rate_table_segment.h: a stretch of a log turned at a known
// constant rate, as a rate table (or the simulator's rate-table profile)
// gives it.
#ifndef GRAVCAL_CORE_RATE_TABLE_SEGMENT_H_
#define GRAVCAL_CORE_RATE_TABLE_SEGMENT_H_

#include <Eigen/Core>
#include <cstddef>

namespace gravcal {

// Samples [begin, end) of a log at constant known body rate.
struct RateTableSegment {
  size_t begin = 0;
  size_t end = 0;
  // The true body rate, rad/s (body frame: the sensor axes).
  Eigen::Vector3d rate = Eigen::Vector3d::Zero();
};

}  // namespace gravcal

#endif  // GRAVCAL_CORE_RATE_TABLE_SEGMENT_H_
