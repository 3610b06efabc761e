// gravcal/core/effects/effect_definition.h: what an effect definition of the
// registry (core/effect_registry.h) declares. Each effect is one struct in
// its own file of this folder, with
//
//   kName, kDescription     its name in configs and JSON, one sentence
//   kSensor, kRegressor     the sensor it acts on; what its residual varies
//                           with (orientation, temperature or time; the
//                           data determine a temperature effect only when
//                           the poses span a temperature range, discovery
//                           says so)
//   kForm                   how its term enters the model (EffectForm)
//   kSize, kParameters,     its parameters, their names and unit
//   kUnit
//   kSimulation             the simulator's truth spread key (sim_<...>)
//   kC                      its term as a C99 expression, for the generated
//                           C corrector (io/c_corrector_export.h; every form
//                           but kInUpper): written in double, with `p` its
//                           parameters, `i` the axis (0..2), `dT` and `dt`
//                           the temperature and time offsets, `x` a shape's
//                           input and `force` the gyroscope's specific force;
//                           the writer makes the float form (literals 1.0f,
//                           sqrtf) and names the arrays
//
// and its equation as templated static functions (T = double in the
// corrector, ceres::Jet in the residuals), by form:
//
//   kAccelOffset  m_i = ... + o_i(p, dT, dt), kC = o_i:
//                   Add(p, i, dT, dt, x)    x += o_i
//                   Remove(p, i, dT, dt, x) x -= o_i
//                   RateT(p, i, dT), Ratet(p, i)   d o_i / d dT, d o_i / d dt
//   kAccelShape   m_i = f_i(x; p, dT, dt), kC = f_i^-1(x), kDepth its
//                 place (1 acts on the true specific force first), kVaries
//                 whether f depends on dT or dt:
//                   Add(p, i, dT, dt, x)    x = f_i(x)
//                   Remove(p, i, dT, dt, x) x = f_i^-1(x); false without a
//                                           real root
//                   Slope(p, i, x, dT), RateT(p, i, x), Ratet(p, i, x)
//                                           d f / d x, d f / d dT, d f / d dt
//                                           at the input x (kVaries only)
//   kGyroOffset   o_i += g_i(p, f, dT, dt) (raw gyroscope units, at rest),
//                 kC = g_i:
//                   Add(p, i, force, dT, dt, o)
//   kInUpper      no term: it frees entries of U (accel_misalignment).
#ifndef GRAVCAL_CORE_EFFECTS_EFFECT_DEFINITION_H_
#define GRAVCAL_CORE_EFFECTS_EFFECT_DEFINITION_H_

#include "gravcal/core/types.h"

namespace gravcal {

// How an effect's term enters the model (effect_definition.h).
enum class EffectForm { kInUpper, kAccelOffset, kAccelShape, kGyroOffset };

// The simulator's truth spread of an effect: config key, name in truth.json's
// options, help and upper limit (0 = no limit). An effect without a key
// (key null) is simulated elsewhere.
struct EffectSimulation {
  const char* key = nullptr;
  const char* name = nullptr;
  const char* help = nullptr;
  double max = 0.0;
};

}  // namespace gravcal

#endif  // GRAVCAL_CORE_EFFECTS_EFFECT_DEFINITION_H_
