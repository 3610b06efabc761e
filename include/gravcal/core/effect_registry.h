// gravcal/core/effect_registry.h: the registry of sensor effects beyond the
// textbook model. Each effect is defined once, in its own file of
// core/effects/ (effect_definition.h says what a definition holds: its
// named parameters with their unit, its equation templated on the scalar,
// what it varies with), and registered here by one line of
// GRAVCAL_EFFECTS (with its #include). Every consumer derives from the
// definitions: the Effect enum and its names, the catalogue
// (model_effects.h), the storage of the values (EffectParameters), the
// model's terms (ImuModel<T> for the residuals and the corrector), the fits'
// parameter blocks, the calibration JSON, the simulator's truth keys,
// discovery's candidates and the exporters' notes.
//
// The accelerometer, per axis, from the true specific force s (model_
// effects.h): the shape terms in order of depth, then the offsets,
//
//   m_i = f_n(... f_1(s_i)) + sum_j o_j,i
//
// inverted by removing the offsets (in registry order) and then the shapes
// from the outermost in. The gyroscope at rest: o = sum_j g_j (raw units).
#ifndef GRAVCAL_CORE_EFFECT_REGISTRY_H_
#define GRAVCAL_CORE_EFFECT_REGISTRY_H_

#include "gravcal/core/effects/accel_bias_drift.h"
#include "gravcal/core/effects/accel_misalignment.h"
#include "gravcal/core/effects/accel_quadratic.h"
#include "gravcal/core/effects/accel_temperature_bias.h"
#include "gravcal/core/effects/accel_temperature_bias_quadratic.h"
#include "gravcal/core/effects/accel_temperature_scale.h"
#include "gravcal/core/effects/gyro_bias_drift.h"
#include "gravcal/core/effects/gyro_g_sensitivity.h"
#include "gravcal/core/effects/gyro_temperature_bias.h"

// Every effect, in catalogue order (the order of configs' lists, help and
// discovery's candidates). A new effect is one line at the end of the list
// and its #include above.
// clang-format off
#define GRAVCAL_EFFECTS(X)                                            \
  X(AccelMisalignment)                                                \
  X(AccelQuadratic)                                                   \
  X(AccelTemperatureBias)                                             \
  X(AccelTemperatureScale)                                            \
  X(AccelBiasDrift)                                                   \
  X(GyroGSensitivity)                                                 \
  X(GyroTemperatureBias)                                              \
  X(GyroBiasDrift)                                                    \
  X(AccelTemperatureBiasQuadratic)                                    \
  /* a new effect: one line above */
// clang-format on

