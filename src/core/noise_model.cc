#include "gravcal/core/noise_model.h"

#include <cmath>

namespace gravcal {

double AxisNoiseModel::AllanVariance(double tau) const {
  double v = 0.0;
  if (quantisation.visible()) v += 3.0 * quantisation.value * quantisation.value / (tau * tau);
  if (white_noise.visible()) v += white_noise.value * white_noise.value / tau;
  if (bias_instability.visible()) {
    v += kFlickerAllanFactor * bias_instability.value * bias_instability.value;
  }
  if (random_walk.visible()) v += random_walk.value * random_walk.value * tau / 3.0;
  return v;
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
