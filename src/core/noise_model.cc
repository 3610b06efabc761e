#include "gravcal/core/noise_model.h"

#include <algorithm>
#include <cmath>

#include "core/noise_flicker.h"

namespace gravcal {

namespace {

// The Allan variance at tau of every term but the bias instability.
double OtherTermsVariance(const AxisNoiseModel& m, double tau) {
  double v = 0.0;
  if (m.quantisation.visible())
    v += 3.0 * m.quantisation.value * m.quantisation.value / (tau * tau);
  if (m.white_noise.visible()) v += m.white_noise.value * m.white_noise.value / tau;
  if (m.random_walk.visible()) v += m.random_walk.value * m.random_walk.value * tau / 3.0;
  return v;
}

}  // namespace

namespace internal {

double FlickerAllanVariance(const AxisNoiseModel& axis) {
  if (!axis.bias_instability.visible()) return 0.0;
  const double b = axis.bias_instability.value;
  double flicker = kFlickerAllanFactor * b * b;
  const double at = axis.bias_instability.tau;
  if (at > 0.0 && std::isfinite(at))
    flicker = std::max(0.0, flicker - OtherTermsVariance(axis, at));
  return flicker;
}

}  // namespace internal

double AxisNoiseModel::AllanVariance(double tau) const {
  return OtherTermsVariance(*this, tau) + internal::FlickerAllanVariance(*this);
}

double StillMeanVariance(const AxisNoiseModel& axis, double seconds) {
  if (!axis.white_noise.visible() || !(seconds > 0.0)) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  return axis.AllanVariance(seconds);
}

Eigen::Vector3d StillMeanVariance(const std::array<AxisNoiseModel, 3>& axes, double seconds) {
  return Eigen::Vector3d(StillMeanVariance(axes[0], seconds), StillMeanVariance(axes[1], seconds),
                         StillMeanVariance(axes[2], seconds));
}

}  // namespace gravcal
