#include "gravcal/core/position.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "util/matrix_checks.h"

namespace gravcal {
namespace {

// The quantisation step to assume on each axis of an interval: its own
// smallest step, else the smallest step on its other axes, else the smallest
// step of any interval, else (nothing changed anywhere) one count when the
// means are integers or 2^-20 (about 1 ppm) of the largest mean component.
Eigen::Vector3d StepFor(const StaticInterval& interval, double fallback_step) {
  Eigen::Vector3d step = interval.accel_resolution;
  double own = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a)
    if (step[a] > 0.0) own = std::min(own, step[a]);
  if (!std::isfinite(own)) own = fallback_step;
  if (!(own > 0.0)) {
    const Eigen::Vector3d& m = interval.accel_mean;
    own = (m.array() == m.array().round()).all()
              ? 1.0
              : std::ldexp(std::max(m.cwiseAbs().maxCoeff(), 1.0), -20);
  }
  for (int a = 0; a < 3; ++a)
    if (!(step[a] > 0.0)) step[a] = own;
  return step;
}

}  // namespace

Eigen::Vector3d NominalAxis(int nominal_up) {
  if (nominal_up < 0 || nominal_up > 5) return Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();
  axis[nominal_up / 2] = (nominal_up % 2 == 0) ? 1.0 : -1.0;
  return axis;
}

std::string NominalAxisName(int nominal_up) {
  static const char* const kNames[] = {"+x", "-x", "+y", "-y", "+z", "-z"};
  if (nominal_up < 0 || nominal_up > 5) return "?";
  return kNames[nominal_up];
}

std::vector<Position> PositionsFromIntervals(const std::vector<StaticInterval>& intervals) {
  double fallback_step = std::numeric_limits<double>::infinity();
  for (const StaticInterval& s : intervals)
    for (int a = 0; a < 3; ++a)
      if (s.accel_resolution[a] > 0.0)
        fallback_step = std::min(fallback_step, s.accel_resolution[a]);
  if (!std::isfinite(fallback_step)) fallback_step = 0.0;

  std::vector<Position> positions;
  positions.reserve(intervals.size());
  for (const StaticInterval& s : intervals) {
    Position p;
    p.raw_mean = s.accel_mean;
    p.sample_count = s.count();
    p.t_begin = s.t_begin;
    p.t_end = s.t_end;
    p.temperature = s.temperature_mean;
    p.raw_mean_cov = s.accel_cov / static_cast<double>(std::max<size_t>(1, s.count()));
    if (!internal::IsSafelyPositiveDefinite(p.raw_mean_cov)) {
      // Constant (quantised) data: the mean is known no better than the
      // uniform quantisation error, step^2 / 12, which averaging does not
      // reduce when the signal does not dither.
      const Eigen::Vector3d step = StepFor(s, fallback_step);
      if (!p.raw_mean_cov.allFinite()) p.raw_mean_cov.setZero();
      p.raw_mean_cov.diagonal() += step.cwiseProduct(step) / 12.0;
    }
    positions.push_back(p);
  }
  return positions;
}

}  // namespace gravcal
