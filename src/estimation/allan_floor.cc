// The floor of an Allan deviation curve (allan_floor.h).
#include "estimation/allan_floor.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <sstream>

namespace gravcal {
namespace internal {

double ReadingDof(const AllanDeviation& curve, size_t i) {
  const AllanPoint& point = curve.points[i];
  const double clusters =
      static_cast<double>(curve.samples) / static_cast<double>(std::max<size_t>(point.m, 1)) - 1.0;
  return std::max(1.0, std::min(point.edf, clusters));
}

AllanFloor ReadAllanFloor(const AllanDeviation& curve, const std::vector<size_t>& used,
                          const std::vector<double>& avar) {
  AllanFloor floor;
  std::vector<size_t> candidates;  // indices into used
  for (size_t k = 0; k < used.size(); ++k) {
    if (curve.points[used[k]].edf >= 5.0 && avar[k] > 0.0) candidates.push_back(k);
  }
  std::ostringstream why;
  why.precision(3);
  if (candidates.size() < 3) {
    why << "the curve has " << candidates.size()
        << " points with 5 or more degrees of freedom, too few to show a floor";
    floor.reason = why.str();
    return floor;
  }
  // Relative standard deviation of a point's Allan deviation.
  auto relative = [&](size_t k) { return 1.0 / std::sqrt(2.0 * ReadingDof(curve, used[k])); };
  // The lowest point by its upper one-sigma bound, among those with 10 or
  // more degrees of freedom: a long-tau point of few clusters that happens
  // to dip is not taken for the floor (it can still show the rise).
  size_t lowest = candidates.front();
  for (size_t k : candidates) {
    if (ReadingDof(curve, used[k]) >= 10.0 &&
        std::sqrt(avar[k]) * (1.0 + relative(k)) <
            std::sqrt(avar[lowest]) * (1.0 + relative(lowest))) {
      lowest = k;
    }
  }
  const double tau0 = curve.points[used[lowest]].tau;
  const double adev0 = std::sqrt(avar[lowest]);
  // Whether point k lies significantly above `level` (two combined sigmas).
  auto above = [&](size_t k, double level) {
    return std::sqrt(avar[k]) > level * (1.0 + 2.0 * std::hypot(relative(k), relative(lowest)));
  };
  // Whether point k lies significantly below `level`.
  auto below = [&](size_t k, double level) {
    return std::sqrt(avar[k]) * (1.0 + 2.0 * std::hypot(relative(k), relative(lowest))) < level;
  };
  bool falls = false, stops = false;
  for (size_t k : candidates) {
    // The white-noise line through the lowest point: a later point above
    // it, or an earlier one below it, shows the curve has left the slope.
    const double white = adev0 * std::sqrt(tau0 / curve.points[used[k]].tau);
    if (k < lowest) {
      falls = falls || above(k, adev0);
      stops = stops || below(k, white);
    }
    if (k > lowest) stops = stops || above(k, white);
  }
  // The curve rises when a later point, however few its clusters (a
  // random walk's rise is steepest at the longest tau), lies significantly
  // above the white-noise line through the lowest point: white noise alone
  // keeps falling.
  for (size_t k = lowest + 1; k < used.size(); ++k) {
    floor.rises = floor.rises || above(k, adev0 * std::sqrt(tau0 / curve.points[used[k]].tau));
  }
  // A later point, however few its clusters, significantly below the
  // lowest shows the curve falling on: the flat part there is the shoulder
  // of a slow line's bump, and the floor lies beyond the points of 10 or
  // more degrees of freedom (a part of a log reads it where the whole log
  // reads it lower).
  size_t deeper = 0;
  for (size_t k = lowest + 1; k < used.size() && deeper == 0; ++k) {
    if (avar[k] > 0.0 && below(k, adev0)) deeper = k;
  }
  floor.lowest_tau = tau0;
  floor.bound = adev0 / std::sqrt(kFlickerAllanFactor);
  if (!falls || !stops || deeper > 0) {
    why << "the curve shows no floor: its lowest point (tau " << tau0 << " s, Allan deviation "
        << adev0 << ") ";
    if (deeper > 0) {
      why << "is not its floor: the curve falls on, to " << std::sqrt(avar[deeper]) << " at tau "
          << curve.points[used[deeper]].tau
          << " s (too few clusters there to read it): the bias instability is at most "
          << floor.bound;
    } else if (!falls) {
      why << "is where it starts: it does not fall to it";
    } else {
      why << "is not followed by a rise or a flat part above the white-noise slope (the log is "
             "too short): the bias instability is at most "
          << floor.bound;
    }
    floor.reason = why.str();
    return floor;
  }
  // The vertex of a weighted parabola through the points within an octave.
  std::vector<size_t> window;
  for (size_t k : candidates) {
    if (std::abs(std::log2(curve.points[used[k]].tau / tau0)) <= 1.0 + 1e-9) window.push_back(k);
  }
  double log_floor = std::log(adev0);
  double vertex_tau = tau0;
  if (window.size() >= 3) {
    Eigen::MatrixXd a(window.size(), 3);
    Eigen::VectorXd b(window.size());
    for (size_t r = 0; r < window.size(); ++r) {
      const double x = std::log(curve.points[used[window[r]]].tau / tau0);
      const double w = 1.0 / relative(window[r]);
      a.row(static_cast<Eigen::Index>(r)) << w, w * x, w * x * x;
      b(static_cast<Eigen::Index>(r)) = w * 0.5 * std::log(avar[window[r]]);
    }
    const Eigen::Vector3d q = a.colPivHouseholderQr().solve(b);
    const double x_lo = std::log(curve.points[used[window.front()]].tau / tau0);
    const double x_hi = std::log(curve.points[used[window.back()]].tau / tau0);
    if (q(2) > 0.0 && q.allFinite()) {
      const double x = -q(1) / (2.0 * q(2));
      if (x >= x_lo && x <= x_hi) {
        log_floor = q(0) - q(1) * q(1) / (4.0 * q(2));
        vertex_tau = tau0 * std::exp(x);
      }
    }
  }
  const double bias = log_floor - std::log(adev0);
  floor.seen = true;
  floor.adev = std::exp(log_floor);
  floor.relative = std::hypot(relative(lowest), bias);
  floor.tau = vertex_tau;
  floor.tau_min = curve.points[used[window.front()]].tau;
  floor.tau_max = curve.points[used[window.back()]].tau;
  return floor;
}

bool RiseTurnsOver(const AllanDeviation& curve, const std::vector<size_t>& used,
                   const std::vector<double>& avar, size_t from, std::string* reason) {
  auto relative = [&](size_t k) { return 1.0 / std::sqrt(2.0 * ReadingDof(curve, used[k])); };
  size_t peak = from;
  for (size_t k = from; k < used.size(); ++k) {
    if (avar[k] > avar[peak]) peak = k;
  }
  for (size_t k = peak + 1; k < used.size(); ++k) {
    if (std::sqrt(avar[k]) * (1.0 + 3.0 * std::hypot(relative(k), relative(peak))) <
        std::sqrt(avar[peak])) {
      const double tau_peak = curve.points[used[peak]].tau;
      std::ostringstream s;
      s.precision(3);
      s << "the rising end turns over: it peaks at tau " << tau_peak << " s and falls by tau "
        << curve.points[used[k]].tau << " s, as a slow line of period about " << tau_peak / 0.37
        << " s does, not a random walk";
      *reason = s.str();
      return true;
    }
  }
  return false;
}

}  // namespace internal
}  // namespace gravcal
