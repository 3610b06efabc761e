#include "gravcal/core/imu_model.h"

namespace gravcal {

int AccelModelParameterCount(AccelParameterization parameterization,
                             const std::vector<Effect>& effects) {
  int count = parameterization == AccelParameterization::kScale ? 6 : 9;
  for (Effect e : effects) {
    const EffectInfo& info = Info(e);
    if (info.sensor != EffectSensor::kAccelerometer) continue;
    // An effect in U only adds to kScale, which lacks it.
    if (info.form == EffectForm::kInUpper && parameterization != AccelParameterization::kScale) {
      continue;
    }
    count += info.num_parameters;
  }
  return count;
}

}  // namespace gravcal
