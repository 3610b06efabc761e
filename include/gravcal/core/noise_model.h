// gravcal/core/noise_model.h: the stochastic noise model of an IMU, axis by
// axis, as the Allan deviation shows it.
//
// One sensor axis (accelerometer in m/s^2, gyroscope in rad/s) is modelled as
// the sum of independent processes, each with its Allan variance
// sigma^2(tau) (IEEE Std 952 / 1554 terminology):
//   quantisation       Q  sigma^2 = 3 Q^2 / tau^2        Q: m/s (accel), rad (gyro)
//   white noise        N  sigma^2 = N^2 / tau            N: m/s^2/sqrt(Hz), rad/s/sqrt(Hz)
//   bias instability   B  sigma^2 = (2 ln 2 / pi) B^2    B: m/s^2, rad/s (the flat floor:
//                                                        sigma_min = 0.664 B)
//   rate random walk   K  sigma^2 = K^2 tau / 3          K: m/s^3/sqrt(Hz), rad/s^2/sqrt(Hz)
// N is the continuous-time white-noise density (a sample at rate f has
// standard deviation N sqrt(f)); K is the density of the white noise whose
// integral is the bias (the bias drifts by K sqrt(t) in t seconds).
//
// Every term carries its estimate, its standard deviation and the tau range
// on which the curve shows it; value NaN means the log cannot show the term
// (too short, or another term dominates everywhere) and `reason` says which.
#ifndef GRAVCAL_CORE_NOISE_MODEL_H_
#define GRAVCAL_CORE_NOISE_MODEL_H_

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <limits>
#include <string>

namespace gravcal {

// (2 ln 2 / pi): the Allan variance of flicker (bias instability) noise of
// coefficient B is this times B^2, so sigma_min = sqrt(this) B = 0.664 B.
constexpr double kFlickerAllanFactor = 0.44127218139;

// One coefficient of the noise model.
struct NoiseTerm {
  // The coefficient (units above); NaN = not shown by the log.
  double value = std::numeric_limits<double>::quiet_NaN();
  // Its standard deviation, from the equivalent degrees of freedom of the
  // Allan variance it was read from.
  double std = std::numeric_limits<double>::quiet_NaN();
  // The tau at which it was read (for bias instability: the tau of the flat
  // part's minimum), seconds.
  double tau = std::numeric_limits<double>::quiet_NaN();
  // The tau range on which the term dominates the fitted curve, seconds.
  double tau_min = std::numeric_limits<double>::quiet_NaN();
  double tau_max = std::numeric_limits<double>::quiet_NaN();
  // Why value is NaN; empty when it is not.
  std::string reason;
  // When value is NaN but the curve bounds the coefficient (bias
  // instability: the curve's floor, or its lowest point, read as B), the
  // bound; NaN otherwise.
  double upper_bound = std::numeric_limits<double>::quiet_NaN();

  bool visible() const { return value == value; }
};

// The noise model of one sensor axis.
struct AxisNoiseModel {
  NoiseTerm quantisation;
  NoiseTerm white_noise;
  NoiseTerm bias_instability;
  NoiseTerm random_walk;

  // The model's Allan variance at tau (seconds): the sum of the visible
  // terms' formulas above, the bias instability's as its flicker part: B
  // read at the floor (tau = bias_instability.tau, the datasheet
  // convention sigma_floor = 0.664 B) holds the other terms' variance
  // there too, which is taken off it (down to 0) so that it is not counted
  // twice; a B without tau (a datasheet's) is taken as all flicker.
  double AllanVariance(double tau) const;
};

// The noise model of an IMU: three accelerometer axes (SI: m/s^2) and three
// gyroscope axes (rad/s), and where it was measured.
struct ImuNoiseModel {
  std::array<AxisNoiseModel, 3> accel;
  std::array<AxisNoiseModel, 3> gyro;
  // Sample rate of the log, Hz.
  double rate_hz = 0.0;
  // The still interval the curves were computed on: samples [begin, end)
  // of the log and their times, seconds.
  size_t still_begin = 0;
  size_t still_end = 0;
  double still_t_begin = 0.0;
  double still_t_end = 0.0;
};

// The variance of the mean of a still interval of `seconds` under the axis
// model: what replaces sigma^2 / n (sample variance over sample count, right
// only for white noise) for the mean of a pose. It is the Allan variance at
// tau = seconds, term by term:
//   white noise        N^2 / T           (exactly the variance of the mean)
//   rate random walk   K^2 T / 3         (the mean's wander about the bias
//                                         at a neighbouring interval)
//   bias instability   (2 ln 2 / pi) B^2 (approximation: the flicker floor,
//                                         reached for T within or above the
//                                         flat part; an upper bound for T
//                                         well below it, where a real sensor's
//                                         flicker noise is mostly white)
//   quantisation       3 Q^2 / T^2
// Terms that are not visible are left out. NaN when white noise is not
// visible (nothing to build on) or seconds <= 0.
double StillMeanVariance(const AxisNoiseModel& axis, double seconds);

// The same for three axes: the diagonal of the mean's covariance.
Eigen::Vector3d StillMeanVariance(const std::array<AxisNoiseModel, 3>& axes, double seconds);

}  // namespace gravcal

#endif  // GRAVCAL_CORE_NOISE_MODEL_H_
