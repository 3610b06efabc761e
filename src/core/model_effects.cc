#include "gravcal/core/model_effects.h"

#include <algorithm>

namespace gravcal {

const std::vector<EffectInfo>& EffectCatalogue() {
  // Never destroyed (Google style for static storage): a batch worker abandoned
  // with a hung unit may still read it while the process exits (found by TSan).
  static const std::vector<EffectInfo>& catalogue = *new std::vector<EffectInfo>([] {
    std::vector<EffectInfo> entries;
    effects::ForEach([&entries](auto d, Effect e) {
      using D = decltype(d);
      EffectInfo info{
          e,          D::kDescription,
          D::kSensor, D::kRegressor,
          D::kSize,   std::vector<std::string>(D::kParameters, D::kParameters + D::kSize),
          D::kUnit,   D::kName,
          D::kForm,   D::kSimulation};
      entries.push_back(info);
    });
    return entries;
  }());
  return catalogue;
}

const EffectInfo& Info(Effect effect) {
  const std::vector<EffectInfo>& catalogue = EffectCatalogue();
  const int k = static_cast<int>(effect);
  return k >= 0 && k < static_cast<int>(catalogue.size()) ? catalogue[k] : catalogue.front();
}

bool ParseEffects(const std::vector<std::string>& names, std::vector<Effect>* effects,
                  std::string* error) {
  std::vector<Effect> out;
  for (const std::string& name : names) {
    Effect e;
    if (!FromString(name, &e)) {
      std::string known;
      for (const EffectInfo& info : EffectCatalogue()) {
        known += (known.empty() ? "" : ", ") + std::string(info.name);
      }
      if (error) *error = "unknown effect '" + name + "' (known: " + known + ")";
      return false;
    }
    if (!Contains(out, e)) out.push_back(e);
  }
  *effects = out;
  return true;
}

std::vector<std::string> EffectNames(const std::vector<Effect>& effects) {
  std::vector<std::string> names;
  for (Effect e : effects) names.push_back(ToString(e));
  return names;
}

bool Contains(const std::vector<Effect>& effects, Effect effect) {
  return std::find(effects.begin(), effects.end(), effect) != effects.end();
}

const double* EffectParameters::Block(Effect effect) const {
  const int k = static_cast<int>(effect);
  switch (Info(effect).form) {
    case EffectForm::kInUpper:
      return nullptr;
    case EffectForm::kGyroOffset:
      return gyro.data() + effects::kLayout.offset[k];
    case EffectForm::kAccelOffset:
    case EffectForm::kAccelShape:
      break;
  }
  return accel.data() + effects::kLayout.offset[k];
}

double* EffectParameters::Block(Effect effect) {
  return const_cast<double*>(static_cast<const EffectParameters&>(*this).Block(effect));
}

std::vector<double> EffectParameters::Values(Effect effect) const {
  const double* b = Block(effect);
  if (b == nullptr) return {};
  return std::vector<double>(b, b + Info(effect).num_parameters);
}

bool EffectParameters::SetValues(Effect effect, const std::vector<double>& values) {
  double* b = Block(effect);
  if (b == nullptr) return true;
  if (static_cast<int>(values.size()) != Info(effect).num_parameters) return false;
  std::copy(values.begin(), values.end(), b);
  return true;
}

void EffectParameters::Pointers(const std::vector<Effect>& active,
                                const double* (&pointers)[kNumEffects]) const {
  for (int k = 0; k < kNumEffects; ++k) {
    const Effect e = static_cast<Effect>(k);
    pointers[k] = Contains(active, e) ? Block(e) : nullptr;
  }
}

double TemperatureOffset(const EffectParameters& p, double temperature) {
  return std::isfinite(temperature) ? temperature - p.reference_temperature : 0.0;
}

Eigen::Vector3d ApplyAccelEffects(const EffectParameters& p, const Eigen::Vector3d& s,
                                  double temperature, double time) {
  const double* all[kNumEffects] = {};
  PointIntoBlocks<double>(p.accel.data(), nullptr, all);
  Eigen::Vector3d m = s;
  AddAccelEffects<double>(all, TemperatureOffset(p, temperature), time - p.reference_time,
                          m.data());
  return m;
}

bool CorrectAccel(const EffectParameters& p, const std::vector<Effect>& effects,
                  const Eigen::Vector3d& m, double temperature, double time, Eigen::Vector3d* a) {
  const double* on[kNumEffects];
  p.Pointers(effects, on);
  Eigen::Vector3d out = m;
  const bool ok = RemoveAccelEffects<double>(on, TemperatureOffset(p, temperature),
                                             time - p.reference_time, out.data());
  *a = out;
  return ok;
}

Eigen::Vector3d GyroOffset(const EffectParameters& p, const std::vector<Effect>& effects,
                           const Eigen::Vector3d& force, double temperature, double time) {
  const double* on[kNumEffects];
  p.Pointers(effects, on);
  Eigen::Vector3d offset;
  GyroEffectOffset<double>(on, force.data(), TemperatureOffset(p, temperature),
                           time - p.reference_time, offset.data());
  return offset;
}

}  // namespace gravcal
