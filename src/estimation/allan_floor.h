// Private: the floor of an Allan deviation curve, where the bias
// instability is read (allan_noise_fit.cc), and the degrees of freedom a
// reading of the curve rests on.
#ifndef GRAVCAL_SRC_ESTIMATION_ALLAN_FLOOR_H_
#define GRAVCAL_SRC_ESTIMATION_ALLAN_FLOOR_H_

#include <cstddef>
#include <string>
#include <vector>

#include "gravcal/estimation/allan_deviation.h"

namespace gravcal {
namespace internal {

// The degrees of freedom a reading at curve point i rests on: the point's
// equivalent dof, but at most the number of independent clusters less one,
// n / m - 1. The edf formulas assume the noise type holds exactly; the
// classic sigma(adev) / adev = 1 / sqrt(2 (n / m - 1)) bounds it where the
// curve is only near a slope, as on real sensors.
double ReadingDof(const AllanDeviation& curve, size_t i);

// The curve's floor: its Allan deviation, relative standard deviation and
// where it lies, or why the curve does not show one.
struct AllanFloor {
  bool seen = false;
  // Whether a point after the lowest (any, however few its clusters) lies
  // significantly above the white-noise line through it (the curve shows a
  // rise, floor or not), and the lowest point's tau.
  bool rises = false;
  double lowest_tau = 0.0;
  double adev = 0.0;
  double relative = 0.0;
  double tau = 0.0;
  double tau_min = 0.0;
  double tau_max = 0.0;
  // The bias instability the lowest point bounds, its adev / 0.664 (the
  // flicker's Allan deviation lies at or below the curve everywhere).
  double bound = 0.0;
  std::string reason;
};

// The floor of the curve from the points `used` (indices into
// curve.points) with Allan variances `avar` (spectral lines subtracted).
// The lowest point among those with 10 or more degrees of freedom (lowest
// by its upper one-sigma bound, adev (1 + 1 / sqrt(2 dof))) marks it;
// it is seen only when the curve falls to it (a point before it lies
// significantly above) and has left the white-noise slope there (a point
// after it lies significantly above the line tau^-1/2 through it, or one
// before it significantly below), and no later point (however few its
// clusters) lies significantly below it (else the curve falls on past a
// slow line's bump), so a log too short to leave the white-noise slope
// gets no floor. Its value
// is the vertex of a weighted parabola in log adev over log tau through the
// points within an octave of the lowest (the lowest point alone is biased
// low: the least of several noisy points); its relative standard deviation
// combines the lowest point's, 1 / sqrt(2 dof), with the distance between
// the vertex and the lowest point (the floor's bias).
AllanFloor ReadAllanFloor(const AllanDeviation& curve, const std::vector<size_t>& used,
                          const std::vector<double>& avar);

// Whether the curve's rise from point `from` on (an index into used) turns
// over: a later point lies significantly (three sigmas: several later
// points are compared, and a random walk's last points scatter widely)
// below the highest
// point of the rise. A random walk rises to the longest tau; a slow line
// (a heater's cycle) rises to about 0.37 of its period and falls after it.
// On true, *reason says where and the period it suggests.
bool RiseTurnsOver(const AllanDeviation& curve, const std::vector<size_t>& used,
                   const std::vector<double>& avar, size_t from, std::string* reason);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_ESTIMATION_ALLAN_FLOOR_H_
