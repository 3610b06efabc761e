// Config section "effects": effects beyond the textbook model fitted by the
// calibration (and the baseline of `discover`), and section "discovery":
// the discovery workflow of `gravcal discover` (DiscoveryOptions).
#include "workflows/config/config_key.h"

namespace gravcal {
namespace internal {

namespace {

bool ReadEffects(const YAML::Node& n, std::vector<Effect>* effects, std::string* e) {
  std::vector<std::string> names;
  return ReadStringList(n, &names, e) && ParseEffects(names, effects, e);
}

}  // namespace

SectionOf<CalibrationConfig> EffectsSection() {
  return {"effects",
          ConfigSectionUse::kSomeMethods,
          {
              GRAVCAL_KEY_AT(
                  "effects",
                  "effects added to the model by name (catalogue: docs/methods.md section 6), e.g. "
                  "[accel_temperature_bias]",
                  ReadEffects(n, &c->effects, e), ListText(EffectNames(c.effects)), &c.effects),
          }};
}

SectionOf<DiscoveryConfig> DiscoverySection() {
  return {
      "discovery",
      ConfigSectionUse::kCommand,
      {
          GRAVCAL_KEY("discovery_candidates", "effects discover tries; empty = the whole catalogue",
                      ReadEffects(n, &c->discovery.candidates, e),
                      ListText(EffectNames(c.discovery.candidates))),
          GRAVCAL_DOUBLE("discovery_significance", discovery.significance,
                         "family-wise significance level of one discovery step"),
          GRAVCAL_DOUBLE("discovery_min_bic_gain", discovery.min_bic_gain,
                         "BIC decrease a candidate must bring (10 = very strong evidence)"),
          GRAVCAL_DOUBLE("discovery_ambiguity_bic", discovery.ambiguity_bic,
                         "candidates within this delta BIC of the best are reported as ambiguous"),
          GRAVCAL_INT("discovery_max_steps", discovery.max_steps, "most effects discover adds"),
          GRAVCAL_INT("discovery_min_dof", discovery.min_dof,
                      "residual dof an extended model must keep"),
          GRAVCAL_DOUBLE("discovery_min_temperature_range", discovery.min_temperature_range,
                         "degC the positions must span for temperature effects to be tried"),
          GRAVCAL_BOOL("discovery_use_within_pose_trends", discovery.use_within_pose_trends,
                       "accelerometer tests also use each pose's trend along gravity"),
          GRAVCAL_DOUBLE("discovery_min_trend_seconds", discovery.min_trend_seconds,
                         "poses held at least this long give a within-pose trend"),
          GRAVCAL_BOOL("discovery_use_rotations", discovery.use_between_pose_rotations,
                       "accelerometer tests also use the gyroscope's turns between poses"),
      }};
}

}  // namespace internal
}  // namespace gravcal
