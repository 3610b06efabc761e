// gravcal/core/thermal_rate.h: the temperature's rate of change along a
// stream of samples, for the thermal model's lag term (thermal_model.h,
// T_e = T - tau dT/dt) when a log is corrected sample by sample.
//
// The rate is the slope of a causal, exponentially weighted least-squares
// line through (t, T) with time constant `seconds` (the fit's windows use a
// centred line over the same span; a causal one lags it by about `seconds`,
// negligible against the minutes a warm-up takes). NaN until two samples
// with distinct times were seen.
#ifndef GRAVCAL_CORE_THERMAL_RATE_H_
#define GRAVCAL_CORE_THERMAL_RATE_H_

#include <cmath>

namespace gravcal {

class ThermalRate {
 public:
  explicit ThermalRate(double seconds = 30.0) : seconds_(seconds) {}

  // Adds one sample (t in s, increasing; T in degrees C, NaN ignored) and
  // returns the rate in degrees C per s.
  double Add(double t, double temperature) {
    if (!std::isfinite(temperature) || !std::isfinite(t)) return Rate();
    if (count_ > 0) {
      const double decay = std::exp(-(t - last_t_) / seconds_);
      w_ *= decay;
      st_ *= decay;
      sy_ *= decay;
      stt_ *= decay;
      sty_ *= decay;
    }
    // Times relative to the first sample keep the sums well conditioned.
    if (count_ == 0) origin_ = t;
    const double x = t - origin_;
    w_ += 1.0;
    st_ += x;
    sy_ += temperature;
    stt_ += x * x;
    sty_ += x * temperature;
    last_t_ = t;
    ++count_;
    return Rate();
  }

  double Rate() const {
    const double d = w_ * stt_ - st_ * st_;
    if (count_ < 2 || !(d > 1e-12 * w_ * stt_)) return NAN;
    return (w_ * sty_ - st_ * sy_) / d;
  }

 private:
  double seconds_;
  double origin_ = 0.0, last_t_ = 0.0;
  double w_ = 0.0, st_ = 0.0, sy_ = 0.0, stt_ = 0.0, sty_ = 0.0;
  long count_ = 0;
};

// The rate the thermal model's lag term takes when a log is corrected sample
// by sample: the sensing element's temperature T_e follows the recorded T
// through the first-order lag tau dT_e/dt = T - T_e (T_e = T at the first
// sample; T linear between samples, for which the step below is exact), and
// Add returns dT_e/dt = (T - T_e) / tau, so that the model's
// T - tau * rate is T_e exactly (thermal_model.h). The thermal fit computes
// T_e the same way (methods/thermal_residual.h). tau = 0: rate 0.
class ThermalElementRate {
 public:
  explicit ThermalElementRate(double tau) : tau_(tau) {}

  double Add(double t, double temperature) {
    if (!(tau_ > 0.0) || !std::isfinite(temperature) || !std::isfinite(t)) return rate_;
    if (!started_ || !(t > last_t_)) {
      if (!started_) element_ = temperature;
      started_ = true;
    } else {
      const double dt = t - last_t_;
      const double m = (temperature - last_temperature_) / dt;
      const double a = std::exp(-dt / tau_);
      element_ = temperature - tau_ * m + (element_ - last_temperature_ + tau_ * m) * a;
    }
    last_t_ = t;
    last_temperature_ = temperature;
    rate_ = (temperature - element_) / tau_;
    return rate_;
  }

  double element_temperature() const { return element_; }

 private:
  double tau_;
  bool started_ = false;
  double last_t_ = 0.0, last_temperature_ = 0.0, element_ = 0.0, rate_ = 0.0;
};

}  // namespace gravcal

#endif  // GRAVCAL_CORE_THERMAL_RATE_H_
