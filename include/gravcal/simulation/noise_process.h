// gravcal/simulation/noise_process.h: correlated sensor noise with a known
// Allan deviation, sample by sample, deterministic from a seed.
//
// One axis at rate f (sample step dt = 1 / f) is the sum of
// - white noise of density N: each sample N(0, N^2 f), so that averages
//   over tau have variance N^2 / tau;
// - a rate random walk of density K: b_{k+1} = b_k + K sqrt(dt) w_k, starting
//   at 0, Allan variance K^2 tau / 3;
// - bias instability B over [tau_low, tau_high]: a sum of first-order
//   Gauss-Markov processes  g_{k+1} = phi g_k + sqrt(1 - phi^2) s w_k,
//   phi = exp(-dt / T), each stationary with variance s^2 and correlation
//   time T. One such process has the Allan variance
//     (2 s^2 T / tau) [1 - T / (2 tau) (3 - 4 e^(-tau/T) + e^(-2 tau/T))],
//   a bump peaking at 0.381 s^2 near tau = 1.89 T. Equal variances at
//   correlation times spaced evenly in log T sum to a 1/f spectrum over their
//   span, i.e. a flat Allan variance: here two per decade from tau_low / 10
//   to 10 tau_high (none below dt), s^2 chosen so that the sum equals the
//   flicker floor (2 ln 2 / pi) B^2 at the geometric middle of the range.
//   Within [tau_low, tau_high] the sum stays within about 10 % of the floor
//   (5 % in deviation; ModelAllanVariance gives it exactly), below tau_low it
//   falls like a random walk, above tau_high like white noise;
// - tones (lines in the spectrum: a fan's 17 Hz, a heater's slow cycle):
//   A sin(2 pi f t + phase), the phase drawn from the seed, Allan variance
//   A^2 sin^4(pi f tau) / (pi f tau)^2;
// - a ramp R t (a drift, as a warming sensor shows: the rising long-tau end
//   of real curves, steeper than a random walk), Allan variance
//   R^2 tau^2 / 2.
#ifndef GRAVCAL_SIMULATION_NOISE_PROCESS_H_
#define GRAVCAL_SIMULATION_NOISE_PROCESS_H_

#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace gravcal {

struct NoiseProcessOptions {
  double rate_hz = 100.0;
  // White-noise density N (units/sqrt(Hz)); 0 = none.
  double white_noise = 0.0;
  // Bias instability B (units) and the tau range where the Allan deviation
  // is flat at 0.664 B, seconds; B = 0 = none. tau_low >= 10 / rate_hz.
  double bias_instability = 0.0;
  double bias_tau_low = 1.0;
  double bias_tau_high = 100.0;
  // Rate random walk density K (units/s/sqrt(Hz)); 0 = none.
  double random_walk = 0.0;
  // Sinusoidal lines: frequency (0 < f < rate_hz / 2) and amplitude.
  struct Tone {
    double frequency_hz = 0.0;
    double amplitude = 0.0;
  };
  std::vector<Tone> tones;
  // Ramp R, units/s (the sign is the drift's direction); 0 = none.
  double ramp = 0.0;

  bool IsValid(std::string* error) const;
};

// One noisy axis. Next() returns successive samples.
class NoiseProcess {
 public:
  // options must be valid (CHECKed).
  NoiseProcess(const NoiseProcessOptions& options, uint64_t seed);

  double Next();
  // n successive samples.
  std::vector<double> Generate(size_t n);

  // The exact Allan variance of the continuous-time construction at tau.
  double ModelAllanVariance(double tau) const;
  // Correlation times and the common standard deviation of the
  // Gauss-Markov components.
  const std::vector<double>& correlation_times() const { return times_; }
  double component_std() const { return component_std_; }

 private:
  NoiseProcessOptions options_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> unit_{0.0, 1.0};
  double white_std_ = 0.0;
  double walk_step_ = 0.0;
  double walk_ = 0.0;
  std::vector<double> times_;
  double component_std_ = 0.0;
  std::vector<double> phi_;
  std::vector<double> drive_;
  std::vector<double> state_;
  std::vector<double> tone_phase_;
  size_t sample_ = 0;
};

}  // namespace gravcal

#endif  // GRAVCAL_SIMULATION_NOISE_PROCESS_H_