namespace gravcal {

#define GRAVCAL_EFFECT_ENUM(Name) k##Name,
// One value per registered effect; ToString gives its name
// (e.g. "accel_temperature_bias").
enum class Effect : int { GRAVCAL_EFFECTS(GRAVCAL_EFFECT_ENUM) };
#undef GRAVCAL_EFFECT_ENUM

namespace effects {

template <typename... D>
struct List {};
#define GRAVCAL_EFFECT_TYPE(Name) , Name
// The definitions in registry order (the leading void is dropped).
template <typename First, typename... D>
struct DropFirst {
  using type = List<D...>;
};
using All = DropFirst<void GRAVCAL_EFFECTS(GRAVCAL_EFFECT_TYPE)>::type;
#undef GRAVCAL_EFFECT_TYPE

// Calls f(D{}, Effect) for every definition D, in registry order.
template <typename F, typename... D>
constexpr void ForEach(List<D...>, F&& f) {
  int index = 0;
  (f(D{}, static_cast<Effect>(index++)), ...);
}
template <typename F>
constexpr void ForEach(F&& f) {
  ForEach(All{}, f);
}

constexpr int kCount = [] {
  int n = 0;
  ForEach([&n](auto, Effect) { ++n; });
  return n;
}();

// Storage: the accelerometer's terms (forms kAccelOffset and kAccelShape)
// in one block, the gyroscope's in another, each effect's parameters at its
// offset in registry order.
struct Layout {
  int accel_size = 0;
  int gyro_size = 0;
  int offset[kCount] = {};
  int size[kCount] = {};
  int max_depth = 0;
};
constexpr Layout kLayout = [] {
  Layout l;
  ForEach([&l](auto d, Effect e) {
    using D = decltype(d);
    const int k = static_cast<int>(e);
    if constexpr (D::kForm == EffectForm::kAccelOffset || D::kForm == EffectForm::kAccelShape) {
      l.offset[k] = l.accel_size;
      l.size[k] = D::kSize;
      l.accel_size += D::kSize;
    } else if constexpr (D::kForm == EffectForm::kGyroOffset) {
      l.offset[k] = l.gyro_size;
      l.size[k] = D::kSize;
      l.gyro_size += D::kSize;
    }
    if constexpr (D::kForm == EffectForm::kAccelShape) {
      if (D::kDepth > l.max_depth) l.max_depth = D::kDepth;
    }
  });
  return l;
}();

}  // namespace effects

// The number of registered effects and the sizes of the two parameter
// blocks that hold their values (the accelerometer's and the gyroscope's).
constexpr int kNumEffects = effects::kCount;
constexpr int kAccelEffectParameters = effects::kLayout.accel_size;
constexpr int kGyroEffectParameters = effects::kLayout.gyro_size;

// Points accel[e] (gyro[e]) into the accelerometer's (gyroscope's) block for
// every effect stored there.
template <typename T>
void PointIntoBlocks(const T* accel_block, const T* gyro_block, const T* (&pointers)[kNumEffects]) {
  effects::ForEach([&](auto d, Effect e) {
    using D = decltype(d);
    const int k = static_cast<int>(e);
    if constexpr (D::kForm == EffectForm::kGyroOffset) {
      if (gyro_block != nullptr) pointers[k] = gyro_block + effects::kLayout.offset[k];
    } else if constexpr (D::kForm != EffectForm::kInUpper) {
      if (accel_block != nullptr) pointers[k] = accel_block + effects::kLayout.offset[k];
    }
  });
}

// s from m in place: the offsets removed (registry order), then the shapes
// from the outermost in. False when a shape has no inverse here.
template <typename T>
bool RemoveAccelEffects(const T* const (&p)[kNumEffects], double dT, double dt, T* m) {
  effects::ForEach([&](auto d, Effect e) {
    using D = decltype(d);
    [[maybe_unused]] const T* q = p[static_cast<int>(e)];
    if constexpr (D::kForm == EffectForm::kAccelOffset) {
      if (q != nullptr) {
        for (int i = 0; i < 3; ++i) D::Remove(q, i, dT, dt, m + i);
      }
    }
  });
  bool ok = true;
  for (int depth = effects::kLayout.max_depth; depth >= 1 && ok; --depth) {
    effects::ForEach([&](auto d, Effect e) {
      using D = decltype(d);
      [[maybe_unused]] const T* q = p[static_cast<int>(e)];
      if constexpr (D::kForm == EffectForm::kAccelShape) {
        if (D::kDepth != depth || q == nullptr || !ok) return;
        for (int i = 0; i < 3 && ok; ++i) ok = D::Remove(q, i, dT, dt, m + i);
      }
    });
  }
  return ok;
}

// m from s (the forward model, for simulation): the shapes from the
// innermost out, then the offsets.
template <typename T>
void AddAccelEffects(const T* const (&p)[kNumEffects], double dT, double dt, T* s) {
  for (int depth = 1; depth <= effects::kLayout.max_depth; ++depth) {
    effects::ForEach([&](auto d, Effect e) {
      using D = decltype(d);
      [[maybe_unused]] const T* q = p[static_cast<int>(e)];
      if constexpr (D::kForm == EffectForm::kAccelShape) {
        if (D::kDepth != depth || q == nullptr) return;
        for (int i = 0; i < 3; ++i) D::Add(q, i, dT, dt, s + i);
      }
    });
  }
  effects::ForEach([&](auto d, Effect e) {
    using D = decltype(d);
    [[maybe_unused]] const T* q = p[static_cast<int>(e)];
    if constexpr (D::kForm == EffectForm::kAccelOffset) {
      if (q != nullptr) {
        for (int i = 0; i < 3; ++i) D::Add(q, i, dT, dt, s + i);
      }
    }
  });
}

// The rate of m within a still pose (s constant) whose temperature changes
// at Tdot (degC/s): mdot = (dm/d dT) Tdot + dm/d dt, m = U (v - b) the mean
// reading at offsets (dT, dt). The shapes that vary are inverted down to
// the deepest of them to find their inputs; the rates are carried out
// through the slopes of the shapes above, then the offsets add theirs.
template <typename T>
void AccelEffectRate(const T* const (&p)[kNumEffects], const T* m, double dT, double dt,
                     double temperature_slope, T* rate) {
  int deepest = effects::kLayout.max_depth + 1;
  effects::ForEach([&](auto d, Effect e) {
    using D = decltype(d);
    if constexpr (D::kForm == EffectForm::kAccelShape) {
      if (D::kVaries && p[static_cast<int>(e)] != nullptr && D::kDepth < deepest) {
        deepest = D::kDepth;
      }
    }
  });
  for (int i = 0; i < 3; ++i) {
    // The input of every shape at `deepest` or above, from the outermost in.
    T x = m[i];
    effects::ForEach([&](auto d, Effect e) {
      using D = decltype(d);
      [[maybe_unused]] const T* q = p[static_cast<int>(e)];
      if constexpr (D::kForm == EffectForm::kAccelOffset) {
        if (q != nullptr) D::Remove(q, i, dT, dt, &x);
      }
    });
    T inputs[effects::kLayout.max_depth + 1];
    for (int depth = effects::kLayout.max_depth; depth >= deepest; --depth) {
      effects::ForEach([&](auto d, Effect e) {
        using D = decltype(d);
        [[maybe_unused]] const T* q = p[static_cast<int>(e)];
        if constexpr (D::kForm == EffectForm::kAccelShape) {
          if (D::kDepth != depth || q == nullptr) return;
          D::Remove(q, i, dT, dt, &x);
          inputs[depth] = x;
        }
      });
    }
    // Out again: rate_T and rate_t are d m / d dT and d m / d dt.
    T rate_T = T(0.0), rate_t = T(0.0);
    bool started = false;
    for (int depth = deepest; depth <= effects::kLayout.max_depth; ++depth) {
      effects::ForEach([&](auto d, Effect e) {
        using D = decltype(d);
        [[maybe_unused]] const T* q = p[static_cast<int>(e)];
        if constexpr (D::kForm == EffectForm::kAccelShape) {
          if constexpr (D::kVaries) {
            if (D::kDepth != depth || q == nullptr) return;
            const T& in = inputs[depth];
            if (started) {
              const T slope = D::Slope(q, i, in, dT);
              rate_T = rate_T * slope + D::RateT(q, i, in);
              rate_t = rate_t * slope + D::Ratet(q, i, in);
            } else {
              rate_T = D::RateT(q, i, in);
              rate_t = D::Ratet(q, i, in);
              started = true;
            }
          }
        }
      });
    }
    effects::ForEach([&](auto d, Effect e) {
      using D = decltype(d);
      [[maybe_unused]] const T* q = p[static_cast<int>(e)];
      if constexpr (D::kForm == EffectForm::kAccelOffset) {
        if (q == nullptr) return;
        rate_T = rate_T + D::RateT(q, i, dT);
        rate_t = rate_t + D::Ratet(q, i);
      }
    });
    rate[i] = rate_T * T(temperature_slope) + rate_t;
  }
}

// The gyroscope offset at rest, o = sum of the terms switched on (raw
// units); force (3 values, the calibrated specific force) may be null when
// no term reads it.
template <typename T>
void GyroEffectOffset(const T* const (&p)[kNumEffects], const double* force, double dT, double dt,
                      T* offset) {
  for (int i = 0; i < 3; ++i) {
    offset[i] = T(0.0);
    effects::ForEach([&](auto d, Effect e) {
      using D = decltype(d);
      [[maybe_unused]] const T* q = p[static_cast<int>(e)];
      if constexpr (D::kForm == EffectForm::kGyroOffset) {
        if (q != nullptr) D::Add(q, i, force, dT, dt, offset + i);
      }
    });
  }
}

}  // namespace gravcal

#endif  // GRAVCAL_CORE_EFFECT_REGISTRY_H_
