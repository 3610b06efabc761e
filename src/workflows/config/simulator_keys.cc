// Config sections of `gravcal simulate` and `gravcal demo`, never of a
// calibration method: "simulator" (SimulatorOptions, every sim_* key, made
// from the options' own table, simulation/simulator_fields.h) and "motion
// simulator" (sim_motion and MotionOptions, the hh_* keys).

#include "simulation/simulator_fields.h"
#include "workflows/config/config_key.h"

namespace gravcal {
namespace internal {

namespace {

// The handler of one field of SimulatorOptions (simulator_fields.h).
KeyHandlerOf<SimulationConfig> FieldHandler(const SimulatorField& field) {
  KeyHandlerOf<SimulationConfig> h;
  h.name = field.key;
  h.help = field.help;
  h.set = [field](const YAML::Node& n, SimulationConfig* c, std::string* e) {
    bool ok = false;
    WithFieldValue(field, c->simulation, [&](auto& value) { ok = ReadValue(n, &value, e); });
    return ok;
  };
  h.get = [field](const SimulationConfig& c) {
    std::string text;
    WithFieldValue(field, c.simulation, [&](const auto& value) { text = ValueText(value); });
    return text;
  };
  return h;
}

}  // namespace

SectionOf<SimulationConfig> SimulatorSection() {
  SectionOf<SimulationConfig> section{"simulator", ConfigSectionUse::kCommand, {}};
  for (const SimulatorField& field : SimulatorFields()) section.keys.push_back(FieldHandler(field));
  return section;
}

SectionOf<SimulationConfig> MotionSimulatorSection() {
  return {
      "motion simulator",
      ConfigSectionUse::kCommand,
      {
          GRAVCAL_KEY("sim_motion",
                      "simulate: " + AcceptedNames(MotionProfile()) + " (empty = sim_scheme)",
                      ReadOptionalEnum(n, &c->sim_motion, e), ValueText(c.sim_motion)),
          GRAVCAL_DOUBLE("hh_initial_still", motion.initial_still_seconds, "still at the start, s"),
          GRAVCAL_DOUBLE("hh_final_still", motion.final_still_seconds, "still at the end, s"),
          GRAVCAL_DOUBLE("hh_seconds_per_axis", motion.seconds_per_axis,
                         "turning time per axis (rate table: per direction), s"),
          GRAVCAL_DOUBLE("hh_rate", motion.rate_dps, "mean turning rate, deg/s"),
          GRAVCAL_DOUBLE("hh_rate_variation", motion.rate_variation,
                         "handheld: relative variation of the hand's rate"),
          GRAVCAL_DOUBLE("hh_axis_wobble", motion.axis_wobble_deg,
                         "handheld: rms wobble of the turning axis, deg"),
          GRAVCAL_DOUBLE("hh_sway", motion.sway, "hand sway, m rms per axis"),
          GRAVCAL_DOUBLE("hh_sway_hz", motion.sway_hz, "highest hand sway frequency, Hz"),
          GRAVCAL_DOUBLE("hh_tremor", motion.tremor, "hand tremor (8-12 Hz), m/s^2 rms per axis"),
          GRAVCAL_DOUBLE("hh_angular_tremor", motion.angular_tremor,
                         "hand tremor (8-12 Hz), rad/s rms per axis"),
          GRAVCAL_INT("hh_rounds", motion.rounds, "times through the x, y, z turns"),
          GRAVCAL_DOUBLE("hh_lever_arm", motion.lever_arm,
                         "sensor distance from the point the hand turns about, m"),
      }};
}

}  // namespace internal
}  // namespace gravcal
