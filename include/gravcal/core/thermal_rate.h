// gravcal/core/thermal_rate.h: the temperature's rate of change along a
// stream of samples, for the thermal model's lag term (thermal_model.h,
// T_e = T - tau dT/dt) when a log is corrected sample by sample.
#ifndef GRAVCAL_CORE_THERMAL_RATE_H_
#define GRAVCAL_CORE_THERMAL_RATE_H_

#include <cmath>

namespace gravcal {

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
