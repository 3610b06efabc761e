#include "gravcal/workflows/simulation_workflow.h"

#include <nlohmann/json.hpp>
#include <utility>

#include "gravcal/io/attitude_fixture.h"
#include "gravcal/io/plan_io.h"
#include "gravcal/simulation/handheld_simulator.h"
#include "gravcal/simulation/simulated_attitudes.h"
#include "gravcal/simulation/thermal_simulator.h"
#include "gravcal/workflows/rate_table_segments.h"
#include "io/thermal_json.h"

namespace gravcal {

bool SimulateFromConfig(const Config& config, const SimulationRequest& request,
                        SimulationFiles* files, std::string* error) {
  if (!config.IsValid(error)) return false;
  SimulatorOptions& sim = files->options;
  sim = config.simulation;
  if (!request.plan_path.empty()) {
    std::vector<PlannedPose> poses;
    std::vector<PlannedRotation> turns;
    if (!ReadPlanPoses(request.plan_path, &poses, error, &turns)) return false;
    sim.planned_poses.clear();
    for (const PlannedPose& p : poses) sim.planned_poses.push_back({p.up, p.hold_seconds});
    // The planned turns, when the plan chose them for the gyroscope.
    for (const PlannedRotation& r : turns) {
      if (r.seconds <= 0.0) continue;
      PlannedHold& to = sim.planned_poses[r.to];
      to.turn_axis = r.axis;
      to.turn_angle_deg = r.angle_deg;
      to.turn_seconds = r.seconds;
    }
    sim.initial_still_seconds = 0.0;
  }
  files->segments.clear();
  if (config.sim_thermal) {
    // Issue 35: a session across temperature; truth.json gains "thermal".
    ThermalSimulatorOptions thermal = config.thermal_simulation;
    thermal.profile = *config.sim_thermal;
    thermal.gravity = sim.gravity;
    thermal.raw_counts = sim.raw_counts;
    ThermalSimulatedSession session;
    if (!SimulateThermal(thermal, request.seed, &session, error)) return false;
    SimulatedSession& out = files->session;
    out.log = std::move(session.log);
    out.accel_truth = session.accel;
    out.gyro_truth = session.gyro;
    out.gravity = thermal.gravity;
    out.accel_units_per_si = session.accel_units_per_si;
    out.gyro_units_per_si = session.gyro_units_per_si;
    out.seed = request.seed;
    nlohmann::json truth = nlohmann::json::parse(TruthToJson(out, sim));
    truth["thermal"] = internal::ThermalJson(session.thermal);
    truth["thermal_profile"] = ToString(*config.sim_thermal);
    truth["thermal_datasheet"] = "Bosch BMI088 (BST-BMI088-DS001) magnitudes unless overridden";
    files->truth_json = truth.dump(2) + "\n";
    files->attitudes_csv = FixtureAttitudesToCsv(std::vector<FixtureAttitude>());
    files->segments_csv.clear();
    return true;
  }
  if (config.sim_motion) {
    MotionOptions motion = config.motion;
    motion.profile = *config.sim_motion;
    MotionSession moving;
    if (!SimulateMotion(sim, motion, request.seed, &moving, error)) return false;
    files->segments = std::move(moving.segments);
    files->session = std::move(moving.sensor);
  } else if (!Simulate(sim, request.seed, &files->session, error)) {
    return false;
  }
  files->truth_json = TruthToJson(files->session, sim);
  files->attitudes_csv = FixtureAttitudesToCsv(
      SimulatedFixtureAttitudes(files->session, sim.fixture_attitude_noise_deg, request.seed));
  files->segments_csv = files->segments.empty()
                            ? std::string()
                            : RateTableSegmentsToCsv(files->segments, files->session.log);
  return true;
}

}  // namespace gravcal
