#include "gravcal/core/imu_model.h"

namespace gravcal {

bool SetEffectValues(Effect effect, const std::vector<double>& v, EffectParameters* p) {
  if (effect == Effect::kAccelMisalignment) return true;
  if (static_cast<int>(v.size()) != Info(effect).num_parameters) return false;
  auto three = [&](Eigen::Vector3d* out) { *out = Eigen::Vector3d(v[0], v[1], v[2]); };
  switch (effect) {
    case Effect::kAccelMisalignment:
      break;
    case Effect::kAccelQuadratic:
      three(&p->accel_quadratic);
      break;
    case Effect::kAccelTemperatureBias:
      three(&p->accel_temperature_bias);
      break;
    case Effect::kAccelTemperatureScale:
      three(&p->accel_temperature_scale);
      break;
    case Effect::kAccelBiasDrift:
      three(&p->accel_bias_drift);
      break;
    case Effect::kGyroGSensitivity:
      for (int i = 0; i < 9; ++i) p->gyro_g_sensitivity(i / 3, i % 3) = v[i];
      break;
    case Effect::kGyroTemperatureBias:
      three(&p->gyro_temperature_bias);
      break;
    case Effect::kGyroBiasDrift:
      three(&p->gyro_bias_drift);
      break;
  }
  return true;
}

int AccelModelParameterCount(AccelParameterization parameterization,
                             const std::vector<Effect>& effects) {
  int count = parameterization == AccelParameterization::kScale ? 6 : 9;
  for (Effect e : effects) {
    const EffectInfo& info = Info(e);
    if (info.sensor != EffectSensor::kAccelerometer) continue;
    if (e == Effect::kAccelMisalignment && parameterization != AccelParameterization::kScale) {
      continue;
    }
    count += info.num_parameters;
  }
  return count;
}

}  // namespace gravcal
