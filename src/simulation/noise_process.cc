#include "gravcal/simulation/noise_process.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>

#include "gravcal/core/noise_model.h"

namespace gravcal {
namespace internal {
namespace {

// The Allan variance of a stationary Gauss-Markov process of variance s2 and
// correlation time T (see the header); its small-tau series where the
// bracket cancels.
double GaussMarkovAllanVariance(double s2, double T, double tau) {
  const double x = tau / T;
  if (x < 1e-3) return 2.0 * s2 * tau / (3.0 * T) * (1.0 - 0.75 * x);
  const double bracket = 1.0 - (3.0 - 4.0 * std::exp(-x) + std::exp(-2.0 * x)) / (2.0 * x);
  return 2.0 * s2 * T / tau * bracket;
}

}  // namespace
}  // namespace internal

bool NoiseProcessOptions::IsValid(std::string* error) const {
  if (!(rate_hz > 0.0) || !std::isfinite(rate_hz)) {
    *error = "noise process rate_hz must be > 0";
  } else if (!(white_noise >= 0.0) || !(random_walk >= 0.0) || !(bias_instability >= 0.0)) {
    *error = "noise process densities must be >= 0";
  } else if (!std::isfinite(ramp)) {
    *error = "noise process ramp must be finite";
  } else if (bias_instability > 0.0 &&
             !(bias_tau_low >= 10.0 / rate_hz && bias_tau_high > bias_tau_low)) {
    *error = "noise process bias tau range must satisfy 10 / rate_hz <= tau_low < tau_high";
  } else if (std::any_of(tones.begin(), tones.end(), [&](const Tone& t) {
               return !(t.frequency_hz > 0.0 && t.frequency_hz < 0.5 * rate_hz) ||
                      !(t.amplitude >= 0.0) || !std::isfinite(t.amplitude);
             })) {
    *error = "noise process tones need 0 < frequency < rate_hz / 2 and amplitude >= 0";
  } else {
    return true;
  }
  return false;
}

NoiseProcess::NoiseProcess(const NoiseProcessOptions& options, uint64_t seed)
    : options_(options), rng_(seed ^ 0x9e3779b97f4a7c15ULL) {
  std::string error;
  CHECK(options.IsValid(&error)) << error;
  const double dt = 1.0 / options.rate_hz;
  white_std_ = options.white_noise * std::sqrt(options.rate_hz);
  walk_step_ = options.random_walk * std::sqrt(dt);
  if (options.bias_instability > 0.0) {
    const double step = std::pow(10.0, 0.5);
    for (double T = options.bias_tau_low / 10.0; T <= 10.0 * options.bias_tau_high * 1.000001;
         T *= step) {
      if (T >= dt) times_.push_back(T);
    }
    const double middle = std::sqrt(options.bias_tau_low * options.bias_tau_high);
    double unit = 0.0;
    for (double T : times_) unit += internal::GaussMarkovAllanVariance(1.0, T, middle);
    const double floor = kFlickerAllanFactor * options.bias_instability * options.bias_instability;
    component_std_ = std::sqrt(floor / unit);
    for (double T : times_) {
      const double phi = std::exp(-dt / T);
      phi_.push_back(phi);
      drive_.push_back(component_std_ * std::sqrt(1.0 - phi * phi));
      // Stationary from the first sample.
      state_.push_back(component_std_ * unit_(rng_));
    }
  }
  // The tones' phases from their own generator: the noise streams stay
  // those of the same seed without tones.
  std::mt19937_64 phases(seed ^ 0x5851f42d4c957f2dULL);
  std::uniform_real_distribution<double> turn(0.0, 2.0 * M_PI);
  for (size_t i = 0; i < options.tones.size(); ++i) tone_phase_.push_back(turn(phases));
}

double NoiseProcess::Next() {
  double v = walk_;
  if (white_std_ > 0.0) v += white_std_ * unit_(rng_);
  for (size_t i = 0; i < state_.size(); ++i) {
    v += state_[i];
    state_[i] = phi_[i] * state_[i] + drive_[i] * unit_(rng_);
  }
  if (walk_step_ > 0.0) walk_ += walk_step_ * unit_(rng_);
  const double t = static_cast<double>(sample_++) / options_.rate_hz;
  for (size_t i = 0; i < tone_phase_.size(); ++i) {
    const NoiseProcessOptions::Tone& tone = options_.tones[i];
    v += tone.amplitude * std::sin(2.0 * M_PI * tone.frequency_hz * t + tone_phase_[i]);
  }
  if (options_.ramp != 0.0) v += options_.ramp * t;
  return v;
}

std::vector<double> NoiseProcess::Generate(size_t n) {
  std::vector<double> out(n);
  for (double& v : out) v = Next();
  return out;
}

double NoiseProcess::ModelAllanVariance(double tau) const {
  double v = options_.white_noise * options_.white_noise / tau +
             options_.random_walk * options_.random_walk * tau / 3.0;
  for (double T : times_) {
    v += internal::GaussMarkovAllanVariance(component_std_ * component_std_, T, tau);
  }
  for (const NoiseProcessOptions::Tone& tone : options_.tones) {
    const double x = M_PI * tone.frequency_hz * tau;
    const double s = std::sin(x);
    v += tone.amplitude * tone.amplitude * s * s * s * s / (x * x);
  }
  return v + 0.5 * options_.ramp * options_.ramp * tau * tau;
}

}  // namespace gravcal
